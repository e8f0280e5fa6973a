#pragma once
// toolpath_summary.json, which `arcwheel toolpath` writes (grinding/toolpath_writer.cc) and
// `arcwheel regenerate` reads back for its report (workflows/regenerate_report.cc): the one place
// that spells its keys. A key of a nested object lives in the namespace named after the object.

#include <string_view>

namespace arcwheel::schema::toolpath {

inline constexpr std::string_view kSummaryFileName = "toolpath_summary.json";
inline constexpr std::string_view kPredictionFileName = "prediction.h5";

namespace summary {
inline constexpr std::string_view kArcwheelVersion = "arcwheel_version";
inline constexpr std::string_view kJob = "job";  // the job as used, every default filled in
namespace job {
inline constexpr std::string_view kName = "name";
}  // namespace job
inline constexpr std::string_view kJobPath = "job_path";
inline constexpr std::string_view kSurface = "surface";  // descriptions, full precision
inline constexpr std::string_view kWheel = "wheel";
inline constexpr std::string_view kWheelProfile = "wheel_profile";  // "mean" or "model"
// The nominal and the measured arc radius side by side, with a measured wheel.
inline constexpr std::string_view kArcRadius = "arc_radius";
namespace arc_radius {
inline constexpr std::string_view kNominalMm = "nominal_mm";
inline constexpr std::string_view kMeasuredMm = "measured_mm";
inline constexpr std::string_view kMeasuredSigmaMm = "measured_sigma_mm";
inline constexpr std::string_view kDifferenceMm = "difference_mm";
inline constexpr std::string_view kMaxChangeMm = "max_change_mm";
inline constexpr std::string_view kUsed = "used";
}  // namespace arc_radius
inline constexpr std::string_view kToolpath = "toolpath";
namespace toolpath {
inline constexpr std::string_view kPasses = "passes";
inline constexpr std::string_view kRowsPerPass = "rows_per_pass";
inline constexpr std::string_view kControlPoints = "control_points";
inline constexpr std::string_view kFirstRowYwMm = "first_row_yw_mm";
inline constexpr std::string_view kRowPitchMm = "row_pitch_mm";
inline constexpr std::string_view kMaxRowDeviationMm = "max_row_deviation_mm";
inline constexpr std::string_view kGougeChecks = "gouge_checks";
inline constexpr std::string_view kMinGougeGapUm = "min_gouge_gap_um";
inline constexpr std::string_view kMinClearanceCurvaturePerMm = "min_clearance_curvature_per_mm";
}  // namespace toolpath
inline constexpr std::string_view kPrediction = "prediction";  // with prediction.enabled
namespace prediction {
inline constexpr std::string_view kArcRadiusErrorMm = "arc_radius_error_mm";
inline constexpr std::string_view kArcRadiusErrorSource = "arc_radius_error_source";
inline constexpr std::string_view kKeepTotalRadius = "keep_total_radius";
inline constexpr std::string_view kPvUm = "pv_um";
inline constexpr std::string_view kRmsUm = "rms_um";
inline constexpr std::string_view kPvAfterTiltUm = "pv_after_tilt_um";
inline constexpr std::string_view kRmsAfterTiltUm = "rms_after_tilt_um";
inline constexpr std::string_view kRipplePvUm = "ripple_pv_um";
inline constexpr std::string_view kProfilePvUm = "profile_pv_um";
}  // namespace prediction
inline constexpr std::string_view kFiles = "files";  // the files written, by name
}  // namespace summary

}  // namespace arcwheel::schema::toolpath
