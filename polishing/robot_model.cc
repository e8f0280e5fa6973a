#include "polishing/robot_model.h"

#include <fmt/core.h>

#include <cmath>

// The URDF files of polishing/robots/, embedded by arcwheel_embed_text (polishing/CMakeLists.txt).
extern const char kAbbIrb4600_40_255Urdf[];

namespace arcwheel::polishing {

const std::vector<RobotModel>& RobotModels() {
  // ABB, Product specification IRB 4600 (3HAC032885-001), figures "Dimensions" (IRB 4600-40/2.55)
  // and tables "Axis working range" and "Maximum axis speed"; docs/polishing.md, "Robot".
  static const std::vector<RobotModel> models = {
      {.name = "ABB IRB 4600-40/2.55",
       .urdf = kAbbIrb4600_40_255Urdf,
       .citation = "ABB Product specification IRB 4600, 3HAC032885-001",
       .geometry = {.a1_mm = 175.0,
                    .a2_mm = -175.0,
                    .c1_mm = 495.0,
                    .c2_mm = 1095.0,
                    .c3_mm = 1270.0,
                    .c4_mm = 135.0}},
  };
  return models;
}

const RobotModel* FindRobotModel(std::string_view name) {
  for (const RobotModel& m : RobotModels()) {
    if (m.name == name) return &m;
  }
  return nullptr;
}

std::vector<std::string> RobotMargins::Problems() const {
  std::vector<std::string> problems;
  if (!(min_joint_margin_deg >= 0.0 && min_joint_margin_deg < 90.0)) {
    problems.push_back(
        fmt::format("robot.min_joint_margin_deg = {} violates 0 <= value < 90", min_joint_margin_deg));
  }
  if (!(min_wrist_margin_deg >= 0.0 && min_wrist_margin_deg < 90.0)) {
    problems.push_back(
        fmt::format("robot.min_wrist_margin_deg = {} violates 0 <= value < 90", min_wrist_margin_deg));
  }
  if (!(max_added_residual_nm >= 0.0 && std::isfinite(max_added_residual_nm))) {
    problems.push_back(fmt::format("robot.max_added_residual_nm = {} violates >= 0", max_added_residual_nm));
  }
  if (!(max_joint_speed_ratio > 0.0 && max_joint_speed_ratio <= 1.0)) {
    problems.push_back(
        fmt::format("robot.max_joint_speed_ratio = {} violates 0 < value <= 1", max_joint_speed_ratio));
  }
  return problems;
}

std::optional<std::string> RigidTransformProblem(const Eigen::Matrix4d& m) {
  if (!m.allFinite()) return "has a value that is not finite";
  if ((m.row(3) - Eigen::RowVector4d(0, 0, 0, 1)).cwiseAbs().maxCoeff() > 1e-12)
    return fmt::format("has last row [{}, {}, {}, {}], not [0, 0, 0, 1]", m(3, 0), m(3, 1), m(3, 2), m(3, 3));
  const Eigen::Matrix3d r = m.topLeftCorner<3, 3>();
  const double off = (r.transpose() * r - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (off > 1e-9) return fmt::format("is not a rotation: R^T R differs from I by {:.3g}", off);
  const double det = r.determinant();
  if (det < 0.0) return fmt::format("is a reflection (determinant {:.6g}), not a rotation", det);
  return std::nullopt;
}

}  // namespace arcwheel::polishing
