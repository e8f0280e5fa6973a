#include "polishing/dwell.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "core/error.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using testing::SampledGaussian;

const surfaces::Aperture kDisc{.shape = surfaces::Aperture::Shape::kCircle, .diameter_mm = 100.0};

// A simulated error map over a 100 mm disc (1 mm grid): astigmatism, a ring and two bumps whose
// widths are above the tool's, as a ground part shows after grinding. Known parameters, seeded.
// A 2 mm grid still samples the 12 mm tool and the features finely, at a quarter of the nodes.
ErrorMap SimulatedErrorMap(unsigned seed, double step_mm = 1.0) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double astig = 0.4 * u(rng), ring = 0.3 * u(rng);
  const double bx = 25.0 * u(rng), by = 25.0 * u(rng), cx = 25.0 * u(rng), cy = 25.0 * u(rng);
  const int nodes = 2 * static_cast<int>(std::ceil(52.0 / step_mm)) + 1;
  const double half_width_mm = (nodes - 1) / 2 * step_mm;
  ErrorMap map{.grid = {.x0_mm = -half_width_mm,
                        .y0_mm = -half_width_mm,
                        .dx_mm = step_mm,
                        .dy_mm = step_mm,
                        .nx = nodes,
                        .ny = nodes}};
  for (int j = 0; j < map.grid.ny; ++j) {
    for (int i = 0; i < map.grid.nx; ++i) {
      const double x = map.grid.X(i) / 50.0, y = map.grid.Y(j) / 50.0, r2 = x * x + y * y;
      map.error_um.push_back(astig * (x * x - y * y) + ring * std::cos(3.0 * std::numbers::pi * r2) +
                             0.5 * std::exp(-((map.grid.X(i) - bx) * (map.grid.X(i) - bx) +
                                              (map.grid.Y(j) - by) * (map.grid.Y(j) - by)) /
                                            200.0) -
                             0.4 * std::exp(-((map.grid.X(i) - cx) * (map.grid.X(i) - cx) +
                                              (map.grid.Y(j) - cy) * (map.grid.Y(j) - cy)) /
                                            300.0));
    }
  }
  return map;
}

// exp(-(node - point)^2 / (2 sigma^2)) for every node of one grid axis (rows) and every path point
// (columns), along x or y.
Eigen::MatrixXd AxisGaussian(int nodes, double first_mm, double step_mm,
                             const std::vector<Eigen::Vector2d>& path, int axis, double sigma_mm) {
  Eigen::MatrixXd g(nodes, static_cast<Eigen::Index>(path.size()));
  for (int i = 0; i < nodes; ++i) {
    for (std::size_t k = 0; k < path.size(); ++k) {
      const double d = first_mm + i * step_mm - path[k][axis];
      g(i, static_cast<Eigen::Index>(k)) = std::exp(-d * d / (2.0 * sigma_mm * sigma_mm));
    }
  }
  return g;
}

// Independent prediction: the untruncated Gaussian summed over every dwell point, at every node of
// `grid` (row j, column i). The Gaussian is separable, so the sum over points k of
// exp(-dx^2 / 2s^2) exp(-dy^2 / 2s^2) dwell_k is the product Gy diag(dwell) Gx^T.
Eigen::MatrixXd FullGaussianRemovalUm(const surfaces::GridSpec& grid,
                                      const std::vector<Eigen::Vector2d>& path,
                                      const std::vector<double>& dwell_s, double peak, double fwhm) {
  const double sigma = fwhm / std::sqrt(8.0 * std::log(2.0));
  const Eigen::Map<const Eigen::VectorXd> dwell(dwell_s.data(), static_cast<Eigen::Index>(dwell_s.size()));
  const Eigen::MatrixXd gx = AxisGaussian(grid.nx, grid.x0_mm, grid.dx_mm, path, 0, sigma);
  const Eigen::MatrixXd gy = AxisGaussian(grid.ny, grid.y0_mm, grid.dy_mm, path, 1, sigma);
  return peak * (gy * dwell.asDiagonal() * gx.transpose());
}

