#include <fmt/core.h>

#include <cmath>
#include <fstream>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"
#include "workflows/batch_internal.h"

namespace arcwheel::workflows::batch {

std::string_view StatusName(Status status) {
  switch (status) {
    case Status::kDone:
      return "done";
    case Status::kReused:
      return "reused";
    case Status::kFailed:
      return "failed";
    case Status::kInterrupted:
      return "interrupted";
    case Status::kNotRun:
      break;
  }
  return "not run";
}

std::optional<Status> ParseStatus(const std::string& name) {
  for (Status s : {Status::kNotRun, Status::kDone, Status::kReused, Status::kFailed, Status::kInterrupted}) {
    if (StatusName(s) == name) return s;
  }
  return std::nullopt;
}

fs::path ResultFolder(const BatchOptions& args, const Scan& scan) {
  return fs::path(args.outdir) / scan.name;
}
fs::path LogPath(const BatchOptions& args, const Scan& scan) {
  return fs::path(args.outdir) / kLogsFolder / (scan.name + ".log");
}
fs::path OutcomePath(const BatchOptions& args, const Scan& scan) {
  return fs::path(args.outdir) / kLogsFolder / (scan.name + ".json");
}

const std::vector<std::string>& ResultFiles() {
  static const std::vector<std::string> files = {std::string(schema::summary::kFileName),
                                                 std::string(schema::wheel_map::kFileName)};
  return files;
}

void WriteOutcome(const BatchOptions& args, const Scan& scan, const Outcome& outcome, const json& inputs) {
  const json record = {{"scan", scan.path.string()},
                       {"status", StatusName(outcome.status)},
                       {"exit_code", outcome.exit_code ? json(*outcome.exit_code) : json()},
                       {"message", outcome.message},
                       {"seconds", std::round(outcome.seconds * 1e3) / 1e3},
                       {"inputs", inputs}};
  WriteFileAtomically(OutcomePath(args, scan), JsonText(record, 2) + "\n");
}

// The outcome a batch (perhaps an array task elsewhere) recorded for the scan, if any.
// Only an outcome of the same input and options counts.
std::optional<Outcome> ReadOutcome(const BatchOptions& args, const Scan& scan, const json& inputs) {
  const fs::path path = OutcomePath(args, scan);
  if (!fs::exists(path)) return std::nullopt;
  try {
    const json record = ReadJsonFile(path, kStage);
    for (const char* key : {"arcwheel_version", "options", "sha256"}) {
      if (record.at("inputs").at(key) != inputs.at(key)) return std::nullopt;
    }
    Outcome outcome;
    outcome.status = ParseStatus(record.at("status").get<std::string>()).value_or(Status::kNotRun);
    if (record.at("exit_code").is_number_integer()) outcome.exit_code = record.at("exit_code").get<int>();
    outcome.message = record.at("message").get<std::string>();
    outcome.seconds = record.at("seconds").get<double>();
    return outcome;
  } catch (const std::exception&) {
    return std::nullopt;  // not a record this command wrote
  }
}

// The child's own error line ("arcwheel: bad input: ..."), else its last line.
std::string ChildMessage(const fs::path& log) {
  std::ifstream in(log);
  std::string line, last, error;
  while (std::getline(in, line)) {
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    last = line;
    if (line.rfind("arcwheel: ", 0) == 0) error = line.substr(10);
  }
  return error.empty() ? last : error;
}

}  // namespace arcwheel::workflows::batch
