#pragma once
// Tool frames and robot quaternions for polishing along a surface (method.md B, eqs. 2-10).
//
// The surface is a surfaces::Surface, z = f(x, y) in the part frame with the part below it
// (surfaces/surface.h). As an implicit surface F = f(x, y) - z = 0, so F_x = f_x, F_y = f_y, F_z = -1.
//  - tool z (eq. 3): the tool axis, pointing into the part: (f_x, f_y, -1) / sqrt(f_x^2 + f_y^2 + 1),
//    the opposite of the upward (outward) normal, for concave and convex parts alike;
//  - tool x (eq. 4): in the reference plane y = 0, perpendicular to tool z: (1, 0, -F_x / F_z) =
//    (1, 0, f_x) normalised, with its sign chosen towards the robot (+x or -x of the part frame);
//  - tool y (eq. 5): z cross x.
// The frame is returned as a rotation matrix whose columns are the tool axes in the part frame
// (part_from_tool), so p_in_part = R p_in_tool.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "surfaces/surface.h"

namespace arcwheel::polishing {

// Which side of the part the robot base stands on, along the part frame's x axis.
enum class RobotSide { kPlusX, kMinusX };

// Tool frame from the surface slopes at a point (f_x = dz/dx, f_y = dz/dy). Columns: x, y, z axes.
[[nodiscard]] Eigen::Matrix3d ToolFrameFromSlopes(double fx, double fy, RobotSide side);

// Tool frame at (x, y) of the surface. Precondition: surface.InDomain(x, y).
[[nodiscard]] Eigen::Matrix3d ToolFrameAt(const surfaces::Surface& surface, double x_mm, double y_mm,
                                          RobotSide side);

// A unit quaternion in ABB order: q1 scalar, then q2, q3, q4 (i, j, k). Note that Eigen stores
// (x, y, z, w); this type is never an Eigen::Quaterniond in disguise.
struct AbbQuaternion {
  double q1 = 1.0;
  double q2 = 0.0;
  double q3 = 0.0;
  double q4 = 0.0;
};

// Rotation matrix -> unit quaternion, robust everywhere (largest-diagonal / Shepperd, via Eigen),
// with the sign chosen so that the first non-zero of (q1, q2, q3, q4) is positive: the paper's
// formula (eqs. 9-10) always has q1 >= 0 and agrees with this wherever it is well defined.
// Precondition: `rotation` is orthonormal with determinant +1.
[[nodiscard]] AbbQuaternion AbbQuaternionFromRotation(const Eigen::Matrix3d& rotation);

// Unit quaternion (ABB order) -> rotation matrix.
[[nodiscard]] Eigen::Matrix3d RotationFromAbbQuaternion(const AbbQuaternion& q);

}  // namespace arcwheel::polishing
