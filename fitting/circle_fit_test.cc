#include "fitting/circle_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

namespace arcwheel::fitting {
namespace {

struct ArcSpec {
  double center_x = 0, center_y = 0, radius = 55.0, arc_deg = 10.0, error_um = 1.0;
  int count = 100;
};

// Points whose radial errors are orthogonal to (1, cos t, sin t): the geometric least-squares
// circle is exactly (center, radius) by construction (the residuals are the errors and are
// orthogonal to the Jacobian's columns).
void ExactArc(const ArcSpec& spec, std::vector<double>& x, std::vector<double>& y) {
  const int n = spec.count;
  std::mt19937 rng(20240611);
  std::normal_distribution<double> normal(0.0, spec.error_um * 1e-3);
  Eigen::MatrixXd basis(n, 3);
  Eigen::VectorXd e(n), t(n);
  for (int i = 0; i < n; ++i) {
    t(i) = (-0.5 + static_cast<double>(i) / std::max(1, n - 1)) * spec.arc_deg * std::numbers::pi / 180.0;
    basis(i, 0) = 1.0;
    basis(i, 1) = std::cos(t(i));
    basis(i, 2) = std::sin(t(i));
    e(i) = n > 3 ? normal(rng) : 0.0;
  }
  const Eigen::MatrixXd q = basis.householderQr().householderQ() * Eigen::MatrixXd::Identity(n, 3);
  e -= q * (q.transpose() * e);
  x.resize(static_cast<std::size_t>(n));
  y.resize(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) {
    x[static_cast<std::size_t>(i)] = spec.center_x + (spec.radius + e(i)) * std::cos(t(i));
    y[static_cast<std::size_t>(i)] = spec.center_y + (spec.radius + e(i)) * std::sin(t(i));
  }
}

class HardArc : public ::testing::TestWithParam<int> {};

TEST_P(HardArc, TenDegreeArcFarFromTheOriginGivesTheExactCircle) {
  std::vector<double> x, y;
  ExactArc({.center_x = 1e5, .center_y = 1e5, .radius = 55.0, .arc_deg = 10.0, .count = GetParam()}, x, y);
  const CircleFit fit = FitCircle(x, y, {}, {});
  ASSERT_TRUE(fit.IsUsable()) << fit.message;
  // Input rounding at 1e5 mm is ~1.5e-11 mm; a 10 deg arc amplifies it ~1e3 times.
  EXPECT_NEAR(fit.radius_mm, 55.0, 2e-8);
  EXPECT_NEAR(fit.center_mm.x(), 1e5, 2e-8);
  EXPECT_NEAR(fit.center_mm.y(), 1e5, 2e-8);
}

INSTANTIATE_TEST_SUITE_P(FiveToAHundredThousandPoints, HardArc, ::testing::Values(5, 6, 50, 1000, 100000));

TEST(FitCircle, TwentyMillimetreChordOnTheWheelsArc) {
  // A 20 mm chord on a 55 mm radius spans 2 asin(10/55) = 20.95 deg.
  std::vector<double> x, y;
  ExactArc({.center_x = -3.0,
            .center_y = -199.5,
            .radius = 55.4423,
            .arc_deg = 2.0 * std::asin(10.0 / 55.4423) * 180.0 / std::numbers::pi,
            .count = 81},
           x, y);
  const CircleFit fit = FitCircle(x, y, {}, {});
  ASSERT_TRUE(fit.IsUsable());
  EXPECT_NEAR(fit.radius_mm, 55.4423, 1e-11);
  EXPECT_NEAR(fit.center_mm.x(), -3.0, 1e-11);
  EXPECT_NEAR(fit.center_mm.y(), -199.5, 1e-11);
}

// Phases of the wheel map: 600 points over a 16 mm band of a 55 mm arc with 0.3 um errors, whose
// least-squares circle is exact by construction. |p_i - c| - r cancels about five digits there, so
// near the minimum the cost cannot tell apart circles 1e-5 sigma apart, and where the damped
// steps stop depends on rounding; the fit must still find the minimum, to 1e-6 of its sigma.
TEST(FitCircle, ShortNoisyArcsGiveTheExactCircleToAMillionthOfTheirSigma) {
  for (int k = 0; k < 20; ++k) {
    SCOPED_TRACE(k);
    const double center_x = 0.4 + 0.01 * k;
    const double radius = 55.0 + 0.001 * k;
    std::vector<double> x, y;
    ExactArc({.center_x = center_x,
              .center_y = -radius,
              .radius = radius,
              .arc_deg = 2.0 * std::asin(8.0 / radius) * 180.0 / std::numbers::pi,
              .error_um = 0.3,
              .count = 600 + k},
             x, y);
    const CircleFit fit = FitCircle(x, y, {}, {});
    ASSERT_TRUE(fit.IsUsable()) << fit.message;
    EXPECT_NEAR(fit.radius_mm, radius, 1e-6 * fit.radius_sigma_mm());
    EXPECT_NEAR(fit.center_mm.x(), center_x, 1e-6 * std::sqrt(fit.covariance(0, 0)));
    EXPECT_NEAR(fit.center_mm.y(), -radius, 1e-6 * std::sqrt(fit.covariance(1, 1)));
  }
}

TEST(FitCircle, RadiusSigmaMatchesTheScatterOverManyNoisyArcs) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 1e-3);
  std::vector<double> radii, sigmas;
  for (int trial = 0; trial < 400; ++trial) {
    std::vector<double> x, y;
    for (int i = 0; i < 60; ++i) {
      const double t = (-10.0 + 20.0 * i / 59.0) * std::numbers::pi / 180.0;
      const double r = 55.0 + noise(rng);
      x.push_back(r * std::sin(t));
      y.push_back(r * std::cos(t));
    }
    const CircleFit fit = FitCircle(x, y, {}, {});
    radii.push_back(fit.radius_mm);
    sigmas.push_back(fit.radius_sigma_mm());
  }
  double mean = 0, var = 0, mean_sigma = 0;
  const auto trials = static_cast<double>(radii.size());
  for (std::size_t i = 0; i < radii.size(); ++i) {
    mean += radii[i] / trials;
    mean_sigma += sigmas[i] / trials;
  }
  for (const double r : radii) var += (r - mean) * (r - mean) / (trials - 1.0);
  // The scatter's own sampling error over 400 trials is ~3.5 %.
  EXPECT_NEAR(std::sqrt(var) / mean_sigma, 1.0, 0.12);
}

