// arcwheel batch INPUTS... -o OUTDIR [-j N] [-- PROCESS OPTIONS]: many scans, one `arcwheel
// process` child each, a result folder each, an index of the headline numbers (docs/batch.md).

#include <fcntl.h>
#include <fmt/chrono.h>
#include <fmt/core.h>
#include <glob.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "cli/commands.h"
#include "cli/step_inputs.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/json_text.h"
#include "core/version.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"

extern char** environ;

namespace arcwheel::cli {

namespace {
// The arguments after `--` on the command line (main.cc takes them off before CLI11 parses).
std::vector<std::string>& PassThroughStorage() {
  static std::vector<std::string> options;
  return options;
}
}  // namespace

void SetBatchProcessOptions(std::vector<std::string> options) { PassThroughStorage() = std::move(options); }

// A named namespace: the command files are compiled as one unity translation unit.
namespace batch {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr const char* kStage = "batch";
// OUTDIR/logs/<scan name>.log (the child's output) and <scan name>.json (its outcome).
constexpr const char* kLogsFolder = "logs";
constexpr const char* kIndexCsv = "index.csv";
constexpr const char* kIndexJson = "index.json";

struct BatchArgs {
  std::vector<std::string> inputs;
  std::string outdir;
  int jobs = 1;
  std::string emit_slurm;
  std::vector<std::string> sbatch_lines;
  bool index_only = false;
  bool no_index = false;
  std::vector<std::string> process_options;
};

// One scan of the batch and where its result goes.
struct Scan {
  fs::path path;
  std::string name;  // the result folder OUTDIR/<name>
};

enum class Status { kNotRun, kDone, kReused, kFailed, kInterrupted };

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

struct Outcome {
  Status status = Status::kNotRun;
  std::optional<int> exit_code;
  std::string message;
  double seconds = 0.0;
};

// ------------------------------------------------------------------------------------------------
// INPUTS -> scans.

std::string Lower(std::string text) {
  std::transform(text.begin(), text.end(), text.begin(), [](unsigned char c) { return std::tolower(c); });
  return text;
}

bool IsScanFile(const fs::path& path) {
  const std::string extension = Lower(path.extension().string());
  return extension == ".h5" || extension == ".hdf5" || extension == ".csv";
}

std::vector<fs::path> ScansInFolder(const fs::path& folder) {
  std::vector<fs::path> scans;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && IsScanFile(entry.path())) scans.push_back(entry.path());
  }
  std::sort(scans.begin(), scans.end());
  return scans;
}

std::vector<fs::path> Glob(const std::string& pattern) {
  glob_t matches{};
  const int status = ::glob(pattern.c_str(), 0, nullptr, &matches);
  std::vector<fs::path> paths;
  if (status == 0) {
    for (size_t i = 0; i < matches.gl_pathc; ++i) paths.emplace_back(matches.gl_pathv[i]);
  }
  ::globfree(&matches);
  if (paths.empty()) {
    throw Error(ErrorCode::kInvalidOption, kStage, fmt::format("no file matches '{}'", pattern));
  }
  return paths;
}

// `@LIST`: one scan path a line; blank lines and lines starting with '#' are skipped, relative
// paths are relative to the list's folder.
std::vector<fs::path> ScansOfList(const fs::path& list) {
  std::ifstream in(list);
  if (!in) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot read the list '{}'", list.string()));
  std::vector<fs::path> scans;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    fs::path path = line;
    if (path.is_relative()) path = list.parent_path() / path;
    if (!fs::is_regular_file(path)) {
      throw Error(ErrorCode::kBadInput, kStage,
                  fmt::format("'{}' line {}: '{}' is not a file", list.string(), number, line));
    }
    scans.push_back(path);
  }
  return scans;
}

