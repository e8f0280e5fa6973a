#pragma once
// Writers of `summary.json` and `wheel_map.h5` (formats.md section 3, docs/outputs.md). Both
// files are staged under temporary names and renamed together only when both are complete.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/scan.h"
#include "fitting/wheel_fit.h"
#include "fitting/wheel_model.h"
#include "processing/process_scan.h"

namespace arcwheel::fitting {

struct RunRecord {
  std::string input_path;
  std::string input_sha256;
  std::string input_format;  // a name of acquisition/scan_format.h, or "memory" for a scan no reader made
  acquisition::ScanMetadata metadata;
  acquisition::ScanReadRecord read;  // what the reader read: columns, markers, settings' sources
  bool has_encoder = false;
  // Every processing parameter as used, in the order to print.
  std::vector<std::pair<std::string, double>> numeric_parameters;
  std::vector<std::pair<std::string, std::string>> text_parameters;
};

// Writes OUTDIR/summary.json and OUTDIR/wheel_map.h5; creates OUTDIR if needed. `later_stages`,
// when given, is an object whose members are summary.json's objects of the stages after the fit
// ("uncertainty", uncertainty/wheel_uncertainty.h; "characteristics", workflows/characteristics_step.h).
// Throws Error{kIo}; on any failure neither file is replaced.
void WriteProcessOutputs(const std::filesystem::path& outdir, const RunRecord& record,
                         const processing::ProcessedScan& processed, const WheelFit& fit,
                         const WheelModel* model = nullptr, const nlohmann::json* later_stages = nullptr);

// The summary document alone (what WriteProcessOutputs writes to summary.json).
[[nodiscard]] std::string SummaryJson(const RunRecord& record, const processing::ProcessedScan& processed,
                                      const WheelFit& fit, const WheelModel* model = nullptr,
                                      const nlohmann::json* later_stages = nullptr);

}  // namespace arcwheel::fitting
