#include "polishing/tool_frame.h"

#include <cmath>

#include "core/check.h"

namespace arcwheel::polishing {

Eigen::Matrix3d ToolFrameFromSlopes(double fx, double fy, RobotSide side) {
  const Eigen::Vector3d z_axis = Eigen::Vector3d(fx, fy, -1.0).normalized();
  const double sign = side == RobotSide::kPlusX ? 1.0 : -1.0;
  const Eigen::Vector3d x_axis = (sign * Eigen::Vector3d(1.0, 0.0, fx)).normalized();
  Eigen::Matrix3d frame;
  frame.col(0) = x_axis;
  frame.col(1) = z_axis.cross(x_axis);
  frame.col(2) = z_axis;
  return frame;
}

Eigen::Matrix3d ToolFrameAt(const surfaces::Surface& surface, double x_mm, double y_mm, RobotSide side) {
  ARCWHEEL_CHECK(surface.InDomain(x_mm, y_mm)) << "(" << x_mm << ", " << y_mm << ")";
  const surfaces::SurfacePoint p = surface.Evaluate(x_mm, y_mm);
  return ToolFrameFromSlopes(p.fx, p.fy, side);
}

AbbQuaternion AbbQuaternionFromRotation(const Eigen::Matrix3d& rotation) {
  // Eigen's conversion picks the largest of the trace and the diagonal (Shepperd 1978), so no
  // component is ever found by a square root of a small difference.
  Eigen::Quaterniond q(rotation);
  q.normalize();
  AbbQuaternion out{q.w(), q.x(), q.y(), q.z()};
  const double components[4] = {out.q1, out.q2, out.q3, out.q4};
  for (const double c : components) {
    if (c == 0.0) continue;
    if (c < 0.0) out = {-out.q1, -out.q2, -out.q3, -out.q4};
    break;
  }
  // -0.0 + 0.0 is +0.0: no "-0" in the robot program.
  out = {out.q1 + 0.0, out.q2 + 0.0, out.q3 + 0.0, out.q4 + 0.0};
  return out;
}

Eigen::Matrix3d RotationFromAbbQuaternion(const AbbQuaternion& q) {
  return Eigen::Quaterniond(q.q1, q.q2, q.q3, q.q4).normalized().toRotationMatrix();
}

}  // namespace arcwheel::polishing