// RMS (about the mean) of target - removal over the disc, the removal recomputed with the whole
// Gaussian from the solution's dwell.
double ResidualRmsUm(const ErrorMap& target, const std::vector<Eigen::Vector2d>& path,
                     const std::vector<double>& dwell_s, double peak, double fwhm) {
  const Eigen::MatrixXd removal = FullGaussianRemovalUm(target.grid, path, dwell_s, peak, fwhm);
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int j = 0; j < target.grid.ny; ++j) {
    for (int i = 0; i < target.grid.nx; ++i) {
      const double x = target.grid.X(i), y = target.grid.Y(j);
      if (x * x + y * y > 50.0 * 50.0) continue;
      const double r = target.At(i, j) - removal(j, i);
      sum += r, sum2 += r * r, ++n;
    }
  }
  return std::sqrt(sum2 / n - (sum / n) * (sum / n));
}

TEST(SolveDwell, CutsTheResidualRmsTenfoldWithNonNegativeDwellWithinSpeedLimits) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const DwellOptions options{.max_speed_mm_s = 150.0, .min_speed_mm_s = 0.2, .max_iterations = 500};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.5, .extension_mm = 10.0});
  for (const unsigned seed : {1u, 2u, 3u}) {
    const ErrorMap error = SimulatedErrorMap(seed, 2.0);
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
    double before_sum = 0.0, before_sum2 = 0.0;
    int n = 0;
    for (int j = 0; j < error.grid.ny; ++j) {
      for (int i = 0; i < error.grid.nx; ++i) {
        const double x = error.grid.X(i), y = error.grid.Y(j), e = error.At(i, j);
        if (x * x + y * y > 50.0 * 50.0) continue;
        before_sum += e, before_sum2 += e * e, ++n;
      }
    }
    const double rms_after = ResidualRmsUm(target, path, solution.dwell_s, 2.0, 12.0);
    const double rms_before = std::sqrt(before_sum2 / n - (before_sum / n) * (before_sum / n));
    EXPECT_NEAR(solution.before.rms_um, rms_before, 1e-9);
    EXPECT_LT(rms_after, rms_before / 10.0) << "seed " << seed << ": " << rms_before << " -> " << rms_after;
    // The solver's model truncates the Gaussian at 3.5 sigma (0.2 % of the peak).
    EXPECT_NEAR(solution.after.rms_um, rms_after, 2e-3 * rms_before);
    EXPECT_GT(solution.total_time_s, 0.0);
  }
}

