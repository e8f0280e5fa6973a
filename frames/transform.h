#pragma once
// Transforms between machine, workpiece and sensor frames, in the position-vector convention:
//
//   p_in_target = scale * linear * p_in_source + translation_mm
//
// `linear` is a rotation (rigid and similarity models, det = +1) or a general 2x2 matrix (affine2d).
// Planar models (rigid2d, affine2d) act on x and y only: their `linear` has the 2x2 block top-left,
// 1 at (2,2), and z passes through unchanged.
//
// Rotation angles, where reported, follow one stated order: R = Rz(rz) * Ry(ry) * Rx(rx) (rotations
// about the fixed axes x, then y, then z; right-handed, positive counter-clockwise looking down the
// axis). Geodesy's 7-parameter Helmert transform has two sign conventions: position-vector (the
// angles above, rotating the point) and coordinate-frame (rotating the axes: R = [Rz Ry Rx]^T with
// the coordinate-frame angles; for small angles their signs are the opposite of position-vector).

#include <Eigen/Core>
#include <string>
#include <string_view>

namespace arcwheel::frames {

enum class TransformModel { kRigid3d, kSimilarity3d, kRigid2d, kAffine2d };

// "rigid3d", "similarity3d", "rigid2d", "affine2d" (formats.md section 5).
[[nodiscard]] std::string_view ModelName(TransformModel model);
// Inverse of ModelName. Throws Error{kInvalidOption} naming the value and the accepted names.
[[nodiscard]] TransformModel ParseModel(std::string_view name);
// 2 for the planar models, 3 otherwise.
[[nodiscard]] int ModelDimension(TransformModel model);
// Number of free parameters: 6, 7, 3, 6.
[[nodiscard]] int ModelParameterCount(TransformModel model);

struct Transform {
  TransformModel model = TransformModel::kRigid3d;
  Eigen::Matrix3d linear = Eigen::Matrix3d::Identity();
  double scale = 1.0;
  Eigen::Vector3d translation_mm = Eigen::Vector3d::Zero();

  // scale * linear * p + translation.
  [[nodiscard]] Eigen::Vector3d ApplyToPoint(const Eigen::Vector3d& p_mm) const;
  // A unit surface normal or direction: rotated, never translated; for affine2d the
  // inverse-transpose is used so that normals stay normal, and the result is renormalised.
  [[nodiscard]] Eigen::Vector3d ApplyToDirection(const Eigen::Vector3d& direction) const;
  // The transform from target back to source. Throws Error{kBadInput} if `linear` is singular.
  [[nodiscard]] Transform Inverse() const;
};

// Angles (rx, ry, rz) in radians with R = Rz(rz) Ry(ry) Rx(rx); ry in [-pi/2, pi/2].
[[nodiscard]] Eigen::Vector3d AnglesFromRotation(const Eigen::Matrix3d& rotation);
[[nodiscard]] Eigen::Matrix3d RotationFromAngles(const Eigen::Vector3d& angles_rad);
// Coordinate-frame Helmert angles of the same rotation: the angles of R^T.
[[nodiscard]] Eigen::Vector3d CoordinateFrameAngles(const Eigen::Matrix3d& rotation);

}  // namespace arcwheel::frames
