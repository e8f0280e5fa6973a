#include "workflows/process_pipeline.h"

#include <future>
#include <limits>
#include <nlohmann/json.hpp>
#include <numbers>
#include <span>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "acquisition/profile_scan.h"
#include "acquisition/scan_format.h"
#include "acquisition/scan_reader.h"
#include "core/check.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/sha256.h"
#include "core/text_encoding.h"
#include "fitting/profile_fit.h"
#include "fitting/sample_fit.h"
#include "processing/helix_geometry.h"
#include "processing/profile_sections.h"
#include "schema/summary.h"
#include "uncertainty/default_budget.h"
#include "workflows/process_options.h"

namespace arcwheel::workflows {
namespace {

fitting::RunRecord MakeRecord(const std::string& scan_path, const ProcessPipelineOptions& options,
                              const acquisition::Scan& scan) {
  fitting::RunRecord record;
  // The path as the file system gives it may be in a legacy encoding; summary.json must stay UTF-8
  // (docs/inputs.md).
  bool latin1_path = false;
  record.input_path = AsUtf8(scan_path, latin1_path);
  // The reader names its format (acquisition/scan_format.h); a scan that no reader made (one
  // simulated in memory and handed over from Python) says so rather than borrow a file format.
  record.input_format = scan.read.format.empty() ? "memory" : scan.read.format;
  record.metadata = scan.metadata;
  record.read = scan.read;
  record.has_encoder = scan.has_encoder();
  // The parameters as the options table records them, in its order; then what the record states
  // beside the options.
  ProcessPipelineOptions bound = options;
  for (const ProcessOption& option : ProcessOptionTable()) {
    if (option.record_key.empty()) continue;
    const std::string key(option.record_key);
    std::visit(
        [&](const auto& value) {
          using T = std::decay_t<decltype(value)>;
          if constexpr (std::is_same_v<T, ChoiceRef>) {
            record.text_parameters.emplace_back(key, std::string(NameOf(value)));
          } else if constexpr (std::is_same_v<T, int*> || std::is_same_v<T, double*>) {
            record.numeric_parameters.emplace_back(key, static_cast<double>(*value));
          } else {
            ARCWHEEL_CHECK(false) << "no record of option " << key;
          }
        },
        option.field(bound));
  }
  namespace parameter = schema::summary::processing;
  record.text_parameters.emplace_back(parameter::kFilter, "none");
  record.text_parameters.emplace_back(parameter::kModel, options.no_model ? "off" : "on");
  return record;
}

// The wheel model over every sample in the band (fitting/wheel_model.h). The per-phase fits are
// the contract's results, so a model that cannot be fitted is a warning, not a failed run.
std::optional<fitting::WheelModel> FitModelUnlessOff(const ProcessPipelineOptions& options,
                                                     const acquisition::Scan& scan,
                                                     processing::ProcessedScan& processed,
                                                     const fitting::WheelFit& fit) {
  if (options.no_model) return std::nullopt;
  try {
    const processing::HelixGeometry geometry(scan, processed.rpm_used);
    return acquisition::VisitReadings(scan, [&](const auto& rho) {
      return fitting::FitWheelModel(std::span(rho), geometry, processed.map, fit, options.model);
    });
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kFitFailed) throw;
    processed.warnings.push_back(std::string("no wheel model: ") + e.what());
    return std::nullopt;
  }
}

// A line-profile sensor's calibrated placement in the budget (docs/uncertainty.md). Tilt and
// offset move every section rigidly, which leaves the arc radii, the arc errors, run-out and
// roundness as they are; an error of the tilt moves each phase's arc centre along the axis by
// its radial position times the angle, so the arc centre's axial deviation changes by the spread of
// the centres' radial positions per radian. The offset moves every centre alike and changes none of
// the budgeted figures: it is recorded with sensitivity 0.
void AddPlacementInputs(const acquisition::ProfilePlacement& placement, const fitting::WheelFit& fit,
                        uncertainty::BudgetFile& budget) {
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (const fitting::PhaseFit& phase : fit.phases) {
    if (!phase.usable) continue;
    low = std::min(low, phase.center_radial_mm);
    high = std::max(high, phase.center_radial_mm);
  }
  const double per_deg = high > low ? (high - low) * std::numbers::pi / 180.0 : 0.0;
  auto& inputs = budget.quantities[std::string(schema::summary::kCenterAxialDeviationMm)];
  inputs.push_back({.input = {.name = "sensor_tilt",
                              .source = "--scan-settings sensor_tilt_u_deg (calibration)",
                              .unit = "deg",
                              .spread = placement.tilt_u_deg,
                              .sensitivity = per_deg}});
  inputs.push_back({.input = {.name = "sensor_axial_offset",
                              .source = "--scan-settings sensor_axial_offset_u_mm (calibration)",
                              .unit = "mm",
                              .spread = placement.axial_offset_u_mm,
                              .sensitivity = 0.0}});
}

// The headline figures' uncertainty from the per-phase fits and the map; `placement`: a
// line-profile sensor's, else null.
uncertainty::WheelUncertainty EvaluateUncertainty(const ProcessPipelineOptions& options,
                                                  const acquisition::ScanMetadata& metadata,
                                                  const processing::ProcessedScan& processed,
                                                  const fitting::WheelFit& fit,
                                                  const acquisition::ProfilePlacement* placement = nullptr) {
  const processing::WheelMap& map = processed.map;
  std::vector<double> radius, radius_sigma, axial, axial_sigma, radial;
  std::vector<char> usable;
  for (const fitting::PhaseFit& phase : fit.phases) {
    radius.push_back(phase.arc_radius_mm);
    radius_sigma.push_back(phase.arc_radius_sigma_mm);
    axial.push_back(phase.center_axial_mm);
    axial_sigma.push_back(phase.center_axial_sigma_mm);
    radial.push_back(phase.center_radial_mm);
    usable.push_back(phase.usable ? 1 : 0);
  }
  const uncertainty::WheelObservations observations{
      .mean_arc_radius_mm = fit.mean_arc_radius_mm,
      .mean_arc_radius_sigma_mm = fit.mean_arc_radius_sigma_mm,
      .arc_radius_range_mm = fit.arc_radius_range_mm,
      .arc_radius_fluctuation_pct = fit.arc_radius_fluctuation_pct,
      .center_axial_deviation_mm = fit.center_axial_deviation_mm,
      .max_arc_error_um = fit.max_arc_error_um,
      .max_runout_um = fit.max_runout_um,
      .max_roundness_um = fit.max_roundness_um,
      .arc_radius_mm = radius,
      .arc_radius_sigma_mm = radius_sigma,
      .center_axial_mm = axial,
      .center_axial_sigma_mm = axial_sigma,
      .center_radial_mm = radial,
      .usable = usable,
      .rho_mm = map.rho_mm,
      .y_mm = map.y_mm,
      .map_sigma_mm = map.map_sigma_mm,  // summary.json's map_sigma_um
      .band_low_mm = fit.band_low_mm,
      .band_high_mm = fit.band_high_mm,
      .section_bins = fit.section_bins,
      .section_residual_um = fit.section_residual_um,
      .section_y_mm = fit.section_y_mm,
      .section_sigma_um = fit.section_sigma_um};
  uncertainty::BudgetFile budget;
  if (options.uncertainty_budget) {
    budget = *options.uncertainty_budget;
  } else {
    const double diameter = metadata.wheel_diameter_mm.value_or(400.0);
    budget = uncertainty::DefaultBudget(
        {.arc_radius_mm = fit.mean_arc_radius_mm,
         .band_half_width_mm = std::min(options.fit.band_half_width_mm, 0.9 * fit.mean_arc_radius_mm),
         .wheel_radius_mm = diameter / 2.0});
  }
  if (placement != nullptr) AddPlacementInputs(*placement, fit, budget);
  uncertainty::WheelUncertainty result =
      uncertainty::EvaluateWheelUncertainty(observations, budget, options.uncertainty);
  if (options.uncertainty_budget) result.budget_source = options.uncertainty_budget_path;
  return result;
}

// The decisions summary.json records, by the rule the report's page 1 uses (RuleOf there).
void DecideTolerances(const reports::Tolerances& tolerances, uncertainty::WheelUncertainty& uncertainty) {
  std::map<std::string, uncertainty::Specification> specifications;
  for (const auto& [key, limit] : tolerances.limits)
    specifications[key] = {.min = limit.min, .max = limit.max};
  uncertainty::DecideConformity(uncertainty, specifications,
                                tolerances.rule.value_or(uncertainty::DecisionRule::kIso14253));
}

// Up to this many readings, the turns' characteristics start before the wheel model rather than
// after it. Measured on the benchmark scans (alternating runs, the same hour): 1e6 readings 0.287 ->
// 0.274 s (medians of 21), 1e7 0.88 -> 0.84 s; at 1e8 the model keeps both cores busy itself, and
// the turns' working memory (37 MiB) would add to the samples' while the model still needs them
// (1.26x -> 1.36x the file, 2.25 -> 2.34 s).
constexpr std::size_t kMaxReadingsForTurnsBesideTheModel = 10'000'000;

// The wheel's radius the characteristics take their turns about.
double WheelRadiusMm(const ProcessPipelineOptions& options, const acquisition::ScanMetadata& metadata) {
  return options.processing.wheel_radius_mm > 0.0 ? options.processing.wheel_radius_mm
                                                  : metadata.wheel_diameter_mm.value_or(400.0) / 2.0;
}

// The turns' characteristics need only the map and the fits: a thread of their own evaluates them
// beside the uncertainty's bootstraps, whose workers leave a core idle part of the time, and, on a
// scan of up to kMaxReadingsForTurnsBesideTheModel readings, beside the wheel model too, which leaves
// one idle at small scans. Nothing, without the uncertainty (the characteristics need its U).
std::future<TurnCharacteristics> StartTurnCharacteristics(const ProcessPipelineOptions& options,
                                                          const acquisition::ScanMetadata& metadata,
                                                          const ProcessPipelineResult& result) {
  if (options.no_uncertainty) return {};
  const double wheel_radius_mm = WheelRadiusMm(options, metadata);
  return std::async(std::launch::async, [&options, &result, wheel_radius_mm] {
    return EvaluateTurnCharacteristics(options, result.processed.map, result.fit, wheel_radius_mm);
  });
}

// The uncertainty, its decisions and the characteristics, after the fits; `turns` from
// StartTurnCharacteristics. The sections' arc profile follows the uncertainty, whose smoothed fit of
// the sections it starts from. Their warnings join the processing's.
void EvaluateUncertaintyAndCharacteristics(const ProcessPipelineOptions& options,
                                           const acquisition::ScanMetadata& metadata,
                                           const acquisition::ProfilePlacement* placement,
                                           std::future<TurnCharacteristics> turns,
                                           ProcessPipelineResult& result, StageClock& clock) {
  clock.Start("uncertainty and turns");
  const double wheel_radius_mm = WheelRadiusMm(options, metadata);
  result.uncertainty = EvaluateUncertainty(options, metadata, result.processed, result.fit, placement);
  if (options.tolerances) DecideTolerances(*options.tolerances, *result.uncertainty);
  clock.Start("characteristics");
  result.characteristics = EvaluateCharacteristics(options, result.processed.map, result.fit,
                                                   *result.uncertainty, wheel_radius_mm, turns.get());
  for (const std::string& warning : result.characteristics->warnings)
    result.processed.warnings.push_back(warning);
}

// Waits for the input's hash, writes the outputs and keeps the clock, for both kinds of scan.
void FinishRun(std::future<std::string> sha256, const std::filesystem::path& outdir,
               ProcessPipelineResult& result, StageClock& clock) {
  clock.Start("waiting for the SHA-256");
  result.record.input_sha256 = sha256.get();
  ThrowIfInterrupted();
  if (!outdir.empty()) {
    clock.Start("writing");
    nlohmann::json later_stages = nlohmann::json::object();
    if (result.uncertainty)
      later_stages[schema::summary::kUncertainty] = uncertainty::WheelUncertaintyToJson(*result.uncertainty);
    if (result.characteristics)
      later_stages[schema::summary::kCharacteristics] = CharacteristicsToJson(*result.characteristics);
    fitting::WriteProcessOutputs(outdir, result.record, result.processed, result.fit,
                                 result.model ? &*result.model : nullptr, &later_stages);
  }
  clock.Stop();
  result.clock = std::move(clock);
}

// Everything after the scan is in memory. `sha256` delivers the input's hash (computed on another
// thread, beside these stages, when the scan came from a file).
ProcessPipelineResult RunOnScan(acquisition::Scan scan, const std::string& scan_path,
                                std::future<std::string> sha256, const std::filesystem::path& outdir,
                                const ProcessPipelineOptions& options, Progress& progress, StageClock clock) {
  ProcessPipelineResult result;
  result.record = MakeRecord(scan_path, options, scan);
  ThrowIfInterrupted();
  progress.Update("processing", 0.3);
  result.processed = processing::ProcessScanInPlace(scan, options.processing);
  clock.Append(result.processed.timings);
  progress.Update("fitting", 0.7);
  clock.Start("per-phase fits");
  // The map's values and their sigma are the per-phase fits' (fitting/sample_fit.h).
  result.fit = acquisition::VisitReadings(scan, [&](const auto& rho) {
    return fitting::FitWheelToSamples(std::span(rho),
                                      processing::HelixGeometry(scan, result.processed.rpm_used),
                                      result.processed.map, options.fit);
  });
  const acquisition::ScanMetadata metadata = scan.metadata;
  const bool turns_beside_the_model = scan.size() <= kMaxReadingsForTurnsBesideTheModel;
  std::future<TurnCharacteristics> turns;
  if (turns_beside_the_model) turns = StartTurnCharacteristics(options, metadata, result);
  clock.Start("wheel model");
  result.model = FitModelUnlessOff(options, scan, result.processed, result.fit);
  clock.Start("releasing the samples");
  scan = {};  // the samples are no longer needed: the uncertainty's bootstrap works on the map
  if (!turns_beside_the_model) turns = StartTurnCharacteristics(options, metadata, result);
  if (!options.no_uncertainty)
    EvaluateUncertaintyAndCharacteristics(options, metadata, nullptr, std::move(turns), result, clock);
  progress.Update("writing", 0.9);
  FinishRun(std::move(sha256), outdir, result, clock);
  return result;
}

// A line-profile scan (docs/processing.md, "Line-profile scans"): its frames become the per-phase
// sections (processing/profile_sections.h), fitted as a helical scan's are (fitting/profile_fit.h);
// from the fits on, everything is as for a helical scan. The wheel model needs the helix's samples
// and is not fitted.
ProcessPipelineResult RunOnProfileScan(acquisition::ProfileScan scan, const std::string& scan_path,
                                       std::future<std::string> sha256, const std::filesystem::path& outdir,
                                       const ProcessPipelineOptions& options, Progress& progress,
                                       StageClock clock) {
  ProcessPipelineResult result;
  acquisition::Scan carrier;
  carrier.metadata = scan.metadata;
  carrier.read = scan.read;
  result.record = MakeRecord(scan_path, options, carrier);
  result.record.has_encoder = !scan.encoder.empty();
  progress.Update("processing", 0.3);
  clock.Start("profile sections");
  processing::ProfileSectionsResult sections = processing::BuildProfileSections(scan, options.processing.map);
  processing::ProcessedScan& processed = result.processed;
  processed.samples = scan.z_mm.size();
  processed.valid_samples = sections.valid_points;
  processed.last_valid = scan.z_mm.empty() ? 0 : scan.z_mm.size() - 1;
  processed.noise_sigma_mm = sections.point_spread_mm;
  processed.phase_source =
      result.record.has_encoder ? processing::PhaseSource::kEncoder : processing::PhaseSource::kNominal;
  processed.rpm_used = scan.metadata.spindle_rpm.value_or(0.0);
  processed.map = std::move(sections.map);
  if (!options.no_model) processed.warnings.push_back("no wheel model: it fits a helical scan's samples");
  ThrowIfInterrupted();
  progress.Update("fitting", 0.7);
  clock.Start("per-phase fits");
  result.fit = fitting::FitProfileWheel(processed.map, options.fit);
  const acquisition::ProfilePlacement placement = scan.placement;
  scan = {};
  if (!options.no_uncertainty)
    EvaluateUncertaintyAndCharacteristics(options, result.record.metadata, &placement,
                                          StartTurnCharacteristics(options, result.record.metadata, result),
                                          result, clock);
  progress.Update("writing", 0.9);
  FinishRun(std::move(sha256), outdir, result, clock);
  return result;
}

}  // namespace