TEST(SolveDwell, AMeasuredGaussianRemovesAsTheAnalyticOneWithinTheInterpolationBoundAndCutsTheRmsTenfold) {
  const double peak = 2.0, fwhm = 12.0, sigma = fwhm / std::sqrt(8.0 * std::log(2.0)), h = 0.1;
  const int n = 2 * static_cast<int>(std::ceil(4.5 * sigma / h)) + 1;
  const double half_width = (n - 1) / 2 * h;
  const RemovalFunction table =
      SampledGaussian(peak, 0.0, 0.0, sigma, sigma, -half_width, -half_width, h, n, n);
  // Bilinear interpolation errs by at most (hx^2 max|f_xx| + hy^2 max|f_yy|) / 8 (linear
  // interpolation's h^2/8 max|f''| along each axis in turn); for the Gaussian max|f_xx| = P/sigma^2.
  const double interpolation_bound = peak * (h * h + h * h) / (8.0 * sigma * sigma);
  const DwellOptions options{.max_speed_mm_s = 150.0, .min_speed_mm_s = 0.2, .max_iterations = 500};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.5, .extension_mm = 10.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(1, 2.0), kDisc, {.uniform_layer_um = 1.5});
  const DwellSolution solution = SolveDwell(target, kDisc, path, table, options);
  // Same dwell through the analytic, untruncated Gaussian: inside the table each point's rate is
  // within the interpolation bound; outside it the table gives 0 for the Gaussian's value. So the
  // bound at a node is the sum over points of dwell * (inside ? interpolation bound : Gaussian),
  // and "inside" (|dx|, |dy| <= half width) is separable like the Gaussian.
  const Eigen::MatrixXd analytic = FullGaussianRemovalUm(target.grid, path, solution.dwell_s, peak, fwhm);
  const auto inside_along = [&](int nodes, double first_mm, double step_mm, int axis) {
    Eigen::MatrixXd in(nodes, static_cast<Eigen::Index>(path.size()));
    for (int i = 0; i < nodes; ++i) {
      for (std::size_t k = 0; k < path.size(); ++k) {
        in(i, static_cast<Eigen::Index>(k)) = std::abs(first_mm + i * step_mm - path[k][axis]) <= half_width;
      }
    }
    return in;
  };
  const Eigen::MatrixXd in_x = inside_along(target.grid.nx, target.grid.x0_mm, target.grid.dx_mm, 0);
  const Eigen::MatrixXd in_y = inside_along(target.grid.ny, target.grid.y0_mm, target.grid.dy_mm, 1);
  const Eigen::MatrixXd gx =
      AxisGaussian(target.grid.nx, target.grid.x0_mm, target.grid.dx_mm, path, 0, sigma);
  const Eigen::MatrixXd gy =
      AxisGaussian(target.grid.ny, target.grid.y0_mm, target.grid.dy_mm, path, 1, sigma);
  const Eigen::Map<const Eigen::VectorXd> dwell(solution.dwell_s.data(),
                                                static_cast<Eigen::Index>(solution.dwell_s.size()));
  const Eigen::MatrixXd inside_dwell = in_y * dwell.asDiagonal() * in_x.transpose();
  const Eigen::MatrixXd inside_gaussian =
      peak * (in_y.cwiseProduct(gy) * dwell.asDiagonal() * in_x.cwiseProduct(gx).transpose());
  const Eigen::MatrixXd bound = interpolation_bound * inside_dwell + (analytic - inside_gaussian);
  for (int j = 0; j < target.grid.ny; ++j) {
    for (int i = 0; i < target.grid.nx; ++i) {
      const double removal = solution.predicted_removal_um.At(i, j);
      if (std::isnan(removal)) continue;
      EXPECT_LE(std::abs(removal - analytic(j, i)), bound(j, i) + 1e-12)
          << target.grid.X(i) << ", " << target.grid.Y(j);
    }
  }
  const double rms_after = ResidualRmsUm(target, path, solution.dwell_s, peak, fwhm);
  EXPECT_LT(rms_after, solution.before.rms_um / 10.0) << solution.before.rms_um << " -> " << rms_after;
  EXPECT_LT(solution.after.rms_um, solution.before.rms_um / 10.0);
}

// Bilinear interpolation written as the weighted sum of the four surrounding nodes.
double BruteForceRate(const TabulatedRemovalFunction& t, double x, double y) {
  const double u = (x - t.x0_mm) / t.dx_mm, v = (y - t.y0_mm) / t.dy_mm;
  if (u < 0.0 || v < 0.0 || u > t.nx - 1 || v > t.ny - 1) return 0.0;
  double sum = 0.0;
  for (int j = static_cast<int>(std::floor(v)); j <= static_cast<int>(std::floor(v)) + 1 && j < t.ny; ++j) {
    for (int i = static_cast<int>(std::floor(u)); i <= static_cast<int>(std::floor(u)) + 1 && i < t.nx; ++i) {
      sum += (1.0 - std::abs(u - i)) * (1.0 - std::abs(v - j)) *
             t.rate_um_per_s[static_cast<std::size_t>(j * t.nx + i)];
    }
  }
  return sum;
}

