#include <fmt/chrono.h>
#include <fmt/core.h>

#include <cmath>
#include <ctime>
#include <map>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/version.h"
#include "schema/summary.h"
#include "workflows/batch_internal.h"

namespace arcwheel::workflows::batch {

namespace {

struct Column {
  std::string name;
  std::vector<std::string_view> path;  // keys into summary.json
};

// The headline numbers with their sigmas (schema/summary.h), units in the names.
const std::vector<Column>& HeadlineColumns() {
  namespace s = schema::summary;
  static const std::vector<Column> columns = {
      {std::string(s::kMeanArcRadiusMm), {s::kMeanArcRadiusMm}},
      {std::string(s::kMeanArcRadiusSigmaMm), {s::kMeanArcRadiusSigmaMm}},
      {std::string(s::kArcRadiusRangeMm), {s::kArcRadiusRangeMm}},
      {std::string(s::kArcRadiusExcessStdMm), {s::kArcRadiusExcessStdMm}},
      {std::string(s::kMeanCenterAxialMm), {s::kMeanCenterAxialMm}},
      {std::string(s::kMeanCenterAxialSigmaMm), {s::kMeanCenterAxialSigmaMm}},
      {std::string(s::kCenterAxialDeviationMm), {s::kCenterAxialDeviationMm}},
      {std::string(s::kMaxArcErrorUm), {s::kMaxArcErrorUm}},
      {std::string(s::kMaxRunoutUm), {s::kMaxRunoutUm}},
      {std::string(s::kMaxRoundnessUm), {s::kMaxRoundnessUm}},
      {std::string(s::kNoiseSigmaUm), {s::kNoiseSigmaUm}},
      {std::string(s::kUsablePhases), {s::kUsablePhases}},
      {"model_" + std::string(s::model::kMeanArcRadiusMm), {s::kModel, s::model::kMeanArcRadiusMm}},
      {"model_" + std::string(s::model::kMeanArcRadiusSigmaMm), {s::kModel, s::model::kMeanArcRadiusSigmaMm}},
      {"model_" + std::string(s::model::kArcRadiusRangeMm), {s::kModel, s::model::kArcRadiusRangeMm}},
      {"model_" + std::string(s::model::kArcRadiusRangeSigmaMm),
       {s::kModel, s::model::kArcRadiusRangeSigmaMm}},
  };
  return columns;
}

json Headline(const json& summary, const Column& column) {
  const json* value = &summary;
  for (std::string_view key : column.path) {
    if (!value->is_object()) return nullptr;
    const auto it = value->find(key);
    if (it == value->end()) return nullptr;
    value = &*it;
  }
  return value->is_number() ? *value : json();
}

json IndexRow(const BatchOptions& args, const Scan& scan, const Outcome& outcome) {
  json row = {{"scan", scan.path.string()},
              {"result", ResultFolder(args, scan).string()},
              {"status", StatusName(outcome.status)},
              {"exit_code", outcome.exit_code ? json(*outcome.exit_code) : json()},
              {"message", outcome.message},
              {"seconds", std::round(outcome.seconds * 1e3) / 1e3}};
  json summary;
  if (outcome.status == Status::kDone || outcome.status == Status::kReused) {
    try {
      summary = ReadJsonFile(ResultFolder(args, scan) / schema::summary::kFileName, kStage);
    } catch (const Error& e) {
      row["message"] = e.what();
    }
  }
  for (const Column& column : HeadlineColumns()) row[column.name] = Headline(summary, column);
  return row;
}

// RFC 4180: a cell with a comma, a quote or a line break is quoted, its quotes doubled.
std::string CsvCell(const json& value) {
  if (value.is_null()) return "";
  if (value.is_number_float()) return fmt::format("{}", value.get<double>());
  if (!value.is_string()) return JsonText(value);
  const std::string text = value.get<std::string>();
  if (text.find_first_of(",\"\r\n") == std::string::npos) return text;
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"') quoted += '"';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

}  // namespace

void WriteIndex(const BatchOptions& args, const std::vector<Scan>& scans,
                const std::vector<Outcome>& outcomes) {
  json rows = json::array();
  std::map<std::string, int> counts;
  for (size_t i = 0; i < scans.size(); ++i) {
    rows.push_back(IndexRow(args, scans[i], outcomes[i]));
    ++counts[std::string(StatusName(outcomes[i].status))];
  }
  const json index = {{"arcwheel_version", kVersion},
                      {"written_utc", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr)))},
                      {"output", args.outdir},
                      {"process_options", args.process_options},
                      {"counts", counts},
                      {"scans", rows}};
  std::string csv;
  const std::vector<std::string> fixed = {"scan", "result", "status", "exit_code", "message", "seconds"};
  std::vector<std::string> names = fixed;
  for (const Column& column : HeadlineColumns()) names.push_back(column.name);
  const auto append_line = [&csv](const std::vector<std::string>& cells) {
    for (size_t c = 0; c < cells.size(); ++c) {
      if (c > 0) csv += ',';
      csv += cells[c];
    }
    csv += '\n';
  };
  append_line(names);
  for (const json& row : rows) {
    std::vector<std::string> cells;
    for (const std::string& name : names) cells.push_back(CsvCell(row.at(name)));
    append_line(cells);
  }
  WriteFileAtomically(fs::path(args.outdir) / kIndexJson, JsonText(index, 2) + "\n");
  WriteFileAtomically(fs::path(args.outdir) / kIndexCsv, csv);
}

}  // namespace arcwheel::workflows::batch
