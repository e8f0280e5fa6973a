#include "store/records.h"

#include <fmt/core.h>

#include <nlohmann/json.hpp>
#include <string_view>
#include <vector>

#include "core/error.h"
#include "core/json_text.h"
#include "core/sha256.h"
#include "reports/history.h"
#include "schema/polish_outputs.h"
#include "schema/summary.h"
#include "schema/toolpath_outputs.h"

namespace arcwheel::store {
namespace {

namespace fs = std::filesystem;
namespace s = schema::store;
namespace su = schema::summary;
using nlohmann::json;

// A headline number: where it sits in the file (a path of keys), its sigma's key path (empty:
// none recorded) and its unit.
struct Characteristic {
  std::vector<std::string_view> path;
  std::vector<std::string_view> sigma_path;
  std::string_view unit;
};

const json* Find(const json& document, const std::vector<std::string_view>& path) {
  const json* node = &document;
  for (std::string_view key : path) {
    if (!node->is_object()) return nullptr;
    const auto it = node->find(key);
    if (it == node->end()) return nullptr;
    node = &*it;
  }
  return node;
}

std::string Name(const std::vector<std::string_view>& path) {
  std::string name;
  for (std::string_view key : path) {
    if (!name.empty()) name += '.';
    name += key;
  }
  return name;
}

// The characteristics the file holds as numbers; one absent or null (a figure not computed) is
// not recorded.
std::vector<StoredNumber> Numbers(const json& document, const std::vector<Characteristic>& characteristics) {
  std::vector<StoredNumber> numbers;
  for (const Characteristic& c : characteristics) {
    const json* value = Find(document, c.path);
    if (value == nullptr || !value->is_number()) continue;
    StoredNumber number{.characteristic = Name(c.path),
                        .value = value->get<double>(),
                        .sigma = std::nullopt,
                        .unit = std::string(c.unit),
                        .expanded_uncertainty = std::nullopt,
                        .decision = {}};
    if (!c.sigma_path.empty()) {
      const json* sigma = Find(document, c.sigma_path);
      if (sigma != nullptr && sigma->is_number()) number.sigma = sigma->get<double>();
    }
    // A headline figure of summary.json: its U and, with tolerances, its decision.
    const json* expanded = Find(document, {su::kUncertainty, su::uncertainty::kQuantities,
                                           number.characteristic, su::uncertainty::quantity::kExpanded});
    if (expanded != nullptr && expanded->is_number()) number.expanded_uncertainty = expanded->get<double>();
    const json* decision = Find(document, {su::kUncertainty, su::uncertainty::kDecisions,
                                           number.characteristic, su::uncertainty::decision::kDecision});
    if (decision != nullptr && decision->is_string()) number.decision = decision->get<std::string>();
    numbers.push_back(std::move(number));
  }
  return numbers;
}

std::string String(const json& document, const std::vector<std::string_view>& path) {
  const json* value = Find(document, path);
  return value != nullptr && value->is_string() ? value->get<std::string>() : "";
}

StoredInput Input(std::string_view role, const fs::path& path) {
  return {std::string(role), fs::absolute(path).lexically_normal().string(), Sha256OfFile(path)};
}

std::string Absolute(const fs::path& path) { return fs::absolute(path).lexically_normal().string(); }

const std::vector<Characteristic>& ProcessCharacteristics() {
  namespace k = schema::summary;
  static const std::vector<Characteristic> list = {
      {{k::kMeanArcRadiusMm}, {k::kMeanArcRadiusSigmaMm}, "mm"},
      {{k::kArcRadiusRangeMm}, {}, "mm"},
      {{k::kArcRadiusFluctuationPct}, {}, "%"},
      {{k::kArcRadiusStdMm}, {}, "mm"},
      {{k::kArcRadiusExcessStdMm}, {}, "mm"},
      {{k::kMeanCenterAxialMm}, {k::kMeanCenterAxialSigmaMm}, "mm"},
      {{k::kCenterAxialDeviationMm}, {}, "mm"},
      {{k::kMeanCenterRadialMm}, {}, "mm"},
      {{k::kMaxArcErrorUm}, {}, "um"},
      {{k::kMaxRunoutUm}, {}, "um"},
      {{k::kMaxRoundnessUm}, {}, "um"},
      {{k::kNoiseSigmaUm}, {}, "um"},
      {{k::kSpindleRpmEstimated}, {k::kSpindleRpmSigma}, "rpm"},
      {{k::kUsablePhases}, {}, "count"},
      {{k::kModel, k::model::kMeanArcRadiusMm}, {k::kModel, k::model::kMeanArcRadiusSigmaMm}, "mm"},
      {{k::kModel, k::model::kArcRadiusRangeMm}, {k::kModel, k::model::kArcRadiusRangeSigmaMm}, "mm"},
      {{k::kModel, k::model::kProfilePvUm}, {}, "um"},
      {{k::kModel, k::model::kResidualRmsUm}, {}, "um"},
  };
  return list;
}

const std::vector<Characteristic>& ToolpathCharacteristics() {
  namespace k = schema::toolpath::summary;
  static const std::vector<Characteristic> list = {
      {{k::kArcRadius, k::arc_radius::kMeasuredMm}, {k::kArcRadius, k::arc_radius::kMeasuredSigmaMm}, "mm"},
      {{k::kArcRadius, k::arc_radius::kDifferenceMm}, {k::kArcRadius, k::arc_radius::kMeasuredSigmaMm}, "mm"},
      {{k::kToolpath, k::toolpath::kControlPoints}, {}, "count"},
      {{k::kToolpath, k::toolpath::kMaxRowDeviationMm}, {}, "mm"},
      {{k::kToolpath, k::toolpath::kMinGougeGapUm}, {}, "um"},
      {{k::kPrediction, k::prediction::kPvUm}, {}, "um"},
      {{k::kPrediction, k::prediction::kRmsUm}, {}, "um"},
      {{k::kPrediction, k::prediction::kPvAfterTiltUm}, {}, "um"},
      {{k::kPrediction, k::prediction::kRmsAfterTiltUm}, {}, "um"},
      {{k::kPrediction, k::prediction::kRipplePvUm}, {}, "um"},
      {{k::kPrediction, k::prediction::kProfilePvUm}, {}, "um"},
  };
  return list;
}

const std::vector<Characteristic>& PolishCharacteristics() {
  namespace k = schema::polish::summary;
  static const std::vector<Characteristic> list = {
      {{k::kPoints}, {}, "count"},
      {{k::kTotalTimeS}, {}, "s"},
      {{k::kBefore, k::figures::kPvUm}, {}, "um"},
      {{k::kBefore, k::figures::kRmsUm}, {}, "um"},
      {{k::kAfter, k::figures::kPvUm}, {}, "um"},
      {{k::kAfter, k::figures::kRmsUm}, {}, "um"},
      {{k::kSpeedMmS, k::speed_mm_s::kMin}, {}, "mm/s"},
      {{k::kSpeedMmS, k::speed_mm_s::kMax}, {}, "mm/s"},
      {{k::kMaxAccelerationMmS2}, {}, "mm/s^2"},
  };
  return list;
}

// What every run's record takes alike from its summary.json: how it was run, the version that
// wrote it, its folder and the options it ran with (the summary's `options_key` object, as JSON).
StoredRun RunFromSummary(std::string_view command, const json& summary, const fs::path& outdir,
                         const std::string& via, std::string_view options_key) {
  StoredRun run;
  run.command = command;
  run.via = via;
  run.arcwheel_version = String(summary, {schema::summary::kArcwheelVersion});
  run.output_folder = Absolute(outdir);
  const json* options = Find(summary, {options_key});
  run.options = options != nullptr ? options->dump() : "{}";
  return run;
}

}  // namespace

StoredRun ProcessRun(const fs::path& outdir, const std::string& via) {
  namespace k = schema::summary;
  const fs::path path = outdir / k::kFileName;
  const json summary = ReadJsonFile(path, "store");
  StoredRun run = RunFromSummary(s::runs::kProcess, summary, outdir, via, k::kProcessing);
  run.wheel_id = String(summary, {k::kScan, k::scan::kWheelId});
  run.scan_timestamp = String(summary, {k::kScan, k::scan::kTimestamp});
  if (!run.scan_timestamp.empty()) {
    try {
      run.scan_time_s =
          reports::ParseTimestamp_s(run.scan_timestamp, "'" + path.string() + "' scan.timestamp");
    } catch (const Error&) {
      run.scan_time_s.reset();  // kept as text; `history` names it when asked
    }
  }
  const std::string scan_path = String(summary, {k::kInput, k::input::kPath});
  run.inputs.push_back({std::string(s::inputs::kScan), scan_path.empty() ? "" : Absolute(scan_path),
                        String(summary, {k::kInput, k::input::kSha256})});
  run.numbers = Numbers(summary, ProcessCharacteristics());
  return run;
}

StoredRun ToolpathRun(const fs::path& outdir, const fs::path& job,
                      const std::optional<fs::path>& wheel_summary, const std::string& via) {
  namespace k = schema::toolpath::summary;
  const json summary = ReadJsonFile(outdir / schema::toolpath::kSummaryFileName, "store");
  StoredRun run = RunFromSummary(s::runs::kToolpath, summary, outdir, via, k::kJob);
  run.inputs.push_back(Input(s::inputs::kJob, job));
  if (wheel_summary) {
    run.inputs.push_back(Input(s::inputs::kWheel, *wheel_summary));
    const json wheel = ReadJsonFile(*wheel_summary, "store");
    run.wheel_id = String(wheel, {schema::summary::kScan, schema::summary::scan::kWheelId});
  }
  run.numbers = Numbers(summary, ToolpathCharacteristics());
  return run;
}

StoredRun PolishRun(const fs::path& outdir, const fs::path& job, const std::optional<fs::path>& error_map,
                    const std::string& via) {
  namespace k = schema::polish::summary;
  const json summary = ReadJsonFile(outdir / schema::polish::kSummaryFileName, "store");
  StoredRun run = RunFromSummary(s::runs::kPolish, summary, outdir, via, k::kJob);
  run.inputs.push_back(Input(s::inputs::kJob, job));
  fs::path map = error_map.value_or(String(summary, {k::kJob, k::job::kErrorMap, k::job::error_map::kFile}));
  if (!map.empty() && map.is_relative() && !fs::exists(map)) map = job.parent_path() / map;
  if (!map.empty() && fs::exists(map)) run.inputs.push_back(Input(s::inputs::kErrorMap, map));
  run.numbers = Numbers(summary, PolishCharacteristics());
  return run;
}

}  // namespace arcwheel::store