std::vector<fs::path> ExpandInput(const std::string& input) {
  if (!input.empty() && input[0] == '@') return ScansOfList(input.substr(1));
  if (fs::is_directory(input)) {
    std::vector<fs::path> scans = ScansInFolder(input);
    if (scans.empty()) {
      throw Error(ErrorCode::kInvalidOption, kStage,
                  fmt::format("the folder '{}' holds no .h5, .hdf5 or .csv scan", input));
    }
    return scans;
  }
  if (fs::is_regular_file(input)) return {input};
  if (input.find_first_of("*?[") != std::string::npos) return Glob(input);
  throw Error(ErrorCode::kInvalidOption, kStage,
              fmt::format("'{}' is neither a scan, a folder, a glob nor an @list", input));
}

// Every scan once (the same file reached twice is one scan), named after its file. Two scans of
// one name would share a result folder: refused, naming both.
std::vector<Scan> PlanScans(const std::vector<std::string>& inputs) {
  std::vector<Scan> scans;
  std::map<fs::path, size_t> by_file;
  std::map<std::string, size_t> by_name;
  for (const std::string& input : inputs) {
    for (const fs::path& path : ExpandInput(input)) {
      const fs::path file = fs::weakly_canonical(path);
      if (by_file.count(file) != 0) continue;
      const std::string name = path.stem().string();
      if (name == kLogsFolder) {
        throw Error(
            ErrorCode::kInvalidOption, kStage,
            fmt::format("the scan '{}' would be written to OUTDIR/{}, which holds the logs: rename it",
                        path.string(), name));
      }
      if (const auto clash = by_name.find(name); clash != by_name.end()) {
        throw Error(ErrorCode::kInvalidOption, kStage,
                    fmt::format("'{}' and '{}' would both be written to OUTDIR/{}: rename one, or run them "
                                "as two batches into different folders",
                                scans[clash->second].path.string(), path.string(), name));
      }
      by_file[file] = scans.size();
      by_name[name] = scans.size();
      scans.push_back({path, name});
    }
  }
  if (scans.empty()) throw Error(ErrorCode::kInvalidOption, kStage, "no scans given");
  return scans;
}

// The options go to every child unchanged; they are parsed once here by the process command's
// own definition, so that a typo stops the batch before any scan runs.
void CheckProcessOptions(const std::vector<std::string>& options, const fs::path& some_scan) {
  for (const std::string& option : options) {
    if (option.rfind("-o", 0) == 0 || option.rfind("--output", 0) == 0) {
      throw Error(
          ErrorCode::kInvalidOption, kStage,
          "the process options after -- must not set the output folder: batch writes OUTDIR/<scan name>");
    }
  }
  CLI::App app{"arcwheel", "arcwheel"};
  app.require_subcommand(1);
  AddProcessCommand(app);
  // Runs once every option is converted and checked, before the process command's own callback:
  // stop there, the options are valid.
  app.parse_complete_callback([] { throw CLI::Success(); });
  std::vector<std::string> arguments = {"process", some_scan.string(), "-o", "unused"};
  arguments.insert(arguments.end(), options.begin(), options.end());
  std::reverse(arguments.begin(), arguments.end());  // CLI11 takes them last first
  try {
    app.parse(arguments);
  } catch (const CLI::Success&) {
    return;
  } catch (const CLI::ParseError& error) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("the process options after --: {}", error.what()));
  }
  throw Error(ErrorCode::kInternal, kStage, "the process options were not checked");
}

// ------------------------------------------------------------------------------------------------
// Records in OUTDIR.

fs::path ResultFolder(const BatchArgs& args, const Scan& scan) { return fs::path(args.outdir) / scan.name; }
fs::path LogPath(const BatchArgs& args, const Scan& scan) {
  return fs::path(args.outdir) / kLogsFolder / (scan.name + ".log");
}
fs::path OutcomePath(const BatchArgs& args, const Scan& scan) {
  return fs::path(args.outdir) / kLogsFolder / (scan.name + ".json");
}

const std::vector<std::string>& ResultFiles() {
  static const std::vector<std::string> files = {std::string(schema::summary::kFileName),
                                                 std::string(schema::wheel_map::kFileName)};
  return files;
}

