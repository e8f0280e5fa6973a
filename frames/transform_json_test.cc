#include "frames/transform_json.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include "core/error.h"

namespace arcwheel::frames {
namespace {

TEST(TransformJson, RoundTripsEveryModelAndItsInverse) {
  Transform similarity{TransformModel::kSimilarity3d,
                       Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 1, 0).normalized()).toRotationMatrix(),
                       1.00003, Eigen::Vector3d(5, -6, 7)};
  Transform rigid2d{TransformModel::kRigid2d, Eigen::Matrix3d::Identity(), 1.0, Eigen::Vector3d(1, 2, 0)};
  rigid2d.linear.topLeftCorner<2, 2>() = Eigen::Rotation2Dd(-0.4).toRotationMatrix();
  Transform affine{TransformModel::kAffine2d, Eigen::Matrix3d::Identity(), 1.0, Eigen::Vector3d(3, 4, 0)};
  affine.linear.topLeftCorner<2, 2>() << 1.1, 0.2, -0.1, 0.9;
  for (const Transform& t : {similarity, rigid2d, affine}) {
    const nlohmann::json json = TransformToJson(t);
    EXPECT_EQ(json["convention"], kConvention);
    const Transform back = TransformFromJson(nlohmann::json::parse(json.dump()), "t.json");
    EXPECT_EQ(back.model, t.model);
    EXPECT_TRUE(back.linear.isApprox(t.linear, 1e-15));
    EXPECT_DOUBLE_EQ(back.scale, t.scale);
    EXPECT_TRUE(back.translation_mm.isApprox(t.translation_mm, 1e-15));
    const Transform inverse = TransformFromJson(json["inverse"], "t.json");
    const Eigen::Vector3d p(10, 20, 0);
    EXPECT_TRUE(inverse.ApplyToPoint(t.ApplyToPoint(p)).isApprox(p, 1e-13));
  }
}

TEST(TransformJson, RefusesMissingOrMalformedKeys) {
  const auto expect_refusal = [](const std::string& text, const std::string& words) {
    try {
      (void)TransformFromJson(nlohmann::json::parse(text), "t.json");
      ADD_FAILURE() << text;
    } catch (const Error& error) {
      EXPECT_EQ(error.code(), ErrorCode::kBadInput);
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
  };
  expect_refusal(R"({"rotation_matrix": [[1,0,0],[0,1,0],[0,0,1]], "translation": [0,0,0]})", "key 'model'");
  expect_refusal(
      R"({"model": "rigid3d", "rotation_matrix": [[1,0,0],[0,1,0],[0,0,2]], "translation": [0,0,0]})",
      "is not a rotation");
  expect_refusal(
      R"({"model": "rigid3d", "rotation_matrix": [[1,0,0],[0,1,0],[0,0,-1]], "translation": [0,0,0]})",
      "is not a rotation");
  expect_refusal(
      R"({"model": "rigid3d", "rotation_matrix": [[1,0,0],[0,1,0],[0,0,1]], "translation": [0,0]})",
      "must hold 3 numbers");
  expect_refusal(R"({"model": "affine2d", "matrix": [[1,2],[2,4]], "translation": [0,0]})", "is singular");
  expect_refusal(R"({"model": "helmert", "translation": [0,0]})", "unknown model");
}

}  // namespace
}  // namespace arcwheel::frames
