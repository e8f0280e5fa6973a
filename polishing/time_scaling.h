#pragma once
// Time scaling where a joint would be too fast (docs/polishing.md, "Slowed segments").
//
// A robot controller that cannot turn a joint as fast as a segment's programmed TCP speed asks
// slows down there, and the part then receives more removal than the dwell planned. arcwheel does
// the same in the plan: each segment into a target takes at least the time its fastest joint
// needs at max_joint_speed_ratio of its maximum speed; the targets' poses are kept (with
// precession the bonnet then turns more slowly over that segment), the extra time is carried into
// the removal prediction, and the job is refused only where the removal it adds exceeds
// robot.max_added_residual_nm.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "polishing/reachability.h"
#include "polishing/removal_function.h"
#include "polishing/removal_target.h"
#include "polishing/robot_program.h"
#include "surfaces/surface.h"

namespace arcwheel::polishing {

// A segment lengthened to what its fastest joint allows.
struct SlowedSegment {
  std::size_t target = 0;  // the target the segment runs into, 0-based (messages say target + 1)
  int joint = 1;           // the joint (1 - 6) that sets the time
  double planned_s = 0.0;  // the dwell's time of the segment
  double slowed_s = 0.0;   // the time the joint allows
};

// The removal the slowed segments add over the aperture (what the residual loses), nm.
struct AddedRemoval {
  double pv_nm = 0.0;                                   // largest - smallest over the aperture nodes
  double rms_nm = 0.0;                                  // about zero, over the aperture nodes
  double max_nm = 0.0;                                  // the largest
  Eigen::Vector2d max_at_mm = Eigen::Vector2d::Zero();  // where, part frame (x, y)
};

struct TimeScaling {
  std::vector<SlowedSegment> slowed;
  double added_time_s = 0.0;
  AddedRemoval added;
};

// Lengthens every segment of `points` shorter than its fastest joint of `path` allows (at
// max_joint_speed_ratio of the joint's maximum speed) to that time (speed = chord / time), and sums the
// removal that adds over the aperture nodes of `target` (removal function at each target's contact point).
// Throws Error{kBadInput, "polishing.robot"} when the largest added removal exceeds
// margins.max_added_residual_nm, naming the target whose slowing adds the most there; `job_name` prefixes the
// message.
[[nodiscard]] TimeScaling SlowDownToJointSpeeds(std::vector<PolishingPoint>& points,
                                                const RobotKinematics& kinematics, const RobotPath& path,
                                                const ErrorMap& target, const surfaces::Aperture& aperture,
                                                const RemovalFunction& removal, const RobotMargins& margins,
                                                const std::string& job_name);

}  // namespace arcwheel::polishing
