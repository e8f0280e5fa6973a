#include "frames/transform.h"

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <string>

#include "core/error.h"

namespace arcwheel::frames {
namespace {

constexpr std::array<std::pair<TransformModel, std::string_view>, 4> kModelNames = {{
    {TransformModel::kRigid3d, "rigid3d"},
    {TransformModel::kSimilarity3d, "similarity3d"},
    {TransformModel::kRigid2d, "rigid2d"},
    {TransformModel::kAffine2d, "affine2d"},
}};

}  // namespace

std::string_view ModelName(TransformModel model) {
  for (const auto& [value, name] : kModelNames) {
    if (value == model) return name;
  }
  return "unknown";
}

TransformModel ParseModel(std::string_view name) {
  for (const auto& [value, known] : kModelNames) {
    if (known == name) return value;
  }
  throw Error(
      ErrorCode::kInvalidOption, "frames.transform",
      "unknown model '" + std::string(name) + "' (expected rigid3d, similarity3d, rigid2d or affine2d)");
}

int ModelDimension(TransformModel model) {
  return model == TransformModel::kRigid2d || model == TransformModel::kAffine2d ? 2 : 3;
}

int ModelParameterCount(TransformModel model) {
  switch (model) {
    case TransformModel::kRigid3d:
      return 6;
    case TransformModel::kSimilarity3d:
      return 7;
    case TransformModel::kRigid2d:
      return 3;
    case TransformModel::kAffine2d:
      return 6;
  }
  return 0;
}

Eigen::Vector3d Transform::ApplyToPoint(const Eigen::Vector3d& p_mm) const {
  return scale * (linear * p_mm) + translation_mm;
}

Eigen::Vector3d Transform::ApplyToDirection(const Eigen::Vector3d& direction) const {
  const Eigen::Vector3d mapped = model == TransformModel::kAffine2d
                                     ? Eigen::Vector3d(linear.inverse().transpose() * direction)
                                     : Eigen::Vector3d(linear * direction);
  const double norm = mapped.norm();
  return norm > 0.0 ? Eigen::Vector3d(mapped / norm) : mapped;
}

Transform Transform::Inverse() const {
  const double determinant = linear.determinant() * scale;
  if (!(std::abs(determinant) > 1e-300) || !std::isfinite(determinant)) {
    throw Error(ErrorCode::kBadInput, "frames.transform", "the transform is singular and has no inverse");
  }
  Transform inverse = *this;
  inverse.linear = model == TransformModel::kAffine2d ? Eigen::Matrix3d(linear.inverse())
                                                      : Eigen::Matrix3d(linear.transpose());
  inverse.scale = 1.0 / scale;
  inverse.translation_mm = -inverse.scale * (inverse.linear * translation_mm);
  return inverse;
}

Eigen::Matrix3d RotationFromAngles(const Eigen::Vector3d& angles_rad) {
  return (Eigen::AngleAxisd(angles_rad.z(), Eigen::Vector3d::UnitZ()) *
          Eigen::AngleAxisd(angles_rad.y(), Eigen::Vector3d::UnitY()) *
          Eigen::AngleAxisd(angles_rad.x(), Eigen::Vector3d::UnitX()))
      .toRotationMatrix();
}

Eigen::Vector3d AnglesFromRotation(const Eigen::Matrix3d& r) {
  // R = Rz Ry Rx: r(2,0) = -sin(ry); away from gimbal lock rx and rz follow from the last row and
  // first column. atan2 of the cosine-scaled entries keeps full accuracy near ry = 0.
  const double ry = std::atan2(-r(2, 0), std::hypot(r(0, 0), r(1, 0)));
  if (std::hypot(r(0, 0), r(1, 0)) < 1e-12) {  // gimbal lock: only rx - rz (or rx + rz) is defined
    return {std::atan2(-r(1, 2), r(1, 1)), ry, 0.0};
  }
  return {std::atan2(r(2, 1), r(2, 2)), ry, std::atan2(r(1, 0), r(0, 0))};
}

Eigen::Vector3d CoordinateFrameAngles(const Eigen::Matrix3d& rotation) {
  return AnglesFromRotation(rotation.transpose());
}

}  // namespace arcwheel::frames
