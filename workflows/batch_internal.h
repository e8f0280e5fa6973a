#pragma once
// What the files of workflows/batch*.cc share: the scans, their outcomes and where they go.

#include <sys/types.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "workflows/batch.h"

namespace arcwheel::workflows::batch {

namespace fs = std::filesystem;
using nlohmann::json;
using Clock = std::chrono::steady_clock;

constexpr const char* kStage = "batch";
// OUTDIR/logs/<scan name>.log (the child's output) and <scan name>.json (its outcome).
constexpr const char* kLogsFolder = "logs";
constexpr const char* kIndexCsv = "index.csv";
constexpr const char* kIndexJson = "index.json";

// One scan of the batch and where its result goes.
struct Scan {
  fs::path path;
  std::string name;  // the result folder OUTDIR/<name>
};

enum class Status { kNotRun, kDone, kReused, kFailed, kInterrupted };

std::string_view StatusName(Status status);
std::optional<Status> ParseStatus(const std::string& name);

struct Outcome {
  Status status = Status::kNotRun;
  std::optional<int> exit_code;
  std::string message;
  double seconds = 0.0;
};

// INPUTS -> scans (batch_plan.cc).
// Every scan once (the same file reached twice is one scan), named after its file. Two scans of
// one name would share a result folder: refused, naming both.
std::vector<Scan> PlanScans(const std::vector<std::string>& inputs);

// Records in OUTDIR (batch_records.cc).
fs::path ResultFolder(const BatchOptions& args, const Scan& scan);
fs::path LogPath(const BatchOptions& args, const Scan& scan);
const std::vector<std::string>& ResultFiles();
void WriteOutcome(const BatchOptions& args, const Scan& scan, const Outcome& outcome, const json& inputs);
// The outcome a batch (perhaps an array task elsewhere) recorded for the scan, if any.
// Only an outcome of the same input and options counts.
std::optional<Outcome> ReadOutcome(const BatchOptions& args, const Scan& scan, const json& inputs);
// The child's own error line ("arcwheel: bad input: ..."), else its last line.
std::string ChildMessage(const fs::path& log);

// Children (batch_children.cc).
fs::path ArcwheelBinary(const BatchOptions& args);
// `arcwheel process SCAN -o OUTDIR/NAME OPTIONS`, its output to the log.
::pid_t SpawnProcess(const BatchOptions& args, const Scan& scan);
// What the child's wait status says; a result folder that did not finish is removed.
Outcome Finish(const BatchOptions& args, const Scan& scan, int wait_status, double seconds,
               const json& inputs);

// Progress on stderr (batch_progress.cc).
class BatchProgress {
 public:
  explicit BatchProgress(size_t total);
  ~BatchProgress();
  BatchProgress(const BatchProgress&) = delete;
  BatchProgress& operator=(const BatchProgress&) = delete;
  void Report(const Scan& scan, const Outcome& outcome);
  // The bar: scans finished (failed), the rate of the scans run here, the time left at that rate.
  void Refresh();

 private:
  void ClearLine();
  size_t total_;
  size_t finished_ = 0, ran_ = 0, failed_ = 0;
  bool terminal_;
  bool line_open_ = false;
  Clock::time_point start_ = Clock::now();
};

// OUTDIR/index.csv and index.json (batch_index.cc).
void WriteIndex(const BatchOptions& args, const std::vector<Scan>& scans,
                const std::vector<Outcome>& outcomes);

// An array job of one task per scan (batch_slurm.cc).
std::string SlurmScript(const BatchOptions& args, const std::vector<Scan>& scans);

}  // namespace arcwheel::workflows::batch
