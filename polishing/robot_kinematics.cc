#include "polishing/robot_kinematics.h"

#include <console_bridge/console.h>
#include <fmt/core.h>
#include <fmt/format.h>
#include <urdf_parser/urdf_parser.h>

#include <cmath>
#include <kdl/chain.hpp>
#include <kdl/chainfksolverpos_recursive.hpp>
#include <kdl/frames.hpp>
#include <kdl/jntarray.hpp>
#include <numbers>
#include <vector>

#include "core/error.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kRobotKinematicsStage = "polishing.robot";
constexpr double kPi = std::numbers::pi;

double Wrap(double angle_rad) {
  double a = std::remainder(angle_rad, 2.0 * kPi);
  if (a <= -kPi) a += 2.0 * kPi;
  return a;
}

Eigen::Matrix3d Rx(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix(); }
Eigen::Matrix3d Ry(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitY()).toRotationMatrix(); }
Eigen::Matrix3d Rz(double a) { return Eigen::AngleAxisd(a, Eigen::Vector3d::UnitZ()).toRotationMatrix(); }

// ABB's tool0 is the last link's frame turned by +90 deg about y: z out of the flange.
const Eigen::Matrix3d& LinkToTool0() {
  static const Eigen::Matrix3d r = Ry(kPi / 2.0);
  return r;
}

[[noreturn]] void Refuse(const std::string& source, const std::string& what) {
  throw Error(ErrorCode::kBadInput, kRobotKinematicsStage, fmt::format("URDF '{}' {}", source, what));
}

KDL::Frame FrameOf(const urdf::Pose& pose) {
  double x = 0.0, y = 0.0, z = 0.0, w = 1.0;
  pose.rotation.getQuaternion(x, y, z, w);
  return {KDL::Rotation::Quaternion(x, y, z, w),
          KDL::Vector(pose.position.x, pose.position.y, pose.position.z)};
}

// A URDF joint as KDL's segment joint, as kdl_parser makes it: the joint sits at the origin of its
// frame in the parent link, its axis turned into the parent link's axes. Joints that neither turn
// nor slide are fixed.
KDL::Joint JointOf(const urdf::Joint& joint) {
  const KDL::Frame parent_from_joint = FrameOf(joint.parent_to_joint_origin_transform);
  const KDL::Vector axis = parent_from_joint.M * KDL::Vector(joint.axis.x, joint.axis.y, joint.axis.z);
  switch (joint.type) {
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS:
      return {joint.name, parent_from_joint.p, axis, KDL::Joint::RotAxis};
    case urdf::Joint::PRISMATIC:
      return {joint.name, parent_from_joint.p, axis, KDL::Joint::TransAxis};
    default:
      return KDL::Joint(joint.name, KDL::Joint::None);
  }
}

// The chain of links from `base` to `tip`: each link from the tip back to the base is a segment
// whose joint is the link's parent joint. (kdl_parser builds the whole tree first; it also brings
// some fifty ROS libraries into every start of the program.) False when `tip` does not descend
// from `base`.
bool ChainBetween(const urdf::ModelInterface& model, const std::string& base, const std::string& tip,
                  KDL::Chain& chain) {
  std::vector<KDL::Segment> segments;
  urdf::LinkConstSharedPtr link = model.getLink(tip);
  while (link && link->name != base) {
    const urdf::JointSharedPtr& joint = link->parent_joint;
    if (!joint) return false;
    segments.emplace_back(link->name, JointOf(*joint), FrameOf(joint->parent_to_joint_origin_transform));
    link = model.getLink(joint->parent_link_name);
  }
  if (!link) return false;
  for (auto segment = segments.rbegin(); segment != segments.rend(); ++segment) chain.addSegment(*segment);
  return true;
}

}  // namespace

int JointQuadrant(double angle_rad) { return static_cast<int>(std::floor(angle_rad / (kPi / 2.0))); }

struct RobotKinematics::Chain {
  KDL::Chain chain;
  std::unique_ptr<KDL::ChainFkSolverPos_recursive> fk;
};

