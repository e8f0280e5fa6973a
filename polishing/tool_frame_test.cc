#include "polishing/tool_frame.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

namespace arcwheel::polishing {
namespace {

// The paper's eqs. 9-10, written out as printed (method.md B): defined only where every
// square-root argument is clearly positive and every sign() argument clearly non-zero.
AbbQuaternion PaperQuaternion(const Eigen::Matrix3d& r) {
  const double x1 = r(0, 0), x2 = r(1, 0), x3 = r(2, 0);
  const double y1 = r(0, 1), y2 = r(1, 1), y3 = r(2, 1);
  const double z1 = r(0, 2), z2 = r(1, 2), z3 = r(2, 2);
  auto sign = [](double v) { return v > 0.0 ? 1.0 : (v < 0.0 ? -1.0 : 0.0); };
  return {std::sqrt(x1 + y2 + z3 + 1.0) / 2.0, std::sqrt(x1 - y2 - z3 + 1.0) / 2.0 * sign(y3 - z2),
          std::sqrt(y2 - x1 - z3 + 1.0) / 2.0 * sign(z1 - x3),
          std::sqrt(z3 - x1 - y2 + 1.0) / 2.0 * sign(x2 - y1)};
}

double MinAbsComponent(const AbbQuaternion& q) {
  return std::min({std::abs(q.q1), std::abs(q.q2), std::abs(q.q3), std::abs(q.q4)});
}

surfaces::EvenAsphere Asphere(bool concave, double off_axis_x_mm) {
  return surfaces::EvenAsphere({.vertex_radius_mm = 800.0,
                                .conic = -0.6,
                                .even_coefficients = {1e-11},
                                .off_axis_x_mm = off_axis_x_mm,
                                .off_axis_y_mm = 0.0,
                                .concave = concave});
}

TEST(AbbQuaternion, RoundTripsRandomRotationsWithin1e12) {
  std::mt19937 rng(20261123);
  std::normal_distribution<double> normal;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Quaterniond q =
        Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng)).normalized();
    const Eigen::Matrix3d r = q.toRotationMatrix();
    const AbbQuaternion abb = AbbQuaternionFromRotation(r);
    EXPECT_NEAR(abb.q1 * abb.q1 + abb.q2 * abb.q2 + abb.q3 * abb.q3 + abb.q4 * abb.q4, 1.0, 1e-14);
    EXPECT_LT((RotationFromAbbQuaternion(abb) - r).cwiseAbs().maxCoeff(), 1e-12) << i;
  }
}

TEST(AbbQuaternion, AgreesWithThePaperFormulaAwayFromItsSingularCases) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  int compared = 0;
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Matrix3d r = Eigen::Quaterniond(normal(rng), normal(rng), normal(rng), normal(rng))
                                  .normalized()
                                  .toRotationMatrix();
    const AbbQuaternion paper = PaperQuaternion(r);
    if (MinAbsComponent(paper) < 0.05) continue;  // a component near zero: the paper's form fails
    const AbbQuaternion ours = AbbQuaternionFromRotation(r);
    EXPECT_NEAR(ours.q1, paper.q1, 1e-12);
    EXPECT_NEAR(ours.q2, paper.q2, 1e-12);
    EXPECT_NEAR(ours.q3, paper.q3, 1e-12);
    EXPECT_NEAR(ours.q4, paper.q4, 1e-12);
    ++compared;
  }
  EXPECT_GT(compared, 1000);
}

TEST(AbbQuaternion, ToolDownAtTheVertexIsAHalfTurnWhereThePaperGivesZero) {
  const Eigen::Matrix3d frame = ToolFrameFromSlopes(0.0, 0.0, RobotSide::kPlusX);
  const AbbQuaternion paper = PaperQuaternion(frame);
  EXPECT_EQ(paper.q1, 0.0);
  EXPECT_EQ(paper.q2, 0.0);
  EXPECT_EQ(paper.q3, 0.0);
  EXPECT_EQ(paper.q4, 0.0);
  const AbbQuaternion ours = AbbQuaternionFromRotation(frame);
  EXPECT_NEAR(ours.q1, 0.0, 1e-15);
  EXPECT_NEAR(ours.q2, 1.0, 1e-15);  // half turn about x: tool z down, tool y along -y
  EXPECT_NEAR(ours.q3, 0.0, 1e-15);
  EXPECT_NEAR(ours.q4, 0.0, 1e-15);
  EXPECT_LT((RotationFromAbbQuaternion(ours) - frame).cwiseAbs().maxCoeff(), 1e-15);
}

TEST(ToolFrame, ZIsTheInwardNormalAndXLiesInTheXzPlaneAlongPaths) {
  for (const bool concave : {true, false}) {
    for (const RobotSide side : {RobotSide::kPlusX, RobotSide::kMinusX}) {
      const surfaces::EvenAsphere surface = Asphere(concave, 150.0);
      for (int k = 0; k <= 200; ++k) {
        // A spiral-like path crossing the aperture, off the y = 0 line too.
        const double t = k / 200.0;
        const double x = 120.0 * std::cos(9.0 * t) * t, y = 120.0 * std::sin(9.0 * t) * t;
        const Eigen::Matrix3d frame = ToolFrameAt(surface, x, y, side);
        // Independent normal: central differences of the height, part below the surface.
        const double h = 1e-4;
        const double fx = (surface.Evaluate(x + h, y).z_mm - surface.Evaluate(x - h, y).z_mm) / (2 * h);
        const double fy = (surface.Evaluate(x, y + h).z_mm - surface.Evaluate(x, y - h).z_mm) / (2 * h);
        const Eigen::Vector3d up = Eigen::Vector3d(-fx, -fy, 1.0).normalized();
        EXPECT_LT((frame.col(2) + up).norm(), 1e-8) << "concave " << concave << " k " << k;
        EXPECT_EQ(frame.col(0).y(), 0.0);
        EXPECT_GT(side == RobotSide::kPlusX ? frame.col(0).x() : -frame.col(0).x(), 0.0);
        EXPECT_LT((frame.transpose() * frame - Eigen::Matrix3d::Identity()).norm(), 1e-14);
        EXPECT_NEAR(frame.determinant(), 1.0, 1e-14);
        const AbbQuaternion q = AbbQuaternionFromRotation(frame);
        EXPECT_LT((RotationFromAbbQuaternion(q) - frame).cwiseAbs().maxCoeff(), 1e-12);
      }
    }
  }
}

}  // namespace
}  // namespace arcwheel::polishing
