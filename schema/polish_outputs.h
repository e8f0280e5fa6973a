#pragma once
// The outputs of `arcwheel polish` that the polish report reads back (docs/polishing.md), written
// by polishing/job.cc and polishing/robot_program.cc and read by reports/polish_report_inputs.cc:
// the one place that spells polish_summary.json's keys and the CSV column names. polish.mod is a
// robot program, not read back, and has no schema here.
//
// The version recorded in polish_summary.json covers the set: the CSV files carry none.

#include <array>
#include <string_view>

#include "schema/version.h"

namespace arcwheel::schema::polish {

inline constexpr int kMajorVersion = 1;
inline constexpr int kMinorVersion = 0;
inline constexpr Version kVersion{kMajorVersion, kMinorVersion};

inline constexpr std::string_view kSummaryFileName = "polish_summary.json";
inline constexpr std::string_view kResidualMapFileName = "residual_map.csv";
// The same residual (and target and removal) as a grid map, schema/grid_map.h.
inline constexpr std::string_view kResidualGridFileName = "residual_map.h5";
inline constexpr std::string_view kPathFileName = "polishing_path.csv";
// The robot's joint angles at each target (only when the job names a robot).
inline constexpr std::string_view kRobotJointsFileName = "robot_joints.csv";

// polish_summary.json. A key of a nested object lives in the namespace named after the object.
namespace summary {
inline constexpr std::string_view kSchemaVersion = "schema_version";  // "MAJOR.MINOR"; absent before 1.0
inline constexpr std::string_view kArcwheelVersion = "arcwheel_version";
// The job as used, every default filled in: the keys of the polish job file (docs/polishing.md).
inline constexpr std::string_view kJob = "job";
namespace job {
inline constexpr std::string_view kName = "name";
inline constexpr std::string_view kErrorMap = "error_map";
namespace error_map {
inline constexpr std::string_view kFile = "file";
}  // namespace error_map
inline constexpr std::string_view kMachine = "machine";
namespace machine {
inline constexpr std::string_view kMaxSpeedMmS = "max_speed_mm_s";
inline constexpr std::string_view kMinSpeedMmS = "min_speed_mm_s";
inline constexpr std::string_view kMaxAccelerationMmS2 = "max_acceleration_mm_s2";
}  // namespace machine
}  // namespace job
inline constexpr std::string_view kPoints = "points";  // rows of polishing_path.csv
inline constexpr std::string_view kTotalTimeS = "total_time_s";
// Figures of the residual over the aperture before and after the planned removal.
inline constexpr std::string_view kBefore = "before";
inline constexpr std::string_view kAfter = "after";
namespace figures {
inline constexpr std::string_view kPvUm = "pv_um";
inline constexpr std::string_view kRmsUm = "rms_um";
}  // namespace figures
inline constexpr std::string_view kApertureNodes = "aperture_nodes";  // rows of residual_map.csv
inline constexpr std::string_view kSpeedMmS = "speed_mm_s";
namespace speed_mm_s {
inline constexpr std::string_view kMin = "min";
inline constexpr std::string_view kMax = "max";
}  // namespace speed_mm_s
inline constexpr std::string_view kMaxAccelerationMmS2 = "max_acceleration_mm_s2";
inline constexpr std::string_view kSolver = "solver";
namespace solver {
inline constexpr std::string_view kIterations = "iterations";
inline constexpr std::string_view kConverged = "converged";
inline constexpr std::string_view kNonzeros = "nonzeros";
inline constexpr std::string_view kShapingRounds = "shaping_rounds";
}  // namespace solver
// The robot's solution of the path (only when the job names a robot): docs/polishing.md, "Robot".
inline constexpr std::string_view kRobot = "robot";
namespace robot {
inline constexpr std::string_view kModel = "model";
inline constexpr std::string_view kCfx = "cfx";  // the arm configuration held, RAPID confdata cfx
// Per joint 1 - 6: the smallest margin to either limit along the path (deg), the largest joint
// speed / the joint's maximum, and the limits [lower, upper] (deg).
inline constexpr std::string_view kMinLimitMarginDeg = "min_limit_margin_deg";
inline constexpr std::string_view kMaxJointSpeedRatio = "max_joint_speed_ratio";
inline constexpr std::string_view kLimitsDeg = "limits_deg";
inline constexpr std::string_view kWristMarginDeg = "wrist_margin_deg";  // smallest |joint 5|
inline constexpr std::string_view kLargestJointSpeedRatio = "largest_joint_speed_ratio";
inline constexpr std::string_view kLargestJointSpeedJoint = "largest_joint_speed_joint";  // 1 - 6
// The segments slowed where a joint could not run the dwell's speed (polishing/time_scaling.h),
// in path order: the target the segment runs into (1 = the first row of polishing_path.csv), the
// joint that set the time, the dwell's time and the slowed time. Empty: none.
inline constexpr std::string_view kSlowedSegments = "slowed_segments";
namespace slowed_segments {
inline constexpr std::string_view kTarget = "target";
inline constexpr std::string_view kJoint = "joint";
inline constexpr std::string_view kPlannedS = "planned_s";
inline constexpr std::string_view kSlowedS = "slowed_s";
}  // namespace slowed_segments
inline constexpr std::string_view kAddedTimeS = "added_time_s";  // their time added, s
// The removal their added time adds over the aperture (included in "after"), nm: PV, RMS about
// zero, the largest and where it lies [x, y] mm.
inline constexpr std::string_view kAddedRemoval = "added_removal";
namespace added_removal {
inline constexpr std::string_view kPvNm = "pv_nm";
inline constexpr std::string_view kRmsNm = "rms_nm";
inline constexpr std::string_view kMaxNm = "max_nm";
inline constexpr std::string_view kMaxAtMm = "max_at_mm";
}  // namespace added_removal
}  // namespace robot
}  // namespace summary

// residual_map.csv: one row per aperture node, in this column order.
namespace residual_map {
inline constexpr std::string_view kXMm = "x_mm";
inline constexpr std::string_view kYMm = "y_mm";
inline constexpr std::string_view kTargetUm = "target_um";
inline constexpr std::string_view kRemovalUm = "removal_um";
inline constexpr std::string_view kResidualUm = "residual_um";
inline constexpr std::array<std::string_view, 5> kColumns = {kXMm, kYMm, kTargetUm, kRemovalUm, kResidualUm};
}  // namespace residual_map

// polishing_path.csv: "# " comment lines, then one row per path point in this column order:
// position in mm (part frame), the tool orientation as an ABB quaternion (q1 = w), speed, dwell.
namespace path {
inline constexpr std::string_view kXMm = "x";
inline constexpr std::string_view kYMm = "y";
inline constexpr std::string_view kZMm = "z";
inline constexpr std::string_view kQ1 = "q1";
inline constexpr std::string_view kQ2 = "q2";
inline constexpr std::string_view kQ3 = "q3";
inline constexpr std::string_view kQ4 = "q4";
inline constexpr std::string_view kSpeedMmS = "speed_mm_s";
inline constexpr std::string_view kDwellS = "dwell_s";
inline constexpr std::array<std::string_view, 9> kColumns = {kXMm, kYMm, kZMm,      kQ1,    kQ2,
                                                             kQ3,  kQ4,  kSpeedMmS, kDwellS};
}  // namespace path

// robot_joints.csv: one row per target of polishing_path.csv, in path order: the target's number
// (1 = the first row) and joints 1 - 6 in degrees (joints 4 and 6 unwrapped along the path).
namespace robot_joints {
inline constexpr std::string_view kTarget = "target";
inline constexpr std::array<std::string_view, 7> kColumns = {kTarget,  "j1_deg", "j2_deg", "j3_deg",
                                                             "j4_deg", "j5_deg", "j6_deg"};
}  // namespace robot_joints

}  // namespace arcwheel::schema::polish