TEST(SolveDwell, PredictsTheRemovalOfAnOffsetEllipticFootprintAsABruteForceConvolution) {
  // Removal centred 2 mm in +x and 1 mm in -y of the tool centre, sigmas 3 and 1.5 mm, on a
  // 0.5 mm table: the interpolation is visible at the map's 1 mm nodes.
  const TabulatedRemovalFunction table = SampledGaussian(3.0, 2.0, -1.0, 3.0, 1.5, -6.0, -6.0, 0.5, 33, 21);
  const surfaces::Aperture square{.width_x_mm = 30.0, .width_y_mm = 30.0};
  ErrorMap error{.grid = {.x0_mm = -15.0, .y0_mm = -15.0, .dx_mm = 1.0, .dy_mm = 1.0, .nx = 31, .ny = 31}};
  for (int j = 0; j < error.grid.ny; ++j) {
    for (int i = 0; i < error.grid.nx; ++i) {
      error.error_um.push_back(0.2 * std::cos(error.grid.X(i) / 6.0) * std::sin(error.grid.Y(j) / 5.0) +
                               0.003 * error.grid.X(i));
    }
  }
  const ErrorMap target = RemovalTarget(error, square, {.uniform_layer_um = 0.5});
  const std::vector<Eigen::Vector2d> path =
      RasterPath(square, {.line_spacing_mm = 1.0, .point_spacing_mm = 1.0, .extension_mm = 6.0});
  const DwellSolution solution =
      SolveDwell(target, square, path, table, {.max_speed_mm_s = 500.0, .max_iterations = 1000});
  double most = 0.0;
  for (int j = 0; j < target.grid.ny; ++j) {
    for (int i = 0; i < target.grid.nx; ++i) {
      double removal = 0.0;
      for (std::size_t k = 0; k < path.size(); ++k) {
        removal += solution.dwell_s[k] *
                   BruteForceRate(table, target.grid.X(i) - path[k].x(), target.grid.Y(j) - path[k].y());
      }
      EXPECT_NEAR(solution.predicted_removal_um.At(i, j), removal, 1e-9)
          << target.grid.X(i) << ", " << target.grid.Y(j);
      most = std::max(most, removal);
    }
  }
  EXPECT_GT(most, 0.5);
  EXPECT_LT(solution.after.rms_um, solution.before.rms_um / 10.0)
      << solution.before.rms_um << " -> " << solution.after.rms_um;
}

TEST(SolveDwell, RecoversAKnownDwellToWithinTheConditioningOfTheProblem) {
  // Target made by a known smooth dwell through the same model: the residual must vanish.
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 1.0, .fwhm_mm = 10.0};
  const surfaces::Aperture square{.width_x_mm = 40.0, .width_y_mm = 40.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(square, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.0, .extension_mm = 8.0});
  ErrorMap target{.grid = {.x0_mm = -20.0, .y0_mm = -20.0, .dx_mm = 1.0, .dy_mm = 1.0, .nx = 41, .ny = 41}};
  std::vector<double> dwell(path.size(), 0.0);
  for (std::size_t k = 1; k < path.size(); ++k)
    dwell[k] = 0.1 + 0.05 * std::cos(path[k].x() / 9.0) * std::sin(path[k].y() / 7.0);
  for (int j = 0; j < target.grid.ny; ++j) {
    for (int i = 0; i < target.grid.nx; ++i) {
      double sum = 0.0;
      for (std::size_t k = 0; k < path.size(); ++k)
        sum += tool.RateUmPerS(target.grid.X(i) - path[k].x(), target.grid.Y(j) - path[k].y()) * dwell[k];
      target.error_um.push_back(sum);
    }
  }
  // Without the stall test: this checks that the iteration itself converges to the exact dwell.
  const DwellSolution solution = SolveDwell(
      target, square, path, tool, {.max_speed_mm_s = 100.0, .max_iterations = 5000, .stall_iterations = 0});
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
    EXPECT_NE(std::string(e.what()).find("unreachable speeds: at max_speed_mm_s = 50"), std::string::npos)
        << e.what();
    EXPECT_NE(std::string(e.what()).find("add a uniform layer of at least"), std::string::npos) << e.what();
  }
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, tool, {.max_speed_mm_s = 5.0, .min_speed_mm_s = 6.0}),
               Error);
}