void WriteOutcome(const BatchArgs& args, const Scan& scan, const Outcome& outcome, const json& inputs) {
  const json record = {{"scan", scan.path.string()},
                       {"status", StatusName(outcome.status)},
                       {"exit_code", outcome.exit_code ? json(*outcome.exit_code) : json()},
                       {"message", outcome.message},
                       {"seconds", std::round(outcome.seconds * 1e3) / 1e3},
                       {"inputs", inputs}};
  WriteFileAtomically(OutcomePath(args, scan), record.dump(2) + "\n");
}

// The outcome a batch (perhaps an array task elsewhere) recorded for the scan, if any.
// Only an outcome of the same input and options counts.
std::optional<Outcome> ReadOutcome(const BatchArgs& args, const Scan& scan, const json& inputs) {
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

// ------------------------------------------------------------------------------------------------
// Children.

struct Child {
  pid_t pid = 0;
  size_t scan = 0;
  Clock::time_point start;
};

fs::path ThisBinary() { return fs::read_symlink("/proc/self/exe"); }

// `arcwheel process SCAN -o OUTDIR/NAME OPTIONS`, its output to the log. In its own process group,
// so that a Ctrl-C reaches only the batch, which then stops each child with one SIGTERM; started
// with SIGINT and SIGTERM blocked until its handlers are in place (core/interrupt.cc).
pid_t SpawnProcess(const BatchArgs& args, const Scan& scan) {
  const std::string binary = ThisBinary().string();
  std::vector<std::string> arguments = {binary, "process", scan.path.string(), "-o",
                                        ResultFolder(args, scan).string()};
  arguments.insert(arguments.end(), args.process_options.begin(), args.process_options.end());
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  const std::string log = LogPath(args, scan).string();

  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t blocked;
  sigemptyset(&blocked);
  sigaddset(&blocked, SIGINT);
  sigaddset(&blocked, SIGTERM);
  posix_spawnattr_setsigmask(&attributes, &blocked);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETPGROUP);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, binary.c_str(), &files, &attributes, argv.data(), environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&files);
  if (error != 0) {
    throw Error(ErrorCode::kIo, kStage, fmt::format("cannot start '{}': {}", binary, std::strerror(error)));
  }
  return pid;
}

// What the child's wait status says; a result folder that did not finish is removed, so that
// only complete results stay (the child's OutputSet removes its own; this covers a crash).
Outcome Finish(const BatchArgs& args, const Scan& scan, int wait_status, double seconds, const json& inputs) {
  Outcome outcome{.status = Status::kFailed, .exit_code = std::nullopt, .message = {}, .seconds = seconds};
  const fs::path folder = ResultFolder(args, scan);
  if (WIFEXITED(wait_status)) {
    outcome.exit_code = WEXITSTATUS(wait_status);
    outcome.message = ChildMessage(LogPath(args, scan));
  } else if (WIFSIGNALED(wait_status)) {
    const int signal = WTERMSIG(wait_status);
    outcome.exit_code = 128 + signal;
    outcome.message = fmt::format("killed by signal {} ({})", signal, ::strsignal(signal));
  }
  if (outcome.exit_code == 0) {
    bool complete = true;
    for (const std::string& file : ResultFiles()) complete = complete && fs::exists(folder / file);
    if (complete) {
      WriteFileAtomically(folder / kStepInputsFileName, inputs.dump(2) + "\n");
      outcome.status = Status::kDone;
      outcome.message.clear();
      return outcome;
    }
    outcome.message = "the child exited with 0 but left no complete result";
  }
  if (outcome.exit_code == ExitStatus(ErrorCode::kInterrupted) && InterruptRequested()) {
    outcome.status = Status::kInterrupted;
  }
  std::error_code ignored;
  fs::remove_all(folder, ignored);
  return outcome;
}

// ------------------------------------------------------------------------------------------------
// Progress: a refreshed line on a terminal, a plain line per scan otherwise.

