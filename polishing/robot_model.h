#pragma once
// The industrial robots a polishing job can name (docs/polishing.md, "Robot"), and the placement
// of a robot in the cell.
//
// A model is a URDF (polishing/robots/, embedded in the library) that orocos KDL reads through
// urdfdom (robot_kinematics.h), plus the closed-form geometry of its arm, which
// the inverse kinematics uses and which is checked against the URDF's forward kinematics. The
// joint limits and speeds are the URDF's: for the shipped models they are those of the
// manufacturer's product specification, cited in the URDF and in docs/polishing.md.

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arcwheel::polishing {

// Geometry of a six-axis arm with an ortho-parallel basis and a spherical wrist, in the notation
// of Brandstoetter, Angerer and Hofbaur (2014), "An analytical solution of the inverse kinematics
// problem of industrial serial manipulators with an ortho-parallel basis and a spherical wrist":
// axis 2 lies a1 in front of axis 1 and c1 above the base; the lower arm (axis 2 to axis 3) is
// c2 long; the wrist centre (axes 4, 5, 6 meet there) lies c3 along the upper arm from axis 3 and
// |a2| above it (a2 < 0 for ABB's offset); the flange lies c4 beyond the wrist centre. All mm.
struct ArmGeometry {
  double a1_mm = 0.0;
  double a2_mm = 0.0;
  double c1_mm = 0.0;
  double c2_mm = 0.0;
  double c3_mm = 0.0;
  double c4_mm = 0.0;
};

struct RobotModel {
  std::string_view name;      // as the job names it, e.g. "ABB IRB 4600-40/2.55"
  std::string_view urdf;      // the URDF text (joint limits and speeds included)
  std::string_view citation;  // where the figures come from
  ArmGeometry geometry;
};

// Every model arcwheel knows, in the order `arcwheel help` and the docs list them.
[[nodiscard]] const std::vector<RobotModel>& RobotModels();
// The model of that name (exact spelling), or nothing.
[[nodiscard]] const RobotModel* FindRobotModel(std::string_view name);

// Margins a path must keep (robot.* job keys). Every target's joints must stay at least
// min_joint_margin_deg inside every joint limit, joint 5 at least min_wrist_margin_deg away from 0
// (the wrist singularity, where joints 4 and 6 line up), and every joint's speed at the programmed
// TCP speed at most max_joint_speed_ratio of the joint's maximum speed. A segment whose joint
// would be faster is slowed (time_scaling.h) as long as the removal that adds stays within
// max_added_residual_nm everywhere.
struct RobotMargins {
  double min_joint_margin_deg = 5.0;   // [0, 90)
  double min_wrist_margin_deg = 10.0;  // [0, 90)
  double max_joint_speed_ratio = 0.9;  // (0, 1]
  // Largest removal the slowed segments may add at any aperture node, nm, >= 0 (10 nm: a tenth
  // of the 0.1 um form tolerance of a polished optic, and a sixtieth of the 633 nm wavelength).
  double max_added_residual_nm = 10.0;
  // Empty when valid, else one line per violation naming the job key and the value.
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The robot of a polish job: which model and where its base frame lies in the world frame (the
// frame RAPID's wobjdata user frame is given in).
struct RobotCell {
  const RobotModel* model = nullptr;  // nothing: the job names no robot, nothing is checked
  Eigen::Isometry3d world_from_base = Eigen::Isometry3d::Identity();  // mm
  std::string urdf_override;  // robot.urdf's text, replacing the model's; empty: none
  std::string urdf_source;    // where the URDF came from, for messages
  RobotMargins margins;
};

// Checks that `m` (a 4 x 4 homogeneous matrix, mm) is a rigid transform: orthonormal rotation of
// determinant +1 to 1e-9, last row 0 0 0 1, finite. Empty when it is, else what is wrong.
[[nodiscard]] std::optional<std::string> RigidTransformProblem(const Eigen::Matrix4d& m);

}  // namespace arcwheel::polishing