// The largest |v_k^2 - v_(k-1)^2| / (2 L_k) over k >= 2, recomputed from the path and the speeds.
double LargestAcceleration(const std::vector<Eigen::Vector2d>& path, const DwellSolution& s) {
  double most = 0.0;
  for (std::size_t k = 2; k < path.size(); ++k) {
    const double length = (path[k] - path[k - 1]).norm();
    const double v0 = s.speed_mm_s[k - 1], v1 = s.speed_mm_s[k];
    most = std::max(most, std::abs(v1 * v1 - v0 * v0) / (2.0 * length));
  }
  return most;
}

TEST(SolveDwell, KeepsTheLeastDwellAndReportsTheAccelerationTheSpeedsNeed) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 3.0, .point_spacing_mm = 3.0, .extension_mm = 8.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(4, 2.0), kDisc, {.uniform_layer_um = 1.5});
  const DwellOptions options{.max_speed_mm_s = 200.0, .min_dwell_s = 0.03, .max_iterations = 300};
  const DwellSolution solution = SolveDwell(target, kDisc, path, tool, options);
  for (std::size_t k = 1; k < path.size(); ++k) EXPECT_GE(solution.dwell_s[k], 0.03);
  const double acceleration = LargestAcceleration(path, solution);
  EXPECT_NEAR(solution.max_acceleration_mm_s2, acceleration, 1e-9 * acceleration);
  EXPECT_EQ(solution.shaping_rounds, 0);
}

TEST(SolveDwell, ShapesTheSpeedsToTheAccelerationLimitAndStillCutsTheResidualTenfold) {
  const double peak = 2.0, fwhm = 12.0;
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = peak, .fwhm_mm = fwhm};
  const DwellOptions free{.max_speed_mm_s = 150.0, .min_speed_mm_s = 0.2, .max_iterations = 500};
  // Shaping re-solves the whole path once a round, so this case is kept small: a 2 mm map and a
  // 3 mm raster, whose unshaped speeds still need more than twice the limit.
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 3.0, .point_spacing_mm = 3.0, .extension_mm = 8.0});
  for (const unsigned seed : {2u}) {
    const ErrorMap error = SimulatedErrorMap(seed, 2.0);
    const ErrorMap target = RemovalTarget(error, kDisc, {.uniform_layer_um = 1.5});
    const DwellSolution unshaped = SolveDwell(target, kDisc, path, tool, free);
    const double limit = 1000.0;  // mm/s^2
    // The unshaped speeds need more than the limit: shaping has work to do.
    ASSERT_GT(LargestAcceleration(path, unshaped), 2.0 * limit) << "seed " << seed;
    DwellOptions limited = free;
    limited.max_acceleration_mm_s2 = limit;
    const DwellSolution solution = SolveDwell(target, kDisc, path, tool, limited);
    EXPECT_GE(solution.shaping_rounds, 1);
    for (std::size_t k = 1; k < path.size(); ++k) {
      const double length = (path[k] - path[k - 1]).norm();
      EXPECT_GE(solution.dwell_s[k], 0.0);
      EXPECT_LE(solution.speed_mm_s[k], free.max_speed_mm_s * (1.0 + 1e-12));
      EXPECT_GE(solution.speed_mm_s[k], free.min_speed_mm_s * (1.0 - 1e-12));
      EXPECT_NEAR(solution.speed_mm_s[k] * solution.dwell_s[k], length, 1e-9);
      if (k < 2) continue;
      const double v0 = solution.speed_mm_s[k - 1], v1 = solution.speed_mm_s[k];
      EXPECT_LE(std::abs(v1 * v1 - v0 * v0) / (2.0 * length), limit * (1.0 + 1e-9))
          << "seed " << seed << " point " << k;
    }
    EXPECT_NEAR(solution.max_acceleration_mm_s2, LargestAcceleration(path, solution), 1e-9 * limit);
    // The prediction is of the final dwell (same truncated model, summed here point by point).
    for (int j = 0; j < target.grid.ny; j += 3) {
      for (int i = 0; i < target.grid.nx; i += 3) {
        if (std::isnan(solution.predicted_removal_um.At(i, j))) continue;
        double removal = 0.0;
        for (std::size_t k = 0; k < path.size(); ++k) {
          removal += tool.RateUmPerS(target.grid.X(i) - path[k].x(), target.grid.Y(j) - path[k].y()) *
                     solution.dwell_s[k];
        }
        EXPECT_NEAR(solution.predicted_removal_um.At(i, j), removal, 1e-9);
      }
    }
    const double rms_after = ResidualRmsUm(target, path, solution.dwell_s, peak, fwhm);
    EXPECT_LT(rms_after, solution.before.rms_um / 10.0)
        << "seed " << seed << ": " << solution.before.rms_um << " -> " << rms_after;
  }
}