RobotKinematics::~RobotKinematics() = default;
RobotKinematics::RobotKinematics(RobotKinematics&&) noexcept = default;
RobotKinematics& RobotKinematics::operator=(RobotKinematics&&) noexcept = default;

RobotKinematics::RobotKinematics(const RobotModel& model, const std::string& urdf, const std::string& source)
    : model_(&model), chain_(std::make_unique<Chain>()) {
  // urdfdom reports through console_bridge on stderr; the refusal below says it once, by file.
  console_bridge::setLogLevel(console_bridge::CONSOLE_BRIDGE_LOG_NONE);
  const urdf::ModelInterfaceSharedPtr parsed = urdf::parseURDF(urdf);
  if (!parsed) Refuse(source, "does not parse (not well-formed XML, or not a valid URDF robot)");
  if (!ChainBetween(*parsed, "base_link", "tool0", chain_->chain))
    Refuse(source, "has no chain of links from 'base_link' to 'tool0'");
  if (chain_->chain.getNrOfJoints() != kRobotJoints) {
    Refuse(source, fmt::format("has {} moving joints from base_link to tool0, a six-axis arm has {}",
                               chain_->chain.getNrOfJoints(), kRobotJoints));
  }
  int joint = 0;
  for (const KDL::Segment& segment : chain_->chain.segments) {
    if (segment.getJoint().getType() == KDL::Joint::None) continue;
    const std::string& name = segment.getJoint().getName();
    const urdf::JointConstSharedPtr j = parsed->getJoint(name);
    if (!j || j->type != urdf::Joint::REVOLUTE)
      Refuse(source, fmt::format("joint '{}' is not revolute (with limits)", name));
    if (!j->limits || !(j->limits->upper > j->limits->lower) || !(j->limits->velocity > 0.0)) {
      Refuse(source, fmt::format("joint '{}' needs limits with lower < upper and a velocity > 0", name));
    }
    limits_[static_cast<std::size_t>(joint++)] = {j->limits->lower, j->limits->upper, j->limits->velocity};
  }
  chain_->fk = std::make_unique<KDL::ChainFkSolverPos_recursive>(chain_->chain);
  // The closed-form inverse holds only if the URDF is the arm of the model's geometry: compare the
  // two forward kinematics over poses that move every joint.
  for (int k = 0; k < 24; ++k) {
    JointAngles q{};
    for (int i = 0; i < kRobotJoints; ++i)
      q[static_cast<std::size_t>(i)] = 2.5 * std::sin(1.3 * k + 0.7 * i + 0.1);
    const Eigen::Isometry3d kdl = ForwardKdl(q), closed = ForwardClosedForm(q);
    const double position_mm = (kdl.translation() - closed.translation()).norm();
    const double rotation = (kdl.linear() - closed.linear()).cwiseAbs().maxCoeff();
    if (position_mm > 1e-6 || rotation > 1e-9) {
      Refuse(source, fmt::format("is not the arm of '{}': at joints [{:.4f}] rad its flange lies {:.6g} mm "
                                 "from the model's closed-form geometry (rotation {:.3g} off)",
                                 model.name, fmt::join(q, ", "), position_mm, rotation));
    }
  }
}

Eigen::Isometry3d RobotKinematics::ForwardKdl(const JointAngles& q) const {
  KDL::JntArray joints(kRobotJoints);
  for (int i = 0; i < kRobotJoints; ++i) joints(static_cast<unsigned>(i)) = q[static_cast<std::size_t>(i)];
  KDL::Frame frame;
  chain_->fk->JntToCart(joints, frame);
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    out.translation()[r] = 1000.0 * frame.p[r];
    for (int c = 0; c < 3; ++c) out.linear()(r, c) = frame.M(r, c);
  }
  return out;
}

