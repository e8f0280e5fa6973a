#include "polishing/precession.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::polishing {
namespace {

using arcwheel::testing::ErrorMessageOf;
using arcwheel::testing::ErrorOf;
using ::testing::HasSubstr;

TEST(PrecessionTrajectory, StraightFeedOnAPlaneTracesTheProlateCycloidOfMethodC) {
  // method.md C: theta = 20 deg, v = 5 mm/s, w2 = 5 r/min, the point 127 mm up the axis.
  const surfaces::XyPolynomial plane({});
  const std::vector<Eigen::Vector2d> path = {{0.0, 0.0}, {60.0, 0.0}};
  const PrecessionOptions options{.tilt_deg = 20.0,
                                  .precession_rate_rpm = 5.0,
                                  .feed_mm_per_s = 5.0,
                                  .bonnet_radius_mm = 40.0,
                                  .arm_length_mm = 127.0,
                                  .time_step_s = 0.1};
  const auto samples = PrecessionTrajectory(plane, path, options);
  ASSERT_EQ(samples.size(), 121u);  // 12 s of feed at 0.1 s
  // Closed form: feed along x, normal +z, so a = x, b = y, c = z and the traced point is
  // (v t + L sin(theta) cos(w2 t), L sin(theta) sin(w2 t), R + L cos(theta)).
  const double theta = 20.0 * std::numbers::pi / 180.0;
  const double w2 = 5.0 * 2.0 * std::numbers::pi / 60.0;
  for (const PrecessionSample& s : samples) {
    const double t = s.time_s;
    const Eigen::Vector3d expected(5.0 * t + 127.0 * std::sin(theta) * std::cos(w2 * t),
                                   127.0 * std::sin(theta) * std::sin(w2 * t),
                                   40.0 + 127.0 * std::cos(theta));
    EXPECT_LT((s.traced_mm - expected).norm(), 1e-9) << "t = " << t;
  }
  // Prolate: the loop speed L sin(theta) w2 (22.7 mm/s) exceeds the feed, so the traced point
  // moves backwards in x over part of each turn.
  bool moves_back = false;
  for (std::size_t i = 1; i < samples.size(); ++i) {
    moves_back = moves_back || samples[i].traced_mm.x() < samples[i - 1].traced_mm.x();
  }
  EXPECT_TRUE(moves_back);
}

TEST(PrecessionTrajectory, AxisKeepsTheTiltFromTheNormalOnACurvedSurface) {
  const surfaces::EvenAsphere sphere({.vertex_radius_mm = 300.0, .concave = false});
  const std::vector<Eigen::Vector2d> path = {{-80.0, -20.0}, {0.0, 10.0}, {70.0, 40.0}};
  const PrecessionOptions options{
      .tilt_deg = 25.0, .precession_rate_rpm = 30.0, .feed_mm_per_s = 10.0, .time_step_s = 0.05};
  const double theta = 25.0 * std::numbers::pi / 180.0;
  const double w2 = 30.0 * 2.0 * std::numbers::pi / 60.0;
  for (const PrecessionSample& s : PrecessionTrajectory(sphere, path, options)) {
    // Independent normal of a convex sphere of radius 300 whose vertex is at the origin.
    const Eigen::Vector3d normal = (s.contact_mm - Eigen::Vector3d(0.0, 0.0, -300.0)).normalized();
    EXPECT_NEAR(std::acos(std::clamp(s.axis.dot(normal), -1.0, 1.0)), theta, 1e-9);
    const Eigen::Vector3d a = s.local_frame.col(0);
    EXPECT_NEAR(a.dot(normal), 0.0, 1e-12);
    // The precession angle measured from the feed direction is w2 t.
    const Eigen::Vector3d tangential = s.axis - s.axis.dot(normal) * normal;
    const double alpha = std::atan2(tangential.dot(normal.cross(a)), tangential.dot(a));
    EXPECT_NEAR(std::remainder(alpha - w2 * s.time_s, 2.0 * std::numbers::pi), 0.0, 1e-9);
  }
}

TEST(PrecessionTrajectory, RefusesATiltOf90DegreesAndAPathOffTheSurface) {
  const surfaces::EvenAsphere sphere({.vertex_radius_mm = 50.0});
  const std::vector<Eigen::Vector2d> path = {{0.0, 0.0}, {60.0, 0.0}};
  EXPECT_THROW((void)PrecessionTrajectory(sphere, path, {.tilt_deg = 90.0}), Error);
  EXPECT_THAT(ErrorOf([&] { (void)PrecessionTrajectory(sphere, path, {}); }).what(),
              HasSubstr("path point 1 (60, 0) mm is off the surface"));
}

TEST(PrecessionOptions, EveryProblemIsReportedInOneErrorWithItsValue) {
  const surfaces::EvenAsphere sphere({.vertex_radius_mm = 50.0});
  const std::vector<Eigen::Vector2d> path = {{0.0, 0.0}, {1.0, 0.0}};
  EXPECT_EQ(ErrorMessageOf(
                [&] { (void)PrecessionTrajectory(sphere, path, {.tilt_deg = 95.0, .time_step_s = 0.0}); },
                ErrorCode::kInvalidOption),
            "polishing.precession: PrecessionOptions::tilt_deg = 95 violates [0, 90); "
            "PrecessionOptions::time_step_s "
            "= 0 violates > 0");
}

}  // namespace
}  // namespace arcwheel::polishing
