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

TEST(FitCircle, RefusesCollinearAndTooFewPoints) {
  const std::vector<double> x = {0, 1, 2, 3}, y = {0, 1, 2, 3};
  EXPECT_FALSE(FitCircle(x, y, {}, {}).IsUsable());
  EXPECT_FALSE(FitCircle(std::vector<double>{0, 1}, std::vector<double>{0, 1}, {}, {}).IsUsable());
}

}  // namespace
}  // namespace arcwheel::fitting