void ResolveProcessPipelineOptions(ProcessPipelineOptions& options) {
  // Every bad option of both stages in one message, before the scan is read: the fit's would
  // otherwise surface only after the whole scan had been processed.
  std::vector<std::string> problems = options.binding_problems;
  if (!options.scan_format.empty()) {
    try {
      (void)acquisition::ScanFormatNamed(options.scan_format, "process");
    } catch (const Error& e) {
      problems.push_back(std::string(e.what()).substr(std::string("process: ").size()));
    }
  }
  for (std::string& problem : acquisition::ColumnsOptionProblems(options.columns))
    problems.push_back(std::move(problem));
  for (std::string& problem : options.processing.Problems()) problems.push_back(std::move(problem));
  for (std::string& problem : options.fit.Problems()) problems.push_back(std::move(problem));
  if (!options.no_model) {
    for (std::string& problem : options.model.Problems()) problems.push_back(std::move(problem));
  }
  if (!options.no_uncertainty) {
    for (std::string& problem : options.uncertainty.Problems()) problems.push_back(std::move(problem));
  }
  ThrowIfProblems(ErrorCode::kInvalidOption, "process", problems);
  // An operator that cannot be evaluated (an option, or a tolerance's) likewise.
  if (!options.no_uncertainty) (void)CharacteristicOperators(options, options.processing.map.phases);
  // A bad budget is refused before the scan is read, with every problem it has (exit 2).
  if (!options.no_uncertainty && !options.uncertainty_budget_path.empty())
    options.uncertainty_budget = uncertainty::ReadBudget(options.uncertainty_budget_path);
  // So is a bad settings file (exit 2), with every problem it has.
  if (!options.scan_settings_path.empty())
    options.scan_settings = acquisition::ReadScanSettings(options.scan_settings_path);
}

