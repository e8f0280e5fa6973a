#pragma once
// What workflows/regenerate.cc (the chain) and regenerate_report.cc (its report and record)
// share: the steps' folders and files.

#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "schema/polish_outputs.h"
#include "schema/regenerate_outputs.h"
#include "schema/summary.h"
#include "schema/toolpath_outputs.h"
#include "schema/wheel_map.h"
#include "workflows/regenerate.h"

namespace arcwheel::workflows::regenerate {

namespace fs = std::filesystem;

constexpr const char* kRegenerateStage = "regenerate";
// In OUTDIR: the headline numbers of a finished regeneration, written last.
inline const std::string kRecordFileName(schema::regenerate::kRecordFileName);
inline const std::string kNominalPathFileName(schema::regenerate::kNominalPathFileName);
inline const std::string kPredictionFileName(schema::toolpath::kPredictionFileName);
inline const std::string kToolpathSummaryFileName(schema::toolpath::kSummaryFileName);

// One step of the chain: its folder in OUTDIR and the files that show it complete.
struct ChainStepSpec {
  int number;
  std::string id;
  std::vector<std::string> outputs;
};
const ChainStepSpec kWheelStep{
    1, "wheel", {std::string(schema::summary::kFileName), std::string(schema::wheel_map::kFileName)}};
const ChainStepSpec kToolpathStep{2, "toolpath", {kToolpathSummaryFileName, kPredictionFileName}};
const ChainStepSpec kPolishStep{3,
                                "polish",
                                {std::string(schema::polish::kSummaryFileName),
                                 std::string(schema::polish::kResidualGridFileName), "polish.mod"}};
constexpr int kStepCount = 4;  // and the report

struct StepStatus {
  bool wheel_ran = false;
  bool toolpath_ran = false;
  std::optional<bool> polish_ran;  // none: no polishing job
};

// A number of a step's JSON file as a person reads it: "55.40158 mm", "n/a" when absent.
std::string Mm(const nlohmann::json& v, int decimals);
std::string Um(const nlohmann::json& v, int decimals = 3);
// object[key], or null when `object` is not an object or has no such key.
const nlohmann::json& At(const nlohmann::json& object, std::string_view key);

// OUTDIR/regenerate_report.html and .pdf and OUTDIR/regenerate.json, from the steps' files.
void WriteChainReport(const RegenerateOptions& args, const StepStatus& status, const fs::path& polished_map);

}  // namespace arcwheel::workflows::regenerate