// The covariance is the textbook s^2 (J^T J)^-1, with J the Jacobian of the geometric residuals
// d_i - r in mm at the fitted circle and s^2 = RSS / (n - 3), formed here independently.
TEST(FitCircle, CovarianceIsTheResidualVarianceTimesTheInverseNormalMatrix) {
  std::mt19937 rng(11);
  std::normal_distribution<double> noise(0.0, 1e-3);
  std::vector<double> x, y;
  for (int i = 0; i < 40; ++i) {
    const double t = (-12.0 + 24.0 * i / 39.0) * std::numbers::pi / 180.0;
    x.push_back(-3.0 + (55.4 + noise(rng)) * std::sin(t));
    y.push_back(-199.5 + (55.4 + noise(rng)) * std::cos(t));
  }
  const CircleFit fit = FitCircle(x, y, {}, {});
  ASSERT_TRUE(fit.IsUsable()) << fit.message;
  Eigen::MatrixXd jacobian(40, 3);
  double rss = 0.0;
  for (int i = 0; i < 40; ++i) {
    const double dx = x[static_cast<std::size_t>(i)] - fit.center_mm.x();
    const double dy = y[static_cast<std::size_t>(i)] - fit.center_mm.y();
    const double d = std::sqrt(dx * dx + dy * dy);
    jacobian.row(i) << -dx / d, -dy / d, -1.0;
    rss += (d - fit.radius_mm) * (d - fit.radius_mm);
  }
  const Eigen::Matrix3d expected = rss / 37.0 * (jacobian.transpose() * jacobian).inverse();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(fit.covariance(r, c), expected(r, c), 1e-7 * std::abs(expected(r, c)) + 1e-20) << r << c;
    }
  }
}

// The reciprocal condition number (s_min / s_max)^2 of the Jacobian of 21 points on an arc grows as
// the arc's angle^4: for a 0.1 deg arc it is 3.9e-15 (as Ceres' covariance reports it), below the
// 1e-14 under which the fit refuses; for a 1 deg arc it is 3.9e-11.
TEST(FitCircle, RefusesAnArcTooShortToDetermineTheCircle) {
  const auto arc = [](double arc_deg) {
    std::vector<double> x, y;
    for (int i = 0; i <= 20; ++i) {
      const double t = (-0.5 + i / 20.0) * arc_deg * std::numbers::pi / 180.0;
      x.push_back(55.0 * std::sin(t));
      y.push_back(55.0 * std::cos(t));
    }
    return FitCircle(x, y, {}, {});
  };
  const CircleFit too_short = arc(0.1);
  EXPECT_EQ(too_short.status, FitStatus::kDegenerate);
  EXPECT_EQ(too_short.message, "the points do not determine the circle (ill-conditioned)");
  const CircleFit long_enough = arc(1.0);
  EXPECT_EQ(long_enough.status, FitStatus::kConverged) << long_enough.message;
  EXPECT_NEAR(long_enough.radius_mm, 55.0, 1e-6);
}

TEST(FitCircle, RefusesCollinearAndTooFewPoints) {
  const std::vector<double> x = {0, 1, 2, 3}, y = {0, 1, 2, 3};
  EXPECT_FALSE(FitCircle(x, y, {}, {}).IsUsable());
  EXPECT_FALSE(FitCircle(std::vector<double>{0, 1}, std::vector<double>{0, 1}, {}, {}).IsUsable());
}

}  // namespace
}  // namespace arcwheel::fitting