ProcessPipelineResult RunProcessPipeline(const std::string& scan_path, const std::filesystem::path& outdir,
                                         ProcessPipelineOptions options, Progress& progress) {
  ResolveProcessPipelineOptions(options);
  progress.Update("reading", 0.0);
  // ReadAnyScan forks (an HDF5 file is read first in a child process, core/hdf5_child.cc), and no
  // thread may be alive at fork(): the input's SHA-256 starts after it, on the second core, beside
  // a text file's parsing or, for an HDF5 file, beside the stages after the read (this process
  // only waits for it before writing).
  StageClock clock;
  clock.Start("reading");
  std::future<std::string> sha256;
  const auto start_hash = [&] {
    sha256 = std::async(std::launch::async, [scan_path] { return Sha256OfFile(scan_path); });
  };
  std::variant<acquisition::Scan, acquisition::ProfileScan> scan = acquisition::ReadAnyScan(
      scan_path, {.keep_float32 = true,
                  .while_reading = start_hash,
                  .settings = options.scan_settings ? &*options.scan_settings : nullptr,
                  .format = options.scan_format,
                  .columns = options.columns});
  if (!sha256.valid()) start_hash();  // an HDF5 file's reader, which does not call it
  if (auto* profile = std::get_if<acquisition::ProfileScan>(&scan)) {
    return RunOnProfileScan(std::move(*profile), scan_path, std::move(sha256), outdir, options, progress,
                            std::move(clock));
  }
  clock.Stop();
  return RunOnScan(std::get<acquisition::Scan>(std::move(scan)), scan_path, std::move(sha256), outdir,
                   options, progress, std::move(clock));
}