TEST(SolveDwell, RefusesSpeedsThatDoNotSettleWithinTheShapingRounds) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 3.0, .point_spacing_mm = 3.0, .extension_mm = 8.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(1, 2.0), kDisc, {.uniform_layer_um = 1.5});
  const DwellOptions options{.max_speed_mm_s = 150.0,
                             .min_speed_mm_s = 0.2,
                             .max_acceleration_mm_s2 = 1000.0,
                             .max_iterations = 500,
                             .max_shaping_rounds = 1};
  try {
    (void)SolveDwell(target, kDisc, path, tool, options);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find(
                  "after 1 shaping rounds the speeds still exceed max_acceleration_mm_s2 = 1000: "
                  "slowing down into path point"),
              std::string::npos)
        << e.what();
  }
}

TEST(SolveDwell, HoldsThePerPointLeastDwellAndRefusesOneOutOfRange) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(kDisc, {.line_spacing_mm = 3.0, .point_spacing_mm = 3.0, .extension_mm = 8.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(4, 2.0), kDisc, {.uniform_layer_um = 1.5});
  DwellOptions options{.max_speed_mm_s = 200.0, .min_speed_mm_s = 1.0, .max_iterations = 300};
  options.least_dwell_s.assign(path.size(), 0.0);
  for (std::size_t k = 1; k < path.size(); k += 17) options.least_dwell_s[k] = 0.5;
  const DwellSolution solution = SolveDwell(target, kDisc, path, tool, options);
  for (std::size_t k = 1; k < path.size(); ++k) EXPECT_GE(solution.dwell_s[k], options.least_dwell_s[k]) << k;
  DwellOptions bad = options;
  bad.least_dwell_s.pop_back();
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, tool, bad), Error);
  bad = options;
  bad.least_dwell_s[0] = 0.1;  // the approach takes no dwell
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, tool, bad), Error);
  bad = options;
  bad.least_dwell_s[5] = -1.0;
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, tool, bad), Error);
  bad = options;
  bad.least_dwell_s[5] = 10.0;  // above length / min_speed = 3 s
  try {
    (void)SolveDwell(target, kDisc, path, tool, bad);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidOption);
    EXPECT_NE(std::string(e.what()).find("least_dwell_s[5] = 10 s"), std::string::npos) << e.what();
  }
}

TEST(SolveDwell, RefusesAnEmptyAperture) {
  const ErrorMap target{.grid = {.x0_mm = 500.0, .y0_mm = 500.0, .nx = 2, .ny = 2}, .error_um = {1, 2, 3, 4}};
  const std::vector<Eigen::Vector2d> path = {{0.0, 0.0}, {1.0, 0.0}};
  EXPECT_THROW((void)SolveDwell(target, kDisc, path, {}, {}), Error);
}

