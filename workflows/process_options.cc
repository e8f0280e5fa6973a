#include "workflows/process_options.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>

#include "schema/summary.h"

namespace arcwheel::workflows {
namespace {

namespace parameter = schema::summary::processing;
using Options = ProcessPipelineOptions;

constexpr std::array<std::string_view, 3> kDespikeMethods = {"median", "moving-mean", "none"};
constexpr std::array<std::string_view, 4> kRpmSources = {"auto", "nominal", "encoder", "estimate"};
constexpr std::array<std::string_view, 2> kFitSpans = {"band", "full"};
constexpr std::array<std::string_view, 4> kAssociations = {"least-squares", "minimum-zone",
                                                           "maximum-inscribed", "minimum-circumscribed"};
// Each name's position is its enum's value.
static_assert(static_cast<int>(processing::DespikeMethod::kMovingMean) == 1 &&
              static_cast<int>(processing::DespikeMethod::kNone) == 2);
static_assert(static_cast<int>(processing::RpmSource::kNominal) == 1 &&
              static_cast<int>(processing::RpmSource::kEncoder) == 2 &&
              static_cast<int>(processing::RpmSource::kEstimate) == 3);
static_assert(static_cast<int>(fitting::FitSpan::kFull) == 1);
static_assert(static_cast<int>(characteristics::Association::kMinimumZone) == 1 &&
              static_cast<int>(characteristics::Association::kMaximumInscribed) == 2 &&
              static_cast<int>(characteristics::Association::kMinimumCircumscribed) == 3);

// An enum held as the position of its name in `names` (the enums declare their values in that order).
template <typename Enum>
ChoiceRef Choice(Enum& value, std::span<const std::string_view> names) {
  return {names, [&value] { return static_cast<std::size_t>(value); },
          [&value](std::size_t index) { value = static_cast<Enum>(index); }};
}

std::vector<ProcessOption> MakeTable() {
  return {
      {"--phases", "phase nodes per turn", parameter::kPhases,
       [](Options& o) -> OptionRef { return &o.processing.map.phases; }},
      {"--band-half-width-mm", "half width of the grinding band", parameter::kBandHalfWidthMm,
       [](Options& o) -> OptionRef { return &o.fit.band_half_width_mm; }},
      {"--despike-window", "window half-width, samples", parameter::kDespikeWindowHalfWidth,
       [](Options& o) -> OptionRef { return &o.processing.despike.window_half_width; }},
      {"--despike-threshold-um", "rejection threshold (default: sigmas x noise)",
       parameter::kDespikeThresholdUm,
       [](Options& o) -> OptionRef { return &o.processing.despike.threshold_um; }, false},
      {"--despike-sigmas", "automatic threshold in noise sigmas", parameter::kDespikeThresholdSigmas,
       [](Options& o) -> OptionRef { return &o.processing.despike.threshold_sigmas; }},
      {"", "", parameter::kDespikeMinThresholdUm,
       [](Options& o) -> OptionRef { return &o.processing.despike.min_threshold_um; }},
      {"", "", parameter::kSpeedMaxHarmonic,
       [](Options& o) -> OptionRef { return &o.processing.speed.max_harmonic; }},
      {"", "", parameter::kSpeedSignificanceSigmas,
       [](Options& o) -> OptionRef { return &o.processing.speed.significance_sigmas; }},
      {"", "", parameter::kMapMinSupport,
       [](Options& o) -> OptionRef { return &o.processing.map.min_support; }},
      {"", "", parameter::kMapMaxSigmaRatio,
       [](Options& o) -> OptionRef { return &o.processing.map.max_sigma_ratio; }},
      {"--min-points", "fewest section points for a usable phase", parameter::kFitMinPoints,
       [](Options& o) -> OptionRef { return &o.fit.min_points; }},
      {"", "", parameter::kFitMinBandCoverage,
       [](Options& o) -> OptionRef { return &o.fit.min_band_coverage; }},
      {"", "", parameter::kRunoutMinPhaseCoverage,
       [](Options& o) -> OptionRef { return &o.fit.min_phase_coverage; }},
      {"--beam-offset-mm", "correct a beam offset from the axis (method.md A.7)", parameter::kBeamOffsetMm,
       [](Options& o) -> OptionRef { return &o.processing.beam_offset_mm; }},
      {"--wheel-radius-mm", "wheel radius for the beam-offset correction", parameter::kWheelRadiusMm,
       [](Options& o) -> OptionRef { return &o.processing.wheel_radius_mm; }, false},
      {"--stuck-run-deg",
       "drop runs of equal readings lasting this much of a turn (stuck sensor); 0 keeps them",
       parameter::kStuckRunDeg, [](Options& o) -> OptionRef { return &o.processing.stuck_run_deg; }},
      {"--model-knots",
       "knots per turn of the model's arc radius Ra(c); 0: chosen from the data, 1: constant",
       parameter::kModelKnots, [](Options& o) -> OptionRef { return &o.model.radius_knots; }},
      {"--model-axial-knots",
       "knots per turn of the model's arc-centre axial position a(c); 0: chosen, 1: constant",
       parameter::kModelAxialKnots, [](Options& o) -> OptionRef { return &o.model.axial_knots; }},
      {"--model-runout-knots", "knots per turn of the model's arc-centre radial position b(c); 0: chosen",
       parameter::kModelRunoutKnots, [](Options& o) -> OptionRef { return &o.model.runout_knots; }},
      {"--model-profile-step-mm", "knot spacing of the model's common profile error p(u)",
       parameter::kModelProfileStepMm, [](Options& o) -> OptionRef { return &o.model.profile_knot_step_mm; }},
      // The texts.
      {"--despike", "median (burst-safe), moving-mean (the paper's), none", parameter::kDespikeMethod,
       [](Options& o) -> OptionRef { return Choice(o.processing.despike.method, kDespikeMethods); }},
      {"--rpm-source", "auto, nominal, encoder or estimate", parameter::kRpmSource,
       [](Options& o) -> OptionRef { return Choice(o.processing.rpm_source, kRpmSources); }},
      {"--fit-span", "band: fit inside the band; full: the whole rim", parameter::kFitSpan,
       [](Options& o) -> OptionRef { return Choice(o.fit.fit_span, kFitSpans); }},
      // The operators' defaults (docs/characteristics.md): summary.json's characteristics name them.
      {"--roundness-filter-upr", "roundness: Gaussian cut-off in UPR, 0 for none (ISO 12181-2)", "",
       [](Options& o) -> OptionRef { return &o.roundness_filter_upr; }},
      {"--roundness-association",
       "roundness: minimum-zone, least-squares, maximum-inscribed or minimum-circumscribed", "",
       [](Options& o) -> OptionRef { return Choice(o.roundness_association, kAssociations); }},
      {"--runout-filter-upr", "circular run-out: Gaussian cut-off in UPR, 0 for none", "",
       [](Options& o) -> OptionRef { return &o.runout_filter_upr; }},
      {"--arc-error-filter-mm", "arc profile error: Gaussian cut-off wavelength in mm, 0 for none", "",
       [](Options& o) -> OptionRef { return &o.arc_error_filter_mm; }},
      {"--arc-error-association", "arc profile error: minimum-zone or least-squares", "",
       [](Options& o) -> OptionRef { return Choice(o.arc_error_association, kAssociations); }},
      // Options that the record states otherwise (the map's steps as used, "model": on or off).
      {"--axial-step-mm", "map node spacing (default one helix pitch)", "",
       [](Options& o) -> OptionRef { return &o.processing.map.axial_step_mm; }, false},
      {"--knot-step-deg",
       "knot spacing of the library's helix spline, recorded in summary.json; process fits none (default "
       "360/phases)",
       "", [](Options& o) -> OptionRef { return &o.processing.map.knot_step_deg; }, false},
      {"--no-model", "skip the wheel model (docs/wheel_model.md)", "",
       [](Options& o) -> OptionRef { return &o.no_model; }, false},
      {"--uncertainty", "type B uncertainty budget (docs/uncertainty.md); default: the simulated sensor's",
       "", [](Options& o) -> OptionRef { return &o.uncertainty_budget_path; }, false, true},
      {"--scan-settings",
       "JSON of the scan's settings the file lacks: spindle_rpm, feed_mm_per_min, sample_period_s, "
       "start_y_mm, radius_sign, wheel_id, sensor, ... (formats.md 2.4)",
       "", [](Options& o) -> OptionRef { return &o.scan_settings_path; }, false, true},
      {"--format",
       "the scan's reader: hdf5, csv, sensortool, keyence-lk, columns; line profiles: gocator, keyence-lj, "
       "profile-hdf5 (default: sniffed)",
       "", [](Options& o) -> OptionRef { return &o.scan_format; }, false},
      {"--columns",
       "which column holds what, by header name and unit: z=NAME[:mm|um|nm],t=NAME[:s|ms|us],"
       "angle=NAME[:deg|counts],y=NAME[:mm]",
       "", [](Options& o) -> OptionRef { return &o.columns; }, false},
      {"--no-uncertainty", "leave the uncertainty budget and the noise-corrected figures out of summary.json",
       "", [](Options& o) -> OptionRef { return &o.no_uncertainty; }, false},
  };
}

}  // namespace

const std::vector<ProcessOption>& ProcessOptionTable() {
  static const std::vector<ProcessOption> table = MakeTable();
  return table;
}

std::string KeywordOf(std::string_view flag) {
  std::string keyword(flag.substr(flag.find_first_not_of('-')));
  std::replace(keyword.begin(), keyword.end(), '-', '_');
  return keyword;
}

std::string_view NameOf(const ChoiceRef& choice) { return choice.names[choice.get()]; }

void SetChoice(std::string_view flag, const ChoiceRef& choice, std::string_view name,
               ProcessPipelineOptions& options) {
  const auto found = std::find(choice.names.begin(), choice.names.end(), name);
  if (found != choice.names.end()) {
    choice.set(static_cast<std::size_t>(found - choice.names.begin()));
    return;
  }
  std::string choices;
  for (std::size_t i = 0; i < choice.names.size(); ++i) {
    if (i > 0) choices += i + 1 == choice.names.size() ? " or " : ", ";
    choices += choice.names[i];
  }
  options.binding_problems.push_back(fmt::format("{} = {} violates {}", flag, name, choices));
}

}  // namespace arcwheel::workflows
