#include "polishing/dwell.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "core/error.h"

namespace arcwheel::polishing {
namespace {

const grinding::Aperture kDisc{.shape = grinding::Aperture::Shape::kCircle, .diameter_mm = 100.0};

// A simulated error map over a 100 mm disc (1 mm grid): astigmatism, a ring and two bumps whose
// widths are above the tool's, as a ground part shows after grinding. Known parameters, seeded.
ErrorMap SimulatedErrorMap(unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double astig = 0.4 * u(rng), ring = 0.3 * u(rng);
  const double bx = 25.0 * u(rng), by = 25.0 * u(rng), cx = 25.0 * u(rng), cy = 25.0 * u(rng);
  ErrorMap map{.x0_mm = -52.0, .y0_mm = -52.0, .dx_mm = 1.0, .dy_mm = 1.0, .nx = 105, .ny = 105};
  for (int j = 0; j < map.ny; ++j) {
    for (int i = 0; i < map.nx; ++i) {
      const double x = map.X(i) / 50.0, y = map.Y(j) / 50.0, r2 = x * x + y * y;
      map.error_um.push_back(astig * (x * x - y * y) + ring * std::cos(3.0 * std::numbers::pi * r2) +
                             0.5 * std::exp(-((map.X(i) - bx) * (map.X(i) - bx) + (map.Y(j) - by) * (map.Y(j) - by)) / 200.0) -
                             0.4 * std::exp(-((map.X(i) - cx) * (map.X(i) - cx) + (map.Y(j) - cy) * (map.Y(j) - cy)) / 300.0));
    }
  }
  return map;
}

// Independent prediction: the untruncated Gaussian summed over every dwell point.
double FullGaussianRemovalUm(double x, double y, const std::vector<Eigen::Vector2d>& path,
                             const std::vector<double>& dwell_s, double peak, double fwhm) {
  const double sigma = fwhm / std::sqrt(8.0 * std::log(2.0));
  double sum = 0.0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    const double r2 = (x - path[k].x()) * (x - path[k].x()) + (y - path[k].y()) * (y - path[k].y());
    sum += peak * std::exp(-r2 / (2.0 * sigma * sigma)) * dwell_s[k];
  }
  return sum;
}

TEST(SolveDwell, CutsTheResidualRmsTenfoldWithNonNegativeDwellWithinSpeedLimits) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const DwellOptions options{.max_speed_mm_s = 150.0, .min_speed_mm_s = 0.2, .max_iterations = 500};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.5, .extension_mm = 10.0});
  for (const unsigned seed : {1u, 2u, 3u}) {
    const ErrorMap error = SimulatedErrorMap(seed);
    const ErrorMap target = RemovalTarget(error, kDisc, {.uniform_layer_um = 1.5});
    const DwellSolution solution = SolveDwell(target, kDisc, path, tool, options);
    ASSERT_EQ(solution.dwell_s.size(), path.size());
    for (std::size_t k = 0; k < path.size(); ++k) {
      EXPECT_GE(solution.dwell_s[k], 0.0);
      EXPECT_LE(solution.speed_mm_s[k], options.max_speed_mm_s * (1.0 + 1e-12));
      if (k > 0) {
        EXPECT_GE(solution.speed_mm_s[k], options.min_speed_mm_s * (1.0 - 1e-12));
        EXPECT_NEAR(solution.speed_mm_s[k] * solution.dwell_s[k], (path[k] - path[k - 1]).norm(), 1e-9);
      }
    }
    // Residual recomputed independently, with the whole Gaussian, over the aperture.
    double sum = 0.0, sum2 = 0.0, before_sum = 0.0, before_sum2 = 0.0;
    int n = 0;
    for (int j = 0; j < target.ny; ++j) {
      for (int i = 0; i < target.nx; ++i) {
        const double x = target.X(i), y = target.Y(j);
        if (x * x + y * y > 50.0 * 50.0) continue;
        const double e = error.At(i, j);
        const double r = target.At(i, j) - FullGaussianRemovalUm(x, y, path, solution.dwell_s, 2.0, 12.0);
        sum += r, sum2 += r * r, before_sum += e, before_sum2 += e * e, ++n;
      }
    }
    const double rms_after = std::sqrt(sum2 / n - (sum / n) * (sum / n));
    const double rms_before = std::sqrt(before_sum2 / n - (before_sum / n) * (before_sum / n));
    EXPECT_NEAR(solution.before.rms_um, rms_before, 1e-9);
    EXPECT_LT(rms_after, rms_before / 10.0) << "seed " << seed << ": " << rms_before << " -> " << rms_after;
    // The solver's model truncates the Gaussian at 3.5 sigma (0.2 % of the peak).
    EXPECT_NEAR(solution.after.rms_um, rms_after, 2e-3 * rms_before);
    EXPECT_GT(solution.total_time_s, 0.0);
  }
}

