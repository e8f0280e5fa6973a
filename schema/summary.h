#pragma once
// summary.json, written by `arcwheel process` (fitting/outputs.cc) and read by grinding's wheel
// reader and the inspection report: the one place that spells its keys (docs/outputs.md). A key
// of a nested object lives in the namespace named after that object, e.g. `phases::kArcRadiusMm`
// inside `kPhases`. Bump kMinorVersion when adding a key, kMajorVersion when a key changes meaning,
// unit or shape, or disappears.

#include <string_view>

#include "schema/version.h"

namespace arcwheel::schema::summary {

inline constexpr int kMajorVersion = 1;
inline constexpr int kMinorVersion = 2;  // 1.1: the wheel model ("model"); 1.2: "uncertainty"
inline constexpr Version kVersion{kMajorVersion, kMinorVersion};
inline constexpr std::string_view kFileName = "summary.json";

// "MAJOR.MINOR" of the schema the file follows; absent in files written before 1.0.
inline constexpr std::string_view kSchemaVersion = "schema_version";
inline constexpr std::string_view kArcwheelVersion = "arcwheel_version";

// Provenance of the scan.
inline constexpr std::string_view kInput = "input";
namespace input {
inline constexpr std::string_view kPath = "path";
inline constexpr std::string_view kSha256 = "sha256";
inline constexpr std::string_view kFormat = "format";  // a name of acquisition/scan_format.h, or "memory"
inline constexpr std::string_view kSamples = "samples";
inline constexpr std::string_view kValidSamples = "valid_samples";
inline constexpr std::string_view kDespikedSamples = "despiked_samples";
inline constexpr std::string_view kStuckSamples = "stuck_samples";
// formats.md 2.4: what the reader read. {"z": {"name": "Distance1 (mm)", "unit": "mm"}, ...}
inline constexpr std::string_view kColumns = "columns";
inline constexpr std::string_view kColumnName = "name";
inline constexpr std::string_view kColumnUnit = "unit";
// Invalid samples by marker kind: {"out_of_range_high": 12, "alarm": 3, ...}; only kinds met.
inline constexpr std::string_view kInvalidMarkers = "invalid_markers";
// The --scan-settings file ("" when none) and where each setting in effect came from:
// {"spindle_rpm": "settings", "sample_period_s": "file", "radius_sign": "default", ...}.
inline constexpr std::string_view kScanSettings = "scan_settings";
inline constexpr std::string_view kSources = "sources";
}  // namespace input

// The scan's metadata as recorded in the scan file.
inline constexpr std::string_view kScan = "scan";
namespace scan {
inline constexpr std::string_view kWheelId = "wheel_id";
inline constexpr std::string_view kSensor = "sensor";
inline constexpr std::string_view kOperator = "operator";
inline constexpr std::string_view kTimestamp = "timestamp";
inline constexpr std::string_view kWheelDiameterMm = "wheel_diameter_mm";
inline constexpr std::string_view kWheelWidthMm = "wheel_width_mm";
inline constexpr std::string_view kFeedMmPerMin = "feed_mm_per_min";
inline constexpr std::string_view kSamplePeriodS = "sample_period_s";
inline constexpr std::string_view kRadiusSign = "radius_sign";
inline constexpr std::string_view kStartYMm = "start_y_mm";
inline constexpr std::string_view kHasEncoder = "has_encoder";
inline constexpr std::string_view kFirstValidSample = "first_valid_sample";
inline constexpr std::string_view kLastValidSample = "last_valid_sample";
}  // namespace scan

// Spindle speed in rpm.
inline constexpr std::string_view kSpindleRpmNominal = "spindle_rpm_nominal";
inline constexpr std::string_view kSpindleRpmEstimated = "spindle_rpm_estimated";
inline constexpr std::string_view kSpindleRpmSource =
    "spindle_rpm_source";  // "nominal", "estimated", "encoder"
inline constexpr std::string_view kSpindleRpmSigma = "spindle_rpm_sigma";
inline constexpr std::string_view kSpindleRpmFitted = "spindle_rpm_fitted";

inline constexpr std::string_view kNoiseSigmaUm = "noise_sigma_um";
inline constexpr std::string_view kMapSigmaUm = "map_sigma_um";

// Headline figures.
inline constexpr std::string_view kMeanArcRadiusMm = "mean_arc_radius_mm";
inline constexpr std::string_view kMeanArcRadiusSigmaMm = "mean_arc_radius_sigma_mm";
inline constexpr std::string_view kArcRadiusRangeMm = "arc_radius_range_mm";
inline constexpr std::string_view kArcRadiusFluctuationPct = "arc_radius_fluctuation_pct";
inline constexpr std::string_view kArcRadiusStdMm = "arc_radius_std_mm";
inline constexpr std::string_view kArcRadiusNoiseStdMm = "arc_radius_noise_std_mm";
inline constexpr std::string_view kArcRadiusExcessStdMm = "arc_radius_excess_std_mm";
inline constexpr std::string_view kMeanCenterAxialMm = "mean_center_axial_mm";
inline constexpr std::string_view kMeanCenterAxialSigmaMm = "mean_center_axial_sigma_mm";
inline constexpr std::string_view kCenterAxialDeviationMm = "center_axial_deviation_mm";
inline constexpr std::string_view kMeanCenterRadialMm = "mean_center_radial_mm";
inline constexpr std::string_view kBandHalfWidthMm = "band_half_width_mm";
inline constexpr std::string_view kBandMm = "band_mm";  // [low, high]
inline constexpr std::string_view kMaxArcErrorUm = "max_arc_error_um";
inline constexpr std::string_view kMaxRunoutUm = "max_runout_um";
inline constexpr std::string_view kMaxRoundnessUm = "max_roundness_um";
inline constexpr std::string_view kMedianChi2PerDof = "median_chi2_per_dof";
inline constexpr std::string_view kUsablePhases = "usable_phases";
inline constexpr std::string_view kRunoutNote = "runout_note";

// Per-phase arrays, one entry per phase node.
inline constexpr std::string_view kPhases = "phases";
namespace phases {
inline constexpr std::string_view kPhaseDeg = "phase_deg";
inline constexpr std::string_view kArcRadiusMm = "arc_radius_mm";
inline constexpr std::string_view kArcRadiusSigmaMm = "arc_radius_sigma_mm";
inline constexpr std::string_view kCenterAxialMm = "center_axial_mm";
inline constexpr std::string_view kCenterAxialSigmaMm = "center_axial_sigma_mm";
inline constexpr std::string_view kCenterRadialMm = "center_radial_mm";
inline constexpr std::string_view kCenterRadialSigmaMm = "center_radial_sigma_mm";
inline constexpr std::string_view kArcErrorUm = "arc_error_um";
inline constexpr std::string_view kChi2PerDof = "chi2_per_dof";
inline constexpr std::string_view kPointsInBand = "points_in_band";
inline constexpr std::string_view kUsable = "usable";
inline constexpr std::string_view kFlag = "flag";
}  // namespace phases

// Per-axial-node arrays over the band.
inline constexpr std::string_view kAxial = "axial";
namespace axial {
inline constexpr std::string_view kYMm = "y_mm";
inline constexpr std::string_view kRunoutUm = "runout_um";
inline constexpr std::string_view kRoundnessUm = "roundness_um";
}  // namespace axial

// The mean measured profile against the mean circle.
inline constexpr std::string_view kMeanProfile = "mean_profile";
namespace mean_profile {
inline constexpr std::string_view kUMm = "u_mm";
inline constexpr std::string_view kErrorUm = "error_um";
}  // namespace mean_profile

// The wheel model fitted to every sample in the band (fitting/wheel_model.h, docs/wheel_model.md);
// absent when the model was not asked for (--no-model).
inline constexpr std::string_view kModel = "model";
namespace model {
inline constexpr std::string_view kRadiusKnots = "radius_knots";  // knots per turn of Ra(c); 1 = constant
inline constexpr std::string_view kAxialKnots = "axial_knots";    // of a(c)
inline constexpr std::string_view kRunoutKnots = "runout_knots";  // of b(c)
inline constexpr std::string_view kKnotsChosenBy = "knots_chosen_by";  // "bic" or "given"
inline constexpr std::string_view kProfileCoefficients = "profile_coefficients";
inline constexpr std::string_view kSamples = "samples";
inline constexpr std::string_view kParameters = "parameters";
inline constexpr std::string_view kIterations = "iterations";
inline constexpr std::string_view kResidualRmsUm = "residual_rms_um";
inline constexpr std::string_view kNoiseSigmaUm = "noise_sigma_um";
inline constexpr std::string_view kMeanArcRadiusMm = "mean_arc_radius_mm";
inline constexpr std::string_view kMeanArcRadiusSigmaMm = "mean_arc_radius_sigma_mm";
inline constexpr std::string_view kArcRadiusRangeMm = "arc_radius_range_mm";
inline constexpr std::string_view kArcRadiusRangeSigmaMm = "arc_radius_range_sigma_mm";
inline constexpr std::string_view kVariationChi2 = "radius_variation_chi2";
inline constexpr std::string_view kVariationDof = "radius_variation_dof";
inline constexpr std::string_view kVariationPValue = "radius_variation_p_value";
inline constexpr std::string_view kSignificanceLevel = "significance_level";
inline constexpr std::string_view kVariationSignificant = "radius_variation_significant";
inline constexpr std::string_view kProfilePvUm = "profile_pv_um";
inline constexpr std::string_view kRadiusHarmonics = "radius_harmonics";  // a list of objects:
namespace harmonic {
inline constexpr std::string_view kOrder = "order";
inline constexpr std::string_view kAmplitudeUm = "amplitude_um";
inline constexpr std::string_view kAmplitudeSigmaUm = "amplitude_sigma_um";
inline constexpr std::string_view kPhaseDeg = "phase_deg";
inline constexpr std::string_view kPhaseSigmaDeg = "phase_sigma_deg";
}  // namespace harmonic
}  // namespace model

// Every processing parameter as used, flat (one number or string per key). The same names are
// the root attributes of wheel_map.h5.
inline constexpr std::string_view kProcessing = "processing";
namespace processing {
inline constexpr std::string_view kPhases = "phases";
inline constexpr std::string_view kBandHalfWidthMm = "band_half_width_mm";
inline constexpr std::string_view kDespikeWindowHalfWidth = "despike_window_half_width";
inline constexpr std::string_view kDespikeThresholdUm = "despike_threshold_um";
inline constexpr std::string_view kDespikeThresholdSigmas = "despike_threshold_sigmas";
inline constexpr std::string_view kDespikeMinThresholdUm = "despike_min_threshold_um";
inline constexpr std::string_view kSpeedMaxHarmonic = "speed_max_harmonic";
inline constexpr std::string_view kSpeedSignificanceSigmas = "speed_significance_sigmas";
inline constexpr std::string_view kMapMinSupport = "map_min_support";
inline constexpr std::string_view kMapMaxSigmaRatio = "map_max_sigma_ratio";
inline constexpr std::string_view kFitMinPoints = "fit_min_points";
inline constexpr std::string_view kFitMinBandCoverage = "fit_min_band_coverage";
inline constexpr std::string_view kRunoutMinPhaseCoverage = "runout_min_phase_coverage";
inline constexpr std::string_view kBeamOffsetMm = "beam_offset_mm";
inline constexpr std::string_view kWheelRadiusMm = "wheel_radius_mm";
inline constexpr std::string_view kStuckRunDeg = "stuck_run_deg";
inline constexpr std::string_view kModelKnots = "model_knots";  // 0: chosen from the data
inline constexpr std::string_view kModelAxialKnots = "model_axial_knots";
inline constexpr std::string_view kModelRunoutKnots = "model_runout_knots";
inline constexpr std::string_view kModelProfileStepMm = "model_profile_step_mm";
inline constexpr std::string_view kModel = "model";  // "on" or "off"
inline constexpr std::string_view kDespikeMethod = "despike_method";
inline constexpr std::string_view kRpmSource = "rpm_source";
inline constexpr std::string_view kFitSpan = "fit_span";
inline constexpr std::string_view kFilter = "filter";
// Written by the writer itself (summary.json only).
inline constexpr std::string_view kKnotStepDeg = "knot_step_deg";
inline constexpr std::string_view kAxialStepMm = "axial_step_mm";
inline constexpr std::string_view kDespikeThresholdUsedUm = "despike_threshold_used_um";
inline constexpr std::string_view kStuckRunSamplesUsed = "stuck_run_samples_used";
}  // namespace processing

inline constexpr std::string_view kWarnings = "warnings";  // array of strings

// Measurement uncertainty per GUM and conformity decisions per ISO 14253-1
// (uncertainty/wheel_uncertainty.h, docs/uncertainty.md); absent with --no-uncertainty.
inline constexpr std::string_view kUncertainty = "uncertainty";
// Each characteristic under its operator (formats.md section 3.3, workflows/characteristics_step.h);
// absent with --no-uncertainty.
inline constexpr std::string_view kCharacteristics = "characteristics";
namespace uncertainty {
inline constexpr std::string_view kCoverageProbability = "coverage_probability";
inline constexpr std::string_view kBudgetSource = "budget_source";  // "default" or the budget file's path
inline constexpr std::string_view kBudget = "budget";               // the type B inputs, as a budget file
inline constexpr std::string_view kQuantities = "quantities";       // by headline key:
namespace quantity {
inline constexpr std::string_view kUnit = "unit";             // "mm", "um" or "%"
inline constexpr std::string_view kMeasured = "measured";     // the headline value as above
inline constexpr std::string_view kValue = "value";           // the estimate: noise-corrected for a PV
inline constexpr std::string_view kNoiseBias = "noise_bias";  // measured - value's PV part; PV only
inline constexpr std::string_view kTypeAMethod = "type_a_method";
inline constexpr std::string_view kContributions = "contributions";  // list of objects:
namespace contribution {
inline constexpr std::string_view kName = "name";
inline constexpr std::string_view kSource = "source";
inline constexpr std::string_view kType = "type";  // "A" or "B"
inline constexpr std::string_view kUnit = "unit";
inline constexpr std::string_view kDistribution = "distribution";
inline constexpr std::string_view kStandardUncertainty = "standard_uncertainty";  // input's unit
inline constexpr std::string_view kSensitivity = "sensitivity";
inline constexpr std::string_view kContribution = "contribution";  // quantity's unit
inline constexpr std::string_view kDof = "dof";                    // null = infinite
}  // namespace contribution
inline constexpr std::string_view kCorrection = "correction";
inline constexpr std::string_view kStandardUncertainty = "u_c";
inline constexpr std::string_view kEffectiveDof = "nu_eff";  // null = infinite
inline constexpr std::string_view kCoverageFactor = "k";
inline constexpr std::string_view kExpanded = "U";
}  // namespace quantity
// With `process --tolerances`: the rule and the decision for each toleranced quantity.
inline constexpr std::string_view kDecisionRule = "decision_rule";  // "iso14253-1" or "simple-acceptance"
inline constexpr std::string_view kDecisions = "decisions";         // by headline key, objects:
namespace decision {
inline constexpr std::string_view kMin = "min";  // the specification's limits; null = one-sided
inline constexpr std::string_view kMax = "max";
inline constexpr std::string_view kValue = "value";  // the estimate decided on (as quantities)
inline constexpr std::string_view kExpanded = "U";   // its expanded uncertainty
inline constexpr std::string_view kCoverageFactor = "k";
inline constexpr std::string_view kDecision = "decision";  // "conforms", "does not conform", "not proven"
}  // namespace decision
// Over the toleranced quantities: "does not conform" if any does not, else "not proven" if any is
// not proven, else "conforms"; null when the tolerance file limits none of them.
inline constexpr std::string_view kOverall = "overall";
}  // namespace uncertainty

}  // namespace arcwheel::schema::summary
