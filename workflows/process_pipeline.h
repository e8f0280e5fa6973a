#pragma once
// The `arcwheel process` pipeline as one library call: read the scan, process it
// (processing/process_scan.h), fit every phase (wheel_fit.h) and the wheel model (wheel_model.h),
// and write summary.json and wheel_map.h5 (outputs.h). The command line and the Python module
// both call it, so that there is one definition of what `process` computes and writes.

#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "acquisition/profile_scan.h"
#include "acquisition/scan.h"
#include "acquisition/scan_settings.h"
#include "core/progress.h"
#include "core/stage_clock.h"
#include "fitting/outputs.h"
#include "fitting/wheel_fit.h"
#include "fitting/wheel_model.h"
#include "processing/process_scan.h"
#include "reports/tolerances.h"
#include "uncertainty/budget_json.h"
#include "uncertainty/wheel_uncertainty.h"
#include "workflows/characteristics_step.h"

namespace arcwheel::workflows {

// Every option of `arcwheel process` that reaches the computation, at the command's defaults; the
// command line, Python and the run record bind them from one table (process_options.h).
struct ProcessPipelineOptions {
  processing::ProcessOptions processing;
  fitting::WheelFitOptions fit;
  fitting::WheelModelOptions model;
  bool no_model = false;  // skip the wheel model
  // The uncertainty of every headline figure (docs/uncertainty.md): the type B budget file
  // (`--uncertainty FILE`; empty = the default budget of the simulated sensor), read and checked
  // with the other options, before the scan; `no_uncertainty` leaves summary.json without it.
  std::string uncertainty_budget_path;
  bool no_uncertainty = false;
  uncertainty::WheelUncertaintyOptions uncertainty;
  // formats.md 2.4: the scan's settings from outside the file (`--scan-settings FILE`: spindle
  // speed, feed, sample period, start position, radius sign, names), read and checked with the
  // other options, before the scan; they fill what the file does not give, and a value the file
  // gives otherwise is refused (exit 2).
  std::string scan_settings_path;
  // formats.md 2.4: the reader by name (`--format`: hdf5, csv, sensortool, keyence-lk, columns;
  // empty: by the extension and a sniff of the header) and the column map of a delimited file
  // (`--columns z=NAME[:UNIT],t=NAME[:UNIT],...`), both checked with the other options.
  std::string scan_format;
  std::string columns;
  // The tolerances (`--tolerances FILE`, reports/tolerances.h), read by the caller before the
  // scan: with the uncertainty, every toleranced quantity is decided by the file's rule (ISO
  // 14253-1 by default) and summary.json's "uncertainty" carries the rule and the decisions.
  std::optional<reports::Tolerances> tolerances;
  // The operators of the form characteristics (docs/characteristics.md); a tolerance file's
  // operator replaces them for its characteristic. A cut-off of 0 means no filter.
  double roundness_filter_upr = 50.0;
  characteristics::Association roundness_association = characteristics::Association::kMinimumZone;
  double runout_filter_upr = 50.0;
  double arc_error_filter_mm = 0.0;
  characteristics::Association arc_error_association = characteristics::Association::kMinimumZone;
  // Problems met while the options were bound from text (an unknown choice, process_options.h),
  // reported by ResolveProcessPipelineOptions with every other problem.
  std::vector<std::string> binding_problems;
  // Filled by ResolveProcessPipelineOptions from uncertainty_budget_path.
  std::optional<uncertainty::BudgetFile> uncertainty_budget;
  // Filled by ResolveProcessPipelineOptions from scan_settings_path.
  std::optional<acquisition::ScanSettingsFile> scan_settings;
};

// Checks every option of both stages (and of the
// model unless no_model); throws one Error{kInvalidOption, "process"} listing every problem.
void ResolveProcessPipelineOptions(ProcessPipelineOptions& options);

struct ProcessPipelineResult {
  fitting::RunRecord record;  // what summary.json says of the input and the parameters
  processing::ProcessedScan processed;
  fitting::WheelFit fit;
  std::optional<fitting::WheelModel> model;  // empty with no_model, or when the model could not be fitted
  std::optional<uncertainty::WheelUncertainty> uncertainty;  // empty with no_uncertainty
  std::optional<CharacteristicsResult> characteristics;      // empty with no_uncertainty
  StageClock clock;  // wall time of each step (`arcwheel process --timings`)
};

// Reads the scan at `scan_path` (acquisition::ReadScan, float32 readings kept as float32),
// hashes the file on a second thread (beside a text file's parsing; after an HDF5 file's read,
// beside the later stages), and runs the pipeline. The record states
// `scan_path` as given (converted to UTF-8). When `outdir` is not empty, writes
// OUTDIR/summary.json and OUTDIR/wheel_map.h5 (fitting::WriteProcessOutputs: nothing partial on failure).
// Throws Error: kInvalidOption for bad options (before the scan is read), kBadInput/kIo from the
// reader, kFitFailed when no phase gives a usable fit, kInterrupted when a signal arrives
// (core/interrupt.h).
[[nodiscard]] ProcessPipelineResult RunProcessPipeline(const std::string& scan_path,
                                                       const std::filesystem::path& outdir,
                                                       ProcessPipelineOptions options, Progress& progress);

// The same for a scan already in memory, e.g. a simulated one: nothing is read or hashed, and the
// record states scan.path and `input_sha256` as given (empty when the samples came from no file).
[[nodiscard]] ProcessPipelineResult RunProcessPipeline(acquisition::Scan scan, std::string input_sha256,
                                                       const std::filesystem::path& outdir,
                                                       ProcessPipelineOptions options, Progress& progress);

// The same for a line-profile scan already in memory (acquisition/profile_scan.h), e.g. a simulated
// one; its placement and settings are taken as they are. docs/processing.md, "Line-profile scans".
[[nodiscard]] ProcessPipelineResult RunProcessPipeline(acquisition::ProfileScan scan,
                                                       std::string input_sha256,
                                                       const std::filesystem::path& outdir,
                                                       ProcessPipelineOptions options, Progress& progress);

}  // namespace arcwheel::workflows