TEST(SolveDwell, RecoversAKnownDwellToWithinTheConditioningOfTheProblem) {
  // Target made by a known smooth dwell through the same model: the residual must vanish.
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 1.0, .fwhm_mm = 10.0};
  const grinding::Aperture square{.width_x_mm = 40.0, .width_y_mm = 40.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(square, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.0, .extension_mm = 8.0});
  ErrorMap target{.x0_mm = -20.0, .y0_mm = -20.0, .dx_mm = 1.0, .dy_mm = 1.0, .nx = 41, .ny = 41};
  std::vector<double> dwell(path.size(), 0.0);
  for (std::size_t k = 1; k < path.size(); ++k) dwell[k] = 0.1 + 0.05 * std::cos(path[k].x() / 9.0) * std::sin(path[k].y() / 7.0);
  for (int j = 0; j < target.ny; ++j) {
    for (int i = 0; i < target.nx; ++i) {
      double sum = 0.0;
      for (std::size_t k = 0; k < path.size(); ++k) sum += tool.RateUmPerS(target.X(i) - path[k].x(), target.Y(j) - path[k].y()) * dwell[k];
      target.error_um.push_back(sum);
    }
  }
  // Without the stall test: this checks that the iteration itself converges to the exact dwell.
  const DwellSolution solution = SolveDwell(target, square, path, tool, {.max_speed_mm_s = 100.0, .stall_iterations = 0});
  EXPECT_LT(solution.after.rms_um, 1e-3 * solution.before.rms_um);
}

TEST(SolveDwell, RefusesUnreachableSpeedsNamingThePointAndTheLayer) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.0, .extension_mm = 10.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(1), kDisc, {});  // no layer: zero somewhere
  try {
    (void)SolveDwell(target, kDisc, path, tool, {.max_speed_mm_s = 50.0});
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find("unreachable speeds: at max_speed_mm_s = 50"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("add a uniform layer of at least"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, tool, {.max_speed_mm_s = 5.0, .min_speed_mm_s = 6.0}), Error);
}

TEST(SolveDwell, KeepsTheLeastDwellAndReportsTheAccelerationTheSpeedsNeed) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 3.0, .point_spacing_mm = 3.0, .extension_mm = 8.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(4), kDisc, {.uniform_layer_um = 1.5});
  const DwellOptions options{.max_speed_mm_s = 200.0, .min_dwell_s = 0.03, .max_iterations = 300};
  const DwellSolution solution = SolveDwell(target, kDisc, path, tool, options);
  double acceleration = 0.0;
  for (std::size_t k = 1; k < path.size(); ++k) {
    EXPECT_GE(solution.dwell_s[k], 0.03);
    if (k < 2) continue;
    const double length = (path[k] - path[k - 1]).norm();
    const double v0 = solution.speed_mm_s[k - 1];
    acceleration = std::max(acceleration, std::abs(solution.speed_mm_s[k] * solution.speed_mm_s[k] - v0 * v0) / (2.0 * length));
  }
  EXPECT_NEAR(solution.max_acceleration_mm_s2, acceleration, 1e-9 * acceleration);
  DwellOptions limited = options;
  limited.max_acceleration_mm_s2 = 0.5 * acceleration;
  try {
    (void)SolveDwell(target, kDisc, path, tool, limited);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("above max_acceleration_mm_s2"), std::string::npos) << e.what();
  }
}

TEST(SolveDwell, RefusesAnEmptyAperture) {
  const ErrorMap target{.x0_mm = 500.0, .y0_mm = 500.0, .nx = 2, .ny = 2, .error_um = {1, 2, 3, 4}};
  const std::vector<Eigen::Vector2d> path = {{0.0, 0.0}, {1.0, 0.0}};
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, {}, {}), Error);
}

TEST(RasterPath, CoversTheGrownDiscInZigzagWithStepsNoLongerThanAsked) {
  const auto path = RasterPath(kDisc, {.line_spacing_mm = 2.0, .point_spacing_mm = 3.0, .extension_mm = 5.0});
  for (const auto& p : path) EXPECT_LE(p.norm(), 55.0 + 1e-9);
  for (std::size_t k = 1; k < path.size(); ++k) {
    if (path[k].y() == path[k - 1].y()) {
      EXPECT_LE((path[k] - path[k - 1]).norm(), 3.0 + 1e-9);
    }
    EXPECT_GT((path[k] - path[k - 1]).norm(), 0.0);
  }
  EXPECT_DOUBLE_EQ(path.front().y(), -55.0);
  EXPECT_DOUBLE_EQ(path.back().y(), 55.0);
}

}  // namespace
}  // namespace arcwheel::polishing