std::string Duration(double seconds) {
  const long s = std::lround(seconds);
  if (s >= 3600) return fmt::format("{}h{:02}m", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{}m{:02}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

class BatchProgress {
 public:
  explicit BatchProgress(size_t total) : total_(total), terminal_(::isatty(STDERR_FILENO) == 1) {}
  ~BatchProgress() { ClearLine(); }
  BatchProgress(const BatchProgress&) = delete;
  BatchProgress& operator=(const BatchProgress&) = delete;

  void Report(const Scan& scan, const Outcome& outcome) {
    ++finished_;
    if (outcome.status == Status::kDone || outcome.status == Status::kFailed) ++ran_;
    if (outcome.status == Status::kFailed) ++failed_;
    std::string line;
    switch (outcome.status) {
      case Status::kDone:
        line = fmt::format("done {} in {:.1f} s", scan.name, outcome.seconds);
        break;
      case Status::kReused:
        line = fmt::format("reused {}: finished earlier with the same input and options", scan.name);
        break;
      case Status::kFailed:
        line = fmt::format("FAILED {} ({}, exit status {}): {}", scan.name, scan.path.string(),
                           outcome.exit_code ? std::to_string(*outcome.exit_code) : "none", outcome.message);
        break;
      case Status::kInterrupted:
        line = fmt::format("interrupted {}", scan.name);
        break;
      case Status::kNotRun:
        break;
    }
    if (terminal_ && outcome.status != Status::kFailed) {
      Refresh();
      return;
    }
    ClearLine();
    fmt::print(stderr, "batch: [{}/{}] {}\n", finished_, total_, line);
    Refresh();
  }

  // The bar: scans finished (failed), the rate of the scans run here, the time left at that rate.
  void Refresh() {
    if (!terminal_) return;
    const double elapsed_s = std::chrono::duration<double>(Clock::now() - start_).count();
    std::string rate = "";
    if (ran_ > 0 && elapsed_s > 0) {
      const double per_s = static_cast<double>(ran_) / elapsed_s;
      rate = fmt::format(", {:.2f} scans/s, about {} left", per_s,
                         Duration(static_cast<double>(total_ - finished_) / per_s));
    }
    const int width = 24;
    const int filled = total_ == 0 ? width : static_cast<int>(width * finished_ / total_);
    fmt::print(stderr, "\r\033[Kbatch [{}{}] {}/{} scans, {} failed{}", std::string(filled, '#'),
               std::string(width - filled, '.'), finished_, total_, failed_, rate);
    std::fflush(stderr);
    line_open_ = true;
  }

 private:
  void ClearLine() {
    if (line_open_) fmt::print(stderr, "\r\033[K");
    line_open_ = false;
  }
  size_t total_;
  size_t finished_ = 0, ran_ = 0, failed_ = 0;
  bool terminal_;
  bool line_open_ = false;
  Clock::time_point start_ = Clock::now();
};

// ------------------------------------------------------------------------------------------------
// The index.

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

json IndexRow(const BatchArgs& args, const Scan& scan, const Outcome& outcome) {
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
  if (!value.is_string()) return value.dump();
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

void WriteIndex(const BatchArgs& args, const std::vector<Scan>& scans, const std::vector<Outcome>& outcomes) {
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
  WriteFileAtomically(fs::path(args.outdir) / kIndexJson, index.dump(2) + "\n");
  WriteFileAtomically(fs::path(args.outdir) / kIndexCsv, csv);
}

// ------------------------------------------------------------------------------------------------
// Running.

json ScanInputs(const BatchArgs& args, const Scan& scan) {
  return StepInputs({{"scan", scan.path}}, args.process_options);
}

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Starts the next scan unless it is finished already; false when it was reused or could not
// be started (its outcome is then set).
bool StartOrReuse(const BatchArgs& args, const Scan& scan, Outcome& outcome, std::vector<json>& inputs,
                  size_t index, std::vector<Child>& running) {
  const Clock::time_point start = Clock::now();
  try {
    inputs[index] = ScanInputs(args, scan);
  } catch (const Error& e) {
    outcome = {
        .status = Status::kFailed, .exit_code = ExitStatus(e.code()), .message = e.what(), .seconds = 0};
    return false;
  }
  if (UpToDate(ResultFolder(args, scan), ResultFiles(), inputs[index])) {
    outcome = {.status = Status::kReused, .exit_code = 0, .message = {}, .seconds = 0};
    return false;
  }
  try {
    // Whatever is there was made from other inputs or did not finish.
    fs::remove_all(ResultFolder(args, scan));
    running.push_back({.pid = SpawnProcess(args, scan), .scan = index, .start = start});
  } catch (const std::exception& e) {
    outcome = {.status = Status::kFailed,
               .exit_code = ExitStatus(ErrorCode::kIo),
               .message = e.what(),
               .seconds = SecondsSince(start)};
    return false;
  }
  return true;
}

// Stops every running child with one SIGTERM and waits for it.
void StopChildren(const BatchArgs& args, const std::vector<Scan>& scans, std::vector<Child>& running,
                  std::vector<Outcome>& outcomes, const std::vector<json>& inputs, BatchProgress& progress) {
  for (const Child& child : running) ::kill(child.pid, SIGTERM);
  for (const Child& child : running) {
    int status = 0;
    while (::waitpid(child.pid, &status, 0) < 0 && errno == EINTR) {
    }
    outcomes[child.scan] =
        Finish(args, scans[child.scan], status, SecondsSince(child.start), inputs[child.scan]);
    WriteOutcome(args, scans[child.scan], outcomes[child.scan], inputs[child.scan]);
    progress.Report(scans[child.scan], outcomes[child.scan]);
  }
  running.clear();
}

// Keeps -j children running until every scan has an outcome or a signal arrives.
void RunLoop(const BatchArgs& args, const std::vector<Scan>& scans, std::vector<Outcome>& outcomes,
             std::vector<json>& inputs, std::vector<Child>& running, BatchProgress& progress) {
  size_t next = 0;
  auto last_refresh = Clock::now();
  while (next < scans.size() || !running.empty()) {
    if (InterruptRequested()) {
      StopChildren(args, scans, running, outcomes, inputs, progress);
      break;
    }
    while (running.size() < static_cast<size_t>(args.jobs) && next < scans.size() && !InterruptRequested()) {
      const size_t index = next++;
      if (!StartOrReuse(args, scans[index], outcomes[index], inputs, index, running)) {
        if (outcomes[index].status == Status::kFailed) {
          WriteOutcome(args, scans[index], outcomes[index], inputs[index]);
        }
        progress.Report(scans[index], outcomes[index]);
      }
    }
    for (auto child = running.begin(); child != running.end();) {
      int status = 0;
      if (::waitpid(child->pid, &status, WNOHANG) != child->pid) {
        ++child;
        continue;
      }
      Outcome& outcome = outcomes[child->scan];
      outcome = Finish(args, scans[child->scan], status, SecondsSince(child->start), inputs[child->scan]);
      WriteOutcome(args, scans[child->scan], outcome, inputs[child->scan]);
      progress.Report(scans[child->scan], outcome);
      child = running.erase(child);
    }
    if (!running.empty()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
    if (SecondsSince(last_refresh) > 0.5) {
      progress.Refresh();
      last_refresh = Clock::now();
    }
  }
}

std::vector<Outcome> RunScans(const BatchArgs& args, const std::vector<Scan>& scans) {
  std::vector<Outcome> outcomes(scans.size());
  std::vector<json> inputs(scans.size());
  std::vector<Child> running;
  BatchProgress progress(scans.size());
  try {
    RunLoop(args, scans, outcomes, inputs, running, progress);
  } catch (...) {
    // The batch itself failed (it cannot write OUTDIR): no child may outlive it unrecorded.
    for (const Child& child : running) ::kill(child.pid, SIGTERM);
    for (const Child& child : running) {
      int status = 0;
      while (::waitpid(child.pid, &status, 0) < 0 && errno == EINTR) {
      }
      std::error_code ignored;
      fs::remove_all(ResultFolder(args, scans[child.scan]), ignored);
    }
    throw;
  }
  return outcomes;
}

// The outcome of each scan as OUTDIR holds it, running nothing.
std::vector<Outcome> ReadOutcomes(const BatchArgs& args, const std::vector<Scan>& scans) {
  std::vector<Outcome> outcomes(scans.size());
  for (size_t i = 0; i < scans.size(); ++i) {
    json inputs;
    try {
      inputs = ScanInputs(args, scans[i]);
    } catch (const Error& e) {
      outcomes[i] = {
          .status = Status::kFailed, .exit_code = ExitStatus(e.code()), .message = e.what(), .seconds = 0};
      continue;
    }
    const std::optional<Outcome> recorded = ReadOutcome(args, scans[i], inputs);
    if (UpToDate(ResultFolder(args, scans[i]), ResultFiles(), inputs)) {
      outcomes[i] = {.status = Status::kDone,
                     .exit_code = 0,
                     .message = {},
                     .seconds = recorded ? recorded->seconds : 0.0};
    } else if (recorded && recorded->status != Status::kDone && recorded->status != Status::kReused) {
      outcomes[i] = *recorded;
    } else {
      outcomes[i].message = "no finished result for this input and these options";
    }
  }
  return outcomes;
}

// ------------------------------------------------------------------------------------------------
// Slurm.

std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  quoted += '\'';
  return quoted;
}

// An #SBATCH option's value as sbatch reads it: inside double quotes a space does not end the
// value, and a backslash keeps the next character (a quote, a backslash, or a '#', which would
// otherwise start a comment even inside quotes).
std::string SbatchQuote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\' || c == '#') quoted += '\\';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

std::string QuotedList(const std::vector<std::string>& words) {
  std::string text;
  for (const std::string& word : words) {
    text += ' ';
    text += ShellQuote(word);
  }
  return text;
}

// An array job of one task per scan; each task is a batch of one scan, which runs the same
// `arcwheel process` child into the same OUTDIR/<scan name> and records it as a local batch does.
std::string SlurmScript(const BatchArgs& args, const std::vector<Scan>& scans) {
  const std::string binary = ThisBinary().string();
  const std::string outdir = fs::absolute(args.outdir).string();
  std::vector<std::string> inputs;
  for (const std::string& input : args.inputs) inputs.push_back(input);
  const std::string options = args.process_options.empty() ? "" : " --" + QuotedList(args.process_options);
  std::string script = fmt::format(
      "#!/bin/bash\n"
      "# arcwheel {} batch as a Slurm array job: one task per scan ({} scans). Each task runs\n"
      "#   arcwheel batch SCAN -o OUTDIR --no-index -- OPTIONS\n"
      "# a batch of one scan: `arcwheel process SCAN -o OUTDIR/<scan name> OPTIONS` as a child, its\n"
      "# result recorded as a local batch records it (a finished scan is skipped on a rerun).\n"
      "# Submit:  sbatch {}\n"
      "# Index, when the tasks have ended (or: sbatch --dependency=afterany:JOBID --wrap '...'):\n"
      "#   cd {} && {} batch{} -o {} --index-only{}\n"
      "#SBATCH --job-name=arcwheel-batch\n"
      "#SBATCH --array=0-{}\n"
      "#SBATCH --ntasks=1\n"
      "#SBATCH --cpus-per-task=1\n"
      "#SBATCH --chdir={}\n"
      "#SBATCH --output={}\n",
      kVersion, scans.size(), ShellQuote(fs::absolute(args.emit_slurm).string()),
      ShellQuote(fs::current_path().string()), ShellQuote(binary), QuotedList(inputs), ShellQuote(outdir),
      options, scans.size() - 1, SbatchQuote(fs::current_path().string()),
      SbatchQuote((fs::path(outdir) / kLogsFolder / "slurm-%A_%a.out").string()));
  for (const std::string& line : args.sbatch_lines) script += "#SBATCH " + line + "\n";
  script += "set -euo pipefail\nscans=(\n";
  for (const Scan& scan : scans) script += "  " + ShellQuote(fs::absolute(scan.path).string()) + "\n";
  script += ")\n";
  script += fmt::format("exec {} batch \"${{scans[$SLURM_ARRAY_TASK_ID]}}\" -o {} --no-index{}\n",
                        ShellQuote(binary), ShellQuote(outdir), options);
  return script;
}

// ------------------------------------------------------------------------------------------------

void RunBatch(BatchArgs& args) {
  args.process_options = PassThroughStorage();
  if (args.jobs < 1)
    throw Error(ErrorCode::kInvalidOption, kStage, fmt::format("-j {} violates >= 1", args.jobs));
  const std::vector<Scan> scans = PlanScans(args.inputs);
  CheckProcessOptions(args.process_options, scans.front().path);
  EnsureDirectory(fs::path(args.outdir) / kLogsFolder);
  if (!args.emit_slurm.empty()) {
    WriteFileAtomically(args.emit_slurm, SlurmScript(args, scans));
    fs::permissions(args.emit_slurm, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
    fmt::print("slurm: {} ({} array tasks); submit with `sbatch {}`\n", args.emit_slurm, scans.size(),
               args.emit_slurm);
    return;
  }
  const std::vector<Outcome> outcomes = args.index_only ? ReadOutcomes(args, scans) : RunScans(args, scans);
  std::map<Status, size_t> counts;
  for (const Outcome& outcome : outcomes) ++counts[outcome.status];
  if (!args.no_index) WriteIndex(args, scans, outcomes);
  const std::string index = args.no_index
                                ? std::string()
                                : fmt::format("; index: {}", (fs::path(args.outdir) / kIndexCsv).string());
  fmt::print("batch: {} scans: {} done, {} reused, {} failed, {} interrupted, {} not run{}\n", scans.size(),
             counts[Status::kDone], counts[Status::kReused], counts[Status::kFailed],
             counts[Status::kInterrupted], counts[Status::kNotRun], index);
  ThrowIfInterrupted();
  const size_t unfinished = counts[Status::kFailed] + counts[Status::kInterrupted] + counts[Status::kNotRun];
  if (unfinished > 0) {
    throw SomeFailed(fmt::format("batch: {} of {} scans have no result{}", unfinished, scans.size(),
                                 args.no_index ? std::string()
                                               : fmt::format(" (the index names them: {})",
                                                             (fs::path(args.outdir) / kIndexCsv).string())));
  }
}

}  // namespace batch

void AddBatchCommand(CLI::App& app) {
  auto args = std::make_shared<batch::BatchArgs>();
  CLI::App* cmd =
      app.add_subcommand("batch", "process many scans, each into OUTDIR/<scan name>, with an index");
  cmd->footer(
      "INPUTS: scan files, folders (their *.h5, *.hdf5, *.csv), globs, and @LIST files (one path a\n"
      "line, # comments; relative paths from the list's folder). A scan's result folder is named\n"
      "after its file without the extension; two scans of one name are refused.\n"
      "Options after -- go unchanged to every `arcwheel process` (e.g. -- --phases 180 --no-model).\n"
      "Each scan runs as a child `arcwheel process`; a scan whose input SHA-256 and options match a\n"
      "finished result is reused. OUTDIR/index.csv and index.json list every scan: status, exit\n"
      "status, message, the headline numbers with their sigmas. OUTDIR/logs/<name>.log holds each\n"
      "child's output. Exit status 0 when every scan has a result, 6 when some have none,\n"
      "130 when interrupted (finished results and the index are kept). See docs/batch.md.");
  cmd->add_option("INPUTS", args->inputs, "scans, folders, globs, @lists")->required();
  cmd->add_option("-o,--output", args->outdir, "output folder")->required();
  cmd->add_option("-j,--jobs", args->jobs, "scans processed at once")->capture_default_str();
  cmd->add_option("--emit-slurm", args->emit_slurm,
                  "write an sbatch array script (one task per scan) instead of running");
  cmd->add_option("--sbatch", args->sbatch_lines,
                  "with --emit-slurm: an extra #SBATCH line, e.g. --sbatch=--partition=short (repeatable)");
  cmd->add_flag("--index-only", args->index_only,
                "run nothing: write the index of what OUTDIR holds (after a Slurm or HTCondor run)");
  cmd->add_flag("--no-index", args->no_index, "write no index (each Slurm array task)");
  cmd->callback([args] { batch::RunBatch(*args); });
}

}  // namespace arcwheel::cli
