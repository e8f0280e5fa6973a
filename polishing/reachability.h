#pragma once
// Whether a robot can run a polishing path (docs/polishing.md, "Robot"): for every target the joint
// solution in one arm configuration held along the whole path, its margins to the joint limits and
// to the wrist singularity, and the joint speeds at the programmed TCP speeds; and a work-object
// placement that keeps every margin.
//
// Frames: a target is the TCP pose in the work object (RAPID's robtarget with \WObj); the work
// object lies in the world (wobjdata's user frame), the robot's base in the world (RobotCell), the
// TCP in the flange's tool0 frame (tooldata). So base_from_flange = base_from_world *
// world_from_work_object * work_object_from_tcp * tcp_from_flange.

#include <Eigen/Geometry>
#include <array>
#include <span>
#include <string>
#include <vector>

#include "polishing/robot_kinematics.h"
#include "polishing/robot_model.h"
#include "polishing/robot_program.h"

namespace arcwheel::polishing {

// The robot's solution of a whole path.
struct RobotPath {
  ArmBranch branch;                                         // held along the path (cfx)
  std::vector<JointAngles> joints_rad;                      // one per target, joints 4 and 6 unwrapped
  std::vector<std::array<int, 4>> confdata;                 // RAPID [cf1, cf4, cf6, cfx] of each target
  std::array<double, kRobotJoints> min_limit_margin_deg{};  // smallest margin to either limit, per joint
  double wrist_margin_deg = 0.0;                            // smallest |joint 5| along the path
  std::array<double, kRobotJoints> max_speed_ratio{};       // largest joint speed / its maximum, per joint
  double largest_speed_ratio = 0.0;                         // the largest of max_speed_ratio
  int largest_speed_joint = 1;                              // which joint (1 - 6) has it
  // The lower and upper limit of each joint, deg (the URDF's), for reports.
  std::array<std::array<double, 2>, kRobotJoints> limits_deg{};
};

// The base_from_flange pose of each point (see above), mm.
[[nodiscard]] std::vector<Eigen::Isometry3d> FlangePosesInBase(std::span<const PolishingPoint> points,
                                                               const ToolData& tool,
                                                               const WorkObject& work_object,
                                                               const Eigen::Isometry3d& world_from_base);

// Solves the path in each of the eight arm configurations and keeps the one that runs it with
// the largest margins: every target reached, every joint at least min_joint_margin_deg inside its
// limits, |joint 5| >= min_wrist_margin_deg, and each joint's speed over each segment (its change
// over the segment's time, the point's dwell_s) at most max_joint_speed_ratio of its maximum.
// Joints 4 and 6 take the turn (+- 360 deg) nearest the previous target's. Throws
// Error{kBadInput, "polishing.robot"} when no configuration runs the path, naming the first target
// where the configuration that gets furthest fails and why: out of reach, joint N beyond (or too
// near) its limit, through the wrist singularity (joint 5), joint N too fast; when every target
// alone is reachable in some configuration but no one configuration reaches them all, the message
// says that the path needs a configuration change. `job_name` prefixes the message.
[[nodiscard]] RobotPath SolveRobotPath(const RobotKinematics& kinematics, const RobotMargins& margins,
                                       std::span<const Eigen::Isometry3d> base_from_flange,
                                       std::span<const double> segment_time_s, const std::string& job_name,
                                       std::span<const Eigen::Vector3d> target_mm = {});

// How far a solved path keeps from the job's thresholds: the least of the joint-limit margin above
// its threshold and the wrist margin above its threshold (deg), or -1 when the speed ratio exceeds
// its limit. Larger is better; >= 0 keeps every margin.
[[nodiscard]] double MarginSlackDeg(const RobotPath& path, const RobotMargins& margins);

struct WorkObjectProposal {
  Eigen::Vector3d origin_mm = Eigen::Vector3d::Zero();  // in the world frame, orientation kept
  RobotPath path;                                       // the path solved there
  double slack_deg = 0.0;                               // MarginSlackDeg there
  int candidates = 0;                                   // placements tried
};

// Searches work-object origins (the job's orientation kept) over the robot's working range for
// the one with the largest MarginSlackDeg: a grid of 200 mm over a box around the base, on a
// subsample of the targets, refined to 50 mm and 10 mm around the best, then the whole path solved
// there. Throws Error{kBadInput, "polishing.robot"}
// when no placement keeps every margin (naming the best found and its margins).
[[nodiscard]] WorkObjectProposal ProposeWorkObjectOrigin(
    const RobotKinematics& kinematics, const RobotMargins& margins, std::span<const PolishingPoint> points,
    const ToolData& tool, const WorkObject& work_object, const Eigen::Isometry3d& world_from_base,
    std::span<const double> segment_time_s, const std::string& job_name);

}  // namespace arcwheel::polishing