Eigen::Isometry3d RobotKinematics::ForwardClosedForm(const JointAngles& q) const {
  const ArmGeometry& g = model_->geometry;
  const Eigen::Matrix3d r1 = Rz(q[0]);
  const Eigen::Matrix3d r3 = r1 * Ry(q[1] + q[2]);
  const Eigen::Vector3d shoulder = r1 * Eigen::Vector3d(g.a1_mm, 0.0, g.c1_mm);
  const Eigen::Vector3d elbow = shoulder + r1 * Ry(q[1]) * Eigen::Vector3d(0.0, 0.0, g.c2_mm);
  const Eigen::Vector3d wrist = elbow + r3 * Eigen::Vector3d(g.c3_mm, 0.0, -g.a2_mm);
  const Eigen::Matrix3d r6 = r3 * Rx(q[3]) * Ry(q[4]) * Rx(q[5]);
  Eigen::Isometry3d out = Eigen::Isometry3d::Identity();
  out.linear() = r6 * LinkToTool0();
  out.translation() = wrist + r6 * Eigen::Vector3d(g.c4_mm, 0.0, 0.0);
  return out;
}

Eigen::Vector3d RobotKinematics::WristCentre(const Eigen::Isometry3d& base_from_flange) const {
  return base_from_flange.translation() - model_->geometry.c4_mm * base_from_flange.linear().col(2);
}

std::optional<JointAngles> RobotKinematics::Inverse(const Eigen::Isometry3d& base_from_flange,
                                                    const ArmBranch& branch) const {
  const ArmGeometry& g = model_->geometry;
  const Eigen::Vector3d w = WristCentre(base_from_flange);
  JointAngles q{};
  q[0] = Wrap(std::atan2(w.y(), w.x()) + (branch.behind_axis1 ? kPi : 0.0));
  // In the arm's plane: r along the arm (axis 1 turned by q1), z up; from axis 2 to the wrist.
  const double dx = w.x() * std::cos(q[0]) + w.y() * std::sin(q[0]) - g.a1_mm, dz = w.z() - g.c1_mm;
  const double upper = std::hypot(g.c3_mm, g.a2_mm), psi = std::atan2(-g.a2_mm, g.c3_mm);
  const double cos_gamma = (dx * dx + dz * dz - g.c2_mm * g.c2_mm - upper * upper) / (2.0 * g.c2_mm * upper);
  if (!(std::abs(cos_gamma) <= 1.0)) return std::nullopt;
  // gamma: the upper arm's direction from the lower arm's; the wrist centre lies in front of the
  // lower arm (on the side it leans towards) when sin(gamma) < 0.
  const double gamma = (branch.behind_lower_arm ? 1.0 : -1.0) * std::acos(cos_gamma);
  const double alpha =
      std::atan2(dz, dx) - std::atan2(upper * std::sin(gamma), g.c2_mm + upper * std::cos(gamma));
  q[1] = Wrap(kPi / 2.0 - alpha);
  q[2] = Wrap(psi - kPi / 2.0 - gamma);
  // The wrist: Rx(q4) Ry(q5) Rx(q6) = R3^T R6.
  const Eigen::Matrix3d r6 = base_from_flange.linear() * LinkToTool0().transpose();
  const Eigen::Matrix3d m = (Rz(q[0]) * Ry(q[1] + q[2])).transpose() * r6;
  const double s5 = std::hypot(m(1, 0), m(2, 0));
  if (s5 < 1e-12) {  // joint 5 at 0: only q4 + q6 is defined
    q[3] = 0.0;
    q[4] = 0.0;
    q[5] = std::atan2(m(2, 1), m(1, 1));
  } else {
    q[3] = std::atan2(m(1, 0), -m(2, 0));
    q[4] = std::atan2(s5, m(0, 0));
    q[5] = std::atan2(m(0, 1), m(0, 2));
  }
  if (branch.negative_joint5) {
    q[3] = Wrap(q[3] + kPi);
    q[4] = -q[4];
    q[5] = Wrap(q[5] + kPi);
  }
  return q;
}

}  // namespace arcwheel::polishing
