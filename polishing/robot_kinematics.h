#pragma once
// Forward and inverse kinematics of a robot model (robot_model.h). The forward kinematics is
// orocos KDL's over the chain base_link -> tool0 of the model's URDF (read with urdfdom); the inverse is the
// closed form of an ortho-parallel arm with a spherical wrist (Brandstoetter et al. 2014), whose geometry is
// checked against the URDF when the kinematics is made. KDL's headers stay in robot_kinematics.cc.
//
// Frames and units: poses are base_from_flange (the flange's tool0 frame in the robot's base
// frame), translation in mm; joint angles in rad, with the controller's signs and zeros.

#include <Eigen/Geometry>
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "polishing/robot_model.h"

namespace arcwheel::polishing {

inline constexpr int kRobotJoints = 6;
using JointAngles = std::array<double, kRobotJoints>;  // rad

struct JointLimit {
  double lower_rad = 0.0;
  double upper_rad = 0.0;
  double max_speed_rad_s = 0.0;
};

// One of the eight closed-form branches, in ABB's cfx terms (RAPID confdata): the wrist centre in
// front of or behind axis 1, in front of or behind the lower arm, and the sign of joint 5.
struct ArmBranch {
  bool behind_axis1 = false;
  bool behind_lower_arm = false;
  bool negative_joint5 = false;
  // ABB's cfx, 0 - 7: 4 behind_axis1 + 2 behind_lower_arm + negative_joint5.
  [[nodiscard]] int Cfx() const { return 4 * behind_axis1 + 2 * behind_lower_arm + negative_joint5; }
  [[nodiscard]] static ArmBranch FromCfx(int cfx) { return {(cfx & 4) != 0, (cfx & 2) != 0, (cfx & 1) != 0}; }
};

// ABB's quadrant of a joint angle (confdata cf1, cf4, cf6): floor(angle / 90 deg), so 0 for
// [0, 90) deg, -1 for [-90, 0) deg, 2 for [180, 270) deg.
[[nodiscard]] int JointQuadrant(double angle_rad);

class RobotKinematics {
 public:
  // Reads `urdf` (text; `source` names it in messages) and the chain base_link -> tool0 with six
  // revolute joints and their limits. Throws Error{kBadInput, "polishing.robot"} naming `source`
  // when the URDF does not parse, lacks that chain or a joint's limits, or when its forward
  // kinematics differs from the model's closed-form geometry by more than 1e-6 mm anywhere in a
  // set of test poses (the inverse would then not invert it).
  RobotKinematics(const RobotModel& model, const std::string& urdf, const std::string& source);
  ~RobotKinematics();
  RobotKinematics(RobotKinematics&&) noexcept;
  RobotKinematics& operator=(RobotKinematics&&) noexcept;

  // KDL's forward kinematics: tool0 in the base frame, mm.
  [[nodiscard]] Eigen::Isometry3d ForwardKdl(const JointAngles& q) const;
  // The closed form of the same (the model's geometry), for the inverse's own checks.
  [[nodiscard]] Eigen::Isometry3d ForwardClosedForm(const JointAngles& q) const;
  // The solution of one branch for a flange pose, joints 1, 4 and 6 in (-pi, pi]; nothing when
  // the wrist centre is out of the arm's reach. Joint limits are not applied.
  [[nodiscard]] std::optional<JointAngles> Inverse(const Eigen::Isometry3d& base_from_flange,
                                                   const ArmBranch& branch) const;
  // The wrist centre (axes 4, 5, 6) of a flange pose, mm.
  [[nodiscard]] Eigen::Vector3d WristCentre(const Eigen::Isometry3d& base_from_flange) const;

  [[nodiscard]] const std::array<JointLimit, kRobotJoints>& limits() const { return limits_; }
  [[nodiscard]] const RobotModel& model() const { return *model_; }

 private:
  struct Chain;  // KDL's chain and solver
  const RobotModel* model_;
  std::array<JointLimit, kRobotJoints> limits_{};
  std::unique_ptr<Chain> chain_;
};

}  // namespace arcwheel::polishing