TEST(DwellOptions, ReportsEveryViolationWithItsValueNamedByTheJobKey) {
  EXPECT_TRUE(DwellOptions{}.Problems().empty());
  const DwellOptions bad{.max_speed_mm_s = -3.0, .min_dwell_s = -1.0, .max_iterations = 0};
  const std::vector<std::string> problems = bad.Problems();
  ASSERT_EQ(problems.size(), 3u) << ::testing::PrintToString(problems);
  EXPECT_EQ(problems[0], "machine.max_speed_mm_s = -3 violates > 0");
  EXPECT_EQ(problems[1], "machine.min_dwell_s = -1 violates >= 0");
  EXPECT_EQ(problems[2], "solver.max_iterations = 0 violates >= 1");
  // SolveDwell refuses them all at once, before any work.
  const std::vector<Eigen::Vector2d> path = {{0.0, 0.0}, {1.0, 0.0}};
  try {
    (void)SolveDwell(RemovalTarget(SimulatedErrorMap(1), kDisc, {}), kDisc, path, {}, bad);
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kInvalidOption);
    for (const std::string& p : problems)
      EXPECT_NE(std::string(e.what()).find(p), std::string::npos) << e.what();
  }
}

TEST(RasterOptions, ReportsEveryViolationWithItsValueNamedByTheJobKey) {
  EXPECT_TRUE(RasterOptions{}.Problems().empty());
  const RasterOptions bad{.line_spacing_mm = 0.0, .point_spacing_mm = -2.0, .extension_mm = -1.0};
  EXPECT_EQ(bad.Problems(), (std::vector<std::string>{"path.line_spacing_mm = 0 violates > 0",
                                                      "path.point_spacing_mm = -2 violates > 0",
                                                      "path.extension_mm = -1 violates >= 0"}));
  EXPECT_THROW((void)RasterPath(kDisc, bad), Error);
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

TEST(SpiralPath, FollowsTheArchimedeanSpiralInEqualArcLengthSteps) {
  const double pitch = 2.0, step = 2.5;
  const auto path =
      SpiralPath(kDisc, {.line_spacing_mm = pitch, .point_spacing_mm = step, .extension_mm = 5.0});
  const double b = pitch / (2.0 * std::numbers::pi);
  // Arc length of r = b theta from the centre: (b/2) (theta sqrt(1 + theta^2) + asinh theta).
  auto arc = [b](double theta) {
    return 0.5 * b * (theta * std::sqrt(1.0 + theta * theta) + std::asinh(theta));
  };
  EXPECT_EQ(path.front().norm(), 0.0);
  EXPECT_NEAR(path.back().norm(), 55.0, 1e-9);
  const double total = arc(55.0 / b);
  const double expected_step = total / std::ceil(total / step);
  for (std::size_t k = 1; k < path.size(); ++k) {
    const double theta = path[k].norm() / b;  // on the spiral, the polar angle is theta mod 2 pi
    EXPECT_NEAR(std::remainder(std::atan2(path[k].y(), path[k].x()) - theta, 2.0 * std::numbers::pi), 0.0,
                1e-9)
        << k;
    EXPECT_NEAR(arc(theta) - arc(path[k - 1].norm() / b), expected_step, 1e-9) << k;
    EXPECT_LE((path[k] - path[k - 1]).norm(), step + 1e-9);
  }
  EXPECT_LE(expected_step, step);
}

TEST(SpiralPath, CarriesADwellThatCutsTheResidualRmsTenfold) {
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 2.0, .fwhm_mm = 12.0};
  const auto path =
      SpiralPath(kDisc, {.line_spacing_mm = 2.0, .point_spacing_mm = 2.5, .extension_mm = 10.0});
  const ErrorMap target = RemovalTarget(SimulatedErrorMap(1, 2.0), kDisc, {.uniform_layer_um = 1.5});
  const DwellSolution solution = SolveDwell(
      target, kDisc, path, tool, {.max_speed_mm_s = 150.0, .min_speed_mm_s = 0.2, .max_iterations = 500});
  const double rms_after = ResidualRmsUm(target, path, solution.dwell_s, 2.0, 12.0);
  EXPECT_LT(rms_after, solution.before.rms_um / 10.0) << solution.before.rms_um << " -> " << rms_after;
}

}  // namespace
}  // namespace arcwheel::polishing
