#include "workflows/batch.h"

#include <fmt/core.h>
#include <signal.h>
#include <sys/wait.h>

#include <cerrno>
#include <map>
#include <thread>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "store/records.h"
#include "workflows/batch_internal.h"
#include "workflows/record.h"
#include "workflows/step_inputs.h"

namespace arcwheel::workflows {
namespace batch {
namespace {

struct Child {
  pid_t pid = 0;
  size_t scan = 0;
  Clock::time_point start;
};

// The scan and, when the process options give one, the settings from outside it (formats.md 2.4),
// by their SHA-256: an edited settings file makes every scan run again.
json ScanInputs(const BatchOptions& args, const Scan& scan) {
  std::vector<std::pair<std::string, fs::path>> files = {{"scan", scan.path}};
  const std::vector<std::string>& options = args.process_options;
  constexpr std::string_view kFlag = "--scan-settings";
  for (std::size_t i = 0; i < options.size(); ++i) {
    if (options[i] == kFlag && i + 1 < options.size()) files.emplace_back("scan_settings", options[i + 1]);
    if (options[i].starts_with(std::string(kFlag) + "="))
      files.emplace_back("scan_settings", options[i].substr(kFlag.size() + 1));
  }
  return StepInputs(files, args.process_options);
}

double SecondsSince(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// Starts the next scan unless it is finished already; false when it was reused or could not
// be started (its outcome is then set).
bool StartOrReuse(const BatchOptions& args, const Scan& scan, Outcome& outcome, std::vector<json>& inputs,
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
void StopChildren(const BatchOptions& args, const std::vector<Scan>& scans, std::vector<Child>& running,
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
void RunLoop(const BatchOptions& args, const std::vector<Scan>& scans, std::vector<Outcome>& outcomes,
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

std::vector<Outcome> RunScans(const BatchOptions& args, const std::vector<Scan>& scans) {
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

// A scan reused from an earlier batch that recorded into no store or another one: recorded now,
// once (a result the store holds already, by folder and scan SHA-256, is not recorded again).
void RecordReused(const BatchOptions& args, const std::vector<Scan>& scans,
                  const std::vector<Outcome>& outcomes, store::Store& results) {
  for (size_t i = 0; i < scans.size(); ++i) {
    if (outcomes[i].status != Status::kReused) continue;
    std::vector<store::StoredRun> runs = {store::ProcessRun(ResultFolder(args, scans[i]), kStage)};
    const store::StoredInput& scan = runs.front().inputs.front();
    if (results.HasRun(runs.front().command, runs.front().output_folder, scan.role, scan.sha256)) continue;
    results.Record(runs);
  }
}

// The outcome of each scan as OUTDIR holds it, running nothing.
std::vector<Outcome> ReadOutcomes(const BatchOptions& args, const std::vector<Scan>& scans) {
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

// The result folder is batch's to choose: OUTDIR/<scan name>.
void CheckOutputNotSet(const std::vector<std::string>& options) {
  for (const std::string& option : options) {
    if (option.rfind("-o", 0) == 0 || option.rfind("--output", 0) == 0) {
      throw Error(
          ErrorCode::kInvalidOption, kStage,
          "the process options after -- must not set the output folder: batch writes OUTDIR/<scan name>");
    }
    if (option.rfind("--db", 0) == 0) {
      throw Error(ErrorCode::kInvalidOption, kStage,
                  "the process options after -- must not name a store: give --db to batch, which hands it "
                  "to every scan");
    }
  }
}

}  // namespace
}  // namespace batch

BatchReport RunBatch(const BatchOptions& options) {
  using namespace batch;
  // Every child records into the store this batch names, which is checked (and an empty one given
  // its schema, once, before two children could race to create it) before anything is written.
  BatchOptions args = options;
  args.db = store::StoreLocation(options.db);
  if (args.jobs < 1)
    throw Error(ErrorCode::kInvalidOption, kStage, fmt::format("-j {} violates >= 1", args.jobs));
  const std::vector<Scan> scans = PlanScans(args.inputs);
  CheckOutputNotSet(args.process_options);
  if (args.check_process_options) args.check_process_options(args.process_options, scans.front().path);
  std::optional<store::Store> results;
  if (!args.db.empty() && !args.index_only) results = OpenRunStore(args.db);
  EnsureDirectory(fs::path(args.outdir) / kLogsFolder);
  BatchReport report;
  report.scans = scans.size();
  if (!args.emit_slurm.empty()) {
    WriteFileAtomically(args.emit_slurm, SlurmScript(args, scans));
    fs::permissions(args.emit_slurm, fs::perms::owner_exec | fs::perms::group_exec, fs::perm_options::add);
    report.slurm_script = args.emit_slurm;
    return report;
  }
  const std::vector<Outcome> outcomes = args.index_only ? ReadOutcomes(args, scans) : RunScans(args, scans);
  if (results) RecordReused(args, scans, outcomes, *results);
  std::map<Status, size_t> counts;
  for (const Outcome& outcome : outcomes) ++counts[outcome.status];
  if (!args.no_index) {
    WriteIndex(args, scans, outcomes);
    report.index_csv = fs::path(args.outdir) / kIndexCsv;
  }
  report.done = counts[Status::kDone];
  report.reused = counts[Status::kReused];
  report.failed = counts[Status::kFailed];
  report.interrupted = counts[Status::kInterrupted];
  report.not_run = counts[Status::kNotRun];
  return report;
}

}  // namespace arcwheel::workflows