ProcessPipelineResult RunProcessPipeline(acquisition::Scan scan, std::string input_sha256,
                                         const std::filesystem::path& outdir, ProcessPipelineOptions options,
                                         Progress& progress) {
  ResolveProcessPipelineOptions(options);
  // The readers merge the settings and validate what they read; a scan built in memory gets the
  // same here.
  acquisition::ApplyScanSettings(options.scan_settings ? &*options.scan_settings : nullptr, scan);
  acquisition::ValidateScan(scan);
  std::promise<std::string> known;
  known.set_value(std::move(input_sha256));
  const std::string scan_path = scan.path;
  return RunOnScan(std::move(scan), scan_path, known.get_future(), outdir, options, progress, StageClock{});
}

}  // namespace arcwheel::workflows

namespace arcwheel::workflows {

ProcessPipelineResult RunProcessPipeline(acquisition::ProfileScan scan, std::string input_sha256,
                                         const std::filesystem::path& outdir, ProcessPipelineOptions options,
                                         Progress& progress) {
  ResolveProcessPipelineOptions(options);
  acquisition::ValidateProfileScan(scan);
  std::promise<std::string> known;
  known.set_value(std::move(input_sha256));
  const std::string scan_path = scan.path;
  return RunOnProfileScan(std::move(scan), scan_path, known.get_future(), outdir, options, progress,
                          StageClock{});
}

}  // namespace arcwheel::workflows
