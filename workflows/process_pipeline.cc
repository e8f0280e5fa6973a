#include "workflows/process_pipeline.h"

#include <fmt/core.h>

#include <future>
#include <nlohmann/json.hpp>
#include <span>
#include <utility>
#include <vector>

#include "acquisition/scan_reader.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/sha256.h"
#include "core/text_encoding.h"
#include "fitting/sample_fit.h"
#include "processing/helix_geometry.h"
#include "schema/summary.h"
#include "uncertainty/default_budget.h"

namespace arcwheel::workflows {
namespace {

fitting::RunRecord MakeRecord(const std::string& scan_path, const ProcessPipelineOptions& options,
                              const acquisition::Scan& scan) {
  fitting::RunRecord record;
  // The path as the file system gives it may be in a legacy encoding; summary.json must stay UTF-8
  // (docs/inputs.md).
  bool latin1_path = false;
  record.input_path = AsUtf8(scan_path, latin1_path);
  const std::string extension = std::filesystem::path(scan_path).extension().string();
  // The readers choose by extension (acquisition/scan_reader.h); a scan that no reader made (one
  // simulated in memory and handed over from Python) says so rather than borrow a file format.
  if (extension == ".h5" || extension == ".hdf5") {
    record.input_format = "hdf5";
  } else if (extension == ".csv" || extension == ".txt") {
    record.input_format = "csv";
  } else {
    record.input_format = "memory";
  }
  record.metadata = scan.metadata;
  record.has_encoder = scan.has_encoder();
  const auto& p = options.processing;
  namespace parameter = schema::summary::processing;
  record.numeric_parameters = {
      {std::string(parameter::kPhases), p.map.phases},
      {std::string(parameter::kBandHalfWidthMm), options.fit.band_half_width_mm},
      {std::string(parameter::kDespikeWindowHalfWidth), p.despike.window_half_width},
      {std::string(parameter::kDespikeThresholdUm), p.despike.threshold_um},
      {std::string(parameter::kDespikeThresholdSigmas), p.despike.threshold_sigmas},
      {std::string(parameter::kDespikeMinThresholdUm), p.despike.min_threshold_um},
      {std::string(parameter::kSpeedMaxHarmonic), p.speed.max_harmonic},
      {std::string(parameter::kSpeedSignificanceSigmas), p.speed.significance_sigmas},
      {std::string(parameter::kMapMinSupport), p.map.min_support},
      {std::string(parameter::kMapMaxSigmaRatio), p.map.max_sigma_ratio},
      {std::string(parameter::kFitMinPoints), options.fit.min_points},
      {std::string(parameter::kFitMinBandCoverage), options.fit.min_band_coverage},
      {std::string(parameter::kRunoutMinPhaseCoverage), options.fit.min_phase_coverage},
      {std::string(parameter::kBeamOffsetMm), p.beam_offset_mm},
      {std::string(parameter::kWheelRadiusMm), p.wheel_radius_mm},
      {std::string(parameter::kStuckRunDeg), p.stuck_run_deg},
      {std::string(parameter::kModelKnots), options.model.radius_knots},
      {std::string(parameter::kModelAxialKnots), options.model.axial_knots},
      {std::string(parameter::kModelRunoutKnots), options.model.runout_knots},
      {std::string(parameter::kModelProfileStepMm), options.model.profile_knot_step_mm},
  };
  record.text_parameters = {{std::string(parameter::kDespikeMethod), options.despike_method},
                            {std::string(parameter::kRpmSource), options.rpm_source},
                            {std::string(parameter::kFitSpan), options.fit_span},
                            {std::string(parameter::kFilter), "none"},
                            {std::string(parameter::kModel), options.no_model ? "off" : "on"}};
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

// The value of a choice option, or a problem in the form of Problems(): "--flag = value violates
// one of ...".
template <typename Parse, typename Value>
void ParseChoice(const char* flag, const std::string& text, const char* choices, Parse parse, Value& value,
                 std::vector<std::string>& problems) {
  try {
    value = parse(text);
  } catch (const Error& e) {
    if (e.code() != ErrorCode::kInvalidOption) throw;
    problems.push_back(fmt::format("{} = {} violates {}", flag, text, choices));
  }
}

// The headline figures' uncertainty from the per-phase fits and the map (before the spline goes:
// nothing here reads it, but the map must still hold every node).
uncertainty::WheelUncertainty EvaluateUncertainty(const ProcessPipelineOptions& options,
                                                  const acquisition::ScanMetadata& metadata,
                                                  const processing::ProcessedScan& processed,
                                                  const fitting::WheelFit& fit) {
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
  uncertainty::WheelUncertainty result;
  if (options.uncertainty_budget) {
    result =
        uncertainty::EvaluateWheelUncertainty(observations, *options.uncertainty_budget, options.uncertainty);
    result.budget_source = options.uncertainty_budget_path;
  } else {
    const double diameter = metadata.wheel_diameter_mm.value_or(400.0);
    const uncertainty::BudgetFile budget = uncertainty::DefaultBudget(
        {.arc_radius_mm = fit.mean_arc_radius_mm,
         .band_half_width_mm = std::min(options.fit.band_half_width_mm, 0.9 * fit.mean_arc_radius_mm),
         .wheel_radius_mm = diameter / 2.0});
    result = uncertainty::EvaluateWheelUncertainty(observations, budget, options.uncertainty);
  }
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

// Everything after the scan is in memory. `sha256` delivers the input's hash (computed meanwhile
// on another thread when the scan came from a file).
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
  // The fits are of the samples (fitting/sample_fit.h): the helix spline (23 MB at 1e8 samples)
  // is not read again.
  result.processed.map.spline.reset();
  // Nor are the sections (24 MB at 1e8 samples); their typical sigma stays (map.map_sigma_mm).
  std::vector<processing::Section>().swap(result.processed.map.sections);
  result.fit = acquisition::VisitReadings(scan, [&](const auto& rho) {
    return fitting::FitWheelToSamples(std::span(rho),
                                      processing::HelixGeometry(scan, result.processed.rpm_used),
                                      result.processed.map, options.fit);
  });
  clock.Start("wheel model");
  result.model = FitModelUnlessOff(options, scan, result.processed, result.fit);
  clock.Start("releasing the samples");
  const acquisition::ScanMetadata metadata = scan.metadata;
  scan = {};  // the samples are no longer needed: the uncertainty's bootstrap works on the map
  if (!options.no_uncertainty) {
    clock.Start("uncertainty");
    result.uncertainty = EvaluateUncertainty(options, metadata, result.processed, result.fit);
    if (options.tolerances) DecideTolerances(*options.tolerances, *result.uncertainty);
  }
  progress.Update("writing", 0.9);
  clock.Start("waiting for the SHA-256");
  result.record.input_sha256 = sha256.get();
  ThrowIfInterrupted();
  if (!outdir.empty()) {
    clock.Start("writing");
    const nlohmann::json uncertainty =
        result.uncertainty ? uncertainty::WheelUncertaintyToJson(*result.uncertainty) : nlohmann::json();
    fitting::WriteProcessOutputs(outdir, result.record, result.processed, result.fit,
                                 result.model ? &*result.model : nullptr,
                                 result.uncertainty ? &uncertainty : nullptr);
  }
  clock.Stop();
  result.clock = std::move(clock);
  return result;
}

}  // namespace

void ResolveProcessPipelineOptions(ProcessPipelineOptions& options) {
  // Every bad option of both stages in one message, before the scan is read: the fit's would
  // otherwise surface only after the whole scan had been processed.
  std::vector<std::string> problems;
  ParseChoice("--despike", options.despike_method, "median, moving-mean or none",
              processing::ParseDespikeMethod, options.processing.despike.method, problems);
  ParseChoice("--rpm-source", options.rpm_source, "auto, nominal, encoder or estimate",
              processing::ParseRpmSource, options.processing.rpm_source, problems);
  ParseChoice("--fit-span", options.fit_span, "band or full", fitting::ParseFitSpan, options.fit.fit_span,
              problems);
  for (std::string& problem : options.processing.Problems()) problems.push_back(std::move(problem));
  for (std::string& problem : options.fit.Problems()) problems.push_back(std::move(problem));
  if (!options.no_model) {
    for (std::string& problem : options.model.Problems()) problems.push_back(std::move(problem));
  }
  if (!options.no_uncertainty) {
    for (std::string& problem : options.uncertainty.Problems()) problems.push_back(std::move(problem));
  }
  ThrowIfProblems(ErrorCode::kInvalidOption, "process", problems);
  // A bad budget is refused before the scan is read, with every problem it has (exit 2).
  if (!options.no_uncertainty && !options.uncertainty_budget_path.empty())
    options.uncertainty_budget = uncertainty::ReadBudget(options.uncertainty_budget_path);
}

ProcessPipelineResult RunProcessPipeline(const std::string& scan_path, const std::filesystem::path& outdir,
                                         ProcessPipelineOptions options, Progress& progress) {
  ResolveProcessPipelineOptions(options);
  progress.Update("reading", 0.0);
  // ReadScan forks (an HDF5 file is read first in a child process, core/hdf5_child.cc), and no
  // thread may be alive at fork(): the input's SHA-256 starts after it, on the second core while
  // the child reads (this process only waits for it then).
  StageClock clock;
  clock.Start("reading");
  std::future<std::string> sha256;
  const auto start_hash = [&] {
    sha256 = std::async(std::launch::async, [scan_path] { return Sha256OfFile(scan_path); });
  };
  acquisition::Scan scan =
      acquisition::ReadScan(scan_path, {.keep_float32 = true, .while_reading = start_hash});
  clock.Stop();
  if (!sha256.valid()) start_hash();  // a reader that had nothing to overlap
  return RunOnScan(std::move(scan), scan_path, std::move(sha256), outdir, options, progress,
                   std::move(clock));
}

ProcessPipelineResult RunProcessPipeline(acquisition::Scan scan, std::string input_sha256,
                                         const std::filesystem::path& outdir, ProcessPipelineOptions options,
                                         Progress& progress) {
  ResolveProcessPipelineOptions(options);
  // The readers validate what they read; a scan built in memory gets the same checks here.
  acquisition::ValidateScan(scan);
  std::promise<std::string> known;
  known.set_value(std::move(input_sha256));
  const std::string scan_path = scan.path;
  return RunOnScan(std::move(scan), scan_path, known.get_future(), outdir, options, progress, StageClock{});
}

}  // namespace arcwheel::workflows
