#pragma once
// wheel_map.h5, written by `arcwheel process` (fitting/outputs.cc) and read by the inspection
// report: the one place that spells its dataset paths and root attributes (docs/outputs.md).
// Grids are [n_phase, n_y], row-major. The processing parameters are root attributes too, named
// as in summary.json's `processing` (schema/summary.h).

#include <string_view>

#include "schema/version.h"

namespace arcwheel::schema::wheel_map {

inline constexpr int kMajorVersion = 1;
inline constexpr int kMinorVersion = 1;  // 1.1: /model
inline constexpr Version kVersion{kMajorVersion, kMinorVersion};
inline constexpr std::string_view kFileName = "wheel_map.h5";

// The regular map.
inline constexpr std::string_view kMapGroup = "/map";
inline constexpr std::string_view kMapPhaseDeg = "/map/phase_deg";            // [n_phase]
inline constexpr std::string_view kMapYMm = "/map/y_mm";                      // [n_y]
inline constexpr std::string_view kMapRhoMm = "/map/rho";                     // [n_phase, n_y], mm
inline constexpr std::string_view kMapFormErrorUm = "/map/form_error_um";     // [n_phase, n_y]
inline constexpr std::string_view kMapSampleCount = "/map/sample_count";      // [n_phase, n_y], int
inline constexpr std::string_view kMapDespikedCount = "/map/despiked_count";  // [n_phase, n_y], int

// Per-phase fits, [n_phase]; NaN for a phase that is not usable.
inline constexpr std::string_view kFitGroup = "/fit";
inline constexpr std::string_view kFitArcRadiusMm = "/fit/arc_radius_mm";
inline constexpr std::string_view kFitArcRadiusSigmaMm = "/fit/arc_radius_sigma_mm";
inline constexpr std::string_view kFitCenterAxialMm = "/fit/center_axial_mm";
inline constexpr std::string_view kFitCenterAxialSigmaMm = "/fit/center_axial_sigma_mm";
inline constexpr std::string_view kFitCenterRadialMm = "/fit/center_radial_mm";
inline constexpr std::string_view kFitCenterRadialSigmaMm = "/fit/center_radial_sigma_mm";
inline constexpr std::string_view kFitArcErrorUm = "/fit/arc_error_um";
inline constexpr std::string_view kFitUsable = "/fit/usable";                // int, 1 or 0
inline constexpr std::string_view kFitPointsInBand = "/fit/points_in_band";  // int

// Runout and roundness per axial node of the band, [n_band].
inline constexpr std::string_view kAxialGroup = "/axial";
inline constexpr std::string_view kAxialYMm = "/axial/y_mm";
inline constexpr std::string_view kAxialRunoutUm = "/axial/runout_um";
inline constexpr std::string_view kAxialRoundnessUm = "/axial/roundness_um";

// Attributes of the root group "/".
// The wheel model (fitting/wheel_model.h), on the map's phase nodes; absent with --no-model.
inline constexpr std::string_view kModelGroup = "/model";
inline constexpr std::string_view kModelArcRadiusMm = "/model/arc_radius_mm";  // [n_phase]
inline constexpr std::string_view kModelArcRadiusSigmaMm = "/model/arc_radius_sigma_mm";
inline constexpr std::string_view kModelCenterAxialMm = "/model/center_axial_mm";
inline constexpr std::string_view kModelCenterAxialSigmaMm = "/model/center_axial_sigma_mm";
inline constexpr std::string_view kModelCenterRadialMm = "/model/center_radial_mm";
inline constexpr std::string_view kModelCenterRadialSigmaMm = "/model/center_radial_sigma_mm";
inline constexpr std::string_view kModelProfileUMm = "/model/profile_u_mm";  // [n_u]
inline constexpr std::string_view kModelProfileErrorUm = "/model/profile_error_um";
inline constexpr std::string_view kModelProfileErrorSigmaUm = "/model/profile_error_sigma_um";
inline constexpr std::string_view kModelResidualUm = "/model/residual_um";  // [n_phase, n_y], NaN: no sample
// [Ra knots, a knots, b knots, p's B-spline coefficients] (mm) and their covariance (mm^2).
inline constexpr std::string_view kModelCoefficients = "/model/coefficients";
inline constexpr std::string_view kModelCovariance = "/model/covariance";  // [n, n]

inline constexpr std::string_view kRoot = "/";
inline constexpr std::string_view kSchemaVersionAttribute = "schema_version";  // "MAJOR.MINOR"
inline constexpr std::string_view kArcwheelVersionAttribute = "arcwheel_version";
inline constexpr std::string_view kInputPathAttribute = "input_path";
inline constexpr std::string_view kInputSha256Attribute = "input_sha256";
inline constexpr std::string_view kNoiseSigmaUmAttribute = "noise_sigma_um";
inline constexpr std::string_view kSpindleRpmUsedAttribute = "spindle_rpm_used";

}  // namespace arcwheel::schema::wheel_map
