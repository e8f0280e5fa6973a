#include "polishing/removal_fft.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "polishing/dwell.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using internal::FftRemoval;
using testing::SampledGaussian;

// A map of `nx` x `ny` nodes every `step_mm` from (x0, y0), with a seeded smooth error.
ErrorMap SmoothMap(double x0_mm, double y0_mm, double step_mm, int nx, int ny, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const double astig = 0.3 * u(rng), coma = 0.2 * u(rng), bx = 10.0 * u(rng), by = 10.0 * u(rng);
  ErrorMap map{
      .grid = {.x0_mm = x0_mm, .y0_mm = y0_mm, .dx_mm = step_mm, .dy_mm = step_mm, .nx = nx, .ny = ny}};
  for (int j = 0; j < ny; ++j) {
    for (int i = 0; i < nx; ++i) {
      const double x = map.grid.X(i) / 20.0, y = map.grid.Y(j) / 20.0;
      map.error_um.push_back(
          astig * (x * x - y * y) + coma * x * (x * x + y * y) +
          0.3 * std::exp(-(std::pow(map.grid.X(i) - bx, 2) + std::pow(map.grid.Y(j) - by, 2)) / 60.0));
    }
  }
  return map;
}

// Points on the map's grid, some beyond it (as a path's extension is), in no particular order.
std::vector<Eigen::Vector2d> GridPoints(const ErrorMap& map, int count, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> i(-6, map.grid.nx + 5), j(-6, map.grid.ny + 5);
  std::vector<Eigen::Vector2d> points;
  for (int k = 0; k < count; ++k) points.emplace_back(map.grid.X(i(rng)), map.grid.Y(j(rng)));
  return points;
}

struct Products {
  std::vector<int> nodes;  // every node of the map, in order
  Eigen::MatrixXd dense;   // rate of point k at node n, summed directly
  long nonzeros = 0;
};

// The removal matrix by brute force: every (node, point) pair.
Products BruteForce(const ErrorMap& map, const std::vector<Eigen::Vector2d>& points,
                    const RemovalFunction& removal) {
  Products p;
  p.dense.resize(map.grid.nx * map.grid.ny, static_cast<Eigen::Index>(points.size()));
  for (int n = 0; n < map.grid.nx * map.grid.ny; ++n) {
    p.nodes.push_back(n);
    for (std::size_t k = 0; k < points.size(); ++k) {
      const double rate = removal.RateUmPerS(map.grid.X(n % map.grid.nx) - points[k].x(),
                                             map.grid.Y(n / map.grid.nx) - points[k].y());
      p.dense(n, static_cast<Eigen::Index>(k)) = rate;
      p.nonzeros += rate > 0.0 ? 1 : 0;
    }
  }
  return p;
}

void ExpectProductsAsBruteForce(const ErrorMap& map, const std::vector<Eigen::Vector2d>& points,
                                const RemovalFunction& removal) {
  const Products brute = BruteForce(map, points, removal);
  const std::optional<FftRemoval> fft = FftRemoval::Make(map, brute.nodes, points, removal);
  ASSERT_TRUE(fft.has_value());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  Eigen::VectorXd dwell(static_cast<Eigen::Index>(points.size())), rows(map.grid.nx * map.grid.ny);
  for (auto& t : dwell) t = u(rng);
  for (auto& r : rows) r = u(rng) - 0.5;
  const Eigen::VectorXd removal_um = brute.dense * dwell, transposed = brute.dense.transpose() * rows;
  // FFT round-off: a few 1e-16 of the largest value times log2 of the size.
  EXPECT_LE((fft->Apply(dwell) - removal_um).cwiseAbs().maxCoeff(), 1e-12 * removal_um.cwiseAbs().maxCoeff());
  EXPECT_LE((fft->ApplyTranspose(rows) - transposed).cwiseAbs().maxCoeff(),
            1e-12 * transposed.cwiseAbs().maxCoeff());
  EXPECT_EQ(fft->Nonzeros(), brute.nonzeros);
}

TEST(FftRemoval, GivesTheGaussiansProductsAsABruteForceSumForPointsOnAndBeyondTheGrid) {
  const ErrorMap map = SmoothMap(-15.0, -12.0, 1.0, 31, 25, 1);
  ExpectProductsAsBruteForce(map, GridPoints(map, 400, 2),
                             GaussianRemovalFunction{.peak_rate_um_per_s = 1.3, .fwhm_mm = 6.0});
}

TEST(FftRemoval, GivesAnOffsetEllipticTablesProductsAsABruteForceSumOnAHalfMillimetreGrid) {
  // A footprint wholly on one side of the tool centre, on a grid of 0.5 x 0.5 mm; the table's
  // edges lie between grid steps (see the next test).
  const ErrorMap map = SmoothMap(-7.25, -4.5, 0.5, 37, 21, 3);
  const TabulatedRemovalFunction table = SampledGaussian(2.0, 3.0, -1.0, 1.5, 0.8, 0.6, -3.9, 0.25, 41, 25);
  ExpectProductsAsBruteForce(map, GridPoints(map, 300, 4), table);
}

TEST(FftRemoval, LeavesATableWhoseEdgeLiesOnTheGridToTheSparseMatrix) {
  // The rate jumps from the edge value to 0 at the table's edge; on the grid, the sparse matrix
  // keeps or drops that entry by the rounding of each point's coordinates.
  const ErrorMap map = SmoothMap(-15.0, -15.0, 1.0, 31, 31, 1);
  const std::vector<Eigen::Vector2d> points = GridPoints(map, 10, 2);
  const std::vector<int> nodes = {0, 1, 2};
  const TabulatedRemovalFunction on_grid = SampledGaussian(3.0, 2.0, -1.0, 3.0, 1.5, -6.0, -6.0, 0.5, 33, 21);
  EXPECT_FALSE(FftRemoval::Make(map, nodes, points, on_grid).has_value());
  const TabulatedRemovalFunction between =
      SampledGaussian(3.0, 2.0, -1.0, 3.0, 1.5, -6.25, -6.25, 0.5, 33, 21);
  EXPECT_TRUE(FftRemoval::Make(map, nodes, points, between).has_value());
}

TEST(FftRemoval, RefusesPointsOffTheGrid) {
  const ErrorMap map = SmoothMap(-15.0, -12.0, 1.0, 31, 25, 1);
  std::vector<Eigen::Vector2d> points = GridPoints(map, 10, 2);
  const std::vector<int> nodes = {0, 1, 2};
  EXPECT_TRUE(FftRemoval::Make(map, nodes, points, GaussianRemovalFunction{}).has_value());
  points[5].x() += 1e-6;  // a thousandth of a micrometre off the grid
  EXPECT_FALSE(FftRemoval::Make(map, nodes, points, GaussianRemovalFunction{}).has_value());
}

// The solve with FFT products against the sparse reference on one job: a square part whose raster
// lies on the map's grid.
TEST(SolveDwell, WithFftProductsAgreesWithTheSparseReference) {
  const surfaces::Aperture square{.width_x_mm = 40.0, .width_y_mm = 40.0};
  const ErrorMap target =
      RemovalTarget(SmoothMap(-20.0, -20.0, 1.0, 41, 41, 5), square, {.uniform_layer_um = 0.2});
  const std::vector<Eigen::Vector2d> path =
      RasterPath(square, {.line_spacing_mm = 1.0, .point_spacing_mm = 1.0, .extension_mm = 5.0});
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 1.0, .fwhm_mm = 5.0};
  // The same iteration both ways: the correlation start and the power-iteration step.
  const DwellOptions fft{.max_speed_mm_s = 500.0, .inverse_filter_start = false};
  DwellOptions sparse = fft;
  sparse.fft_products = false;
  const DwellSolution a = SolveDwell(target, square, path, tool, fft);
  const DwellSolution b = SolveDwell(target, square, path, tool, sparse);
  EXPECT_TRUE(a.fft_products);
  EXPECT_FALSE(b.fft_products);
  EXPECT_EQ(a.nonzeros, b.nonzeros);
  EXPECT_LT(b.after.rms_um, b.before.rms_um / 100.0);
  EXPECT_NEAR(a.after.rms_um, b.after.rms_um, 0.01 * b.after.rms_um);
  EXPECT_NEAR(a.total_time_s, b.total_time_s, 1e-6 * b.total_time_s);
  double largest = 0.0;
  for (std::size_t k = 0; k < a.dwell_s.size(); ++k)
    largest = std::max(largest, std::abs(a.dwell_s[k] - b.dwell_s[k]));
  EXPECT_LE(largest, 1e-6 * *std::max_element(b.dwell_s.begin(), b.dwell_s.end()));
}

TEST(SolveDwell, TheInverseFilterStartNeedsFewerIterationsForAResidualNoWorse) {
  const surfaces::Aperture square{.width_x_mm = 60.0, .width_y_mm = 60.0};
  const ErrorMap target =
      RemovalTarget(SmoothMap(-30.0, -30.0, 1.0, 61, 61, 5), square, {.uniform_layer_um = 0.2});
  const std::vector<Eigen::Vector2d> path =
      RasterPath(square, {.line_spacing_mm = 1.0, .point_spacing_mm = 1.0, .extension_mm = 5.0});
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 1.0, .fwhm_mm = 5.0};
  const DwellSolution fast = SolveDwell(target, square, path, tool, {.max_speed_mm_s = 500.0});
  const DwellSolution classic =
      SolveDwell(target, square, path, tool, {.max_speed_mm_s = 500.0, .inverse_filter_start = false});
  ASSERT_TRUE(fast.fft_products);
  EXPECT_LE(fast.after.rms_um, classic.after.rms_um) << fast.iterations << " against " << classic.iterations;
  EXPECT_LT(fast.iterations, classic.iterations);
  // Both within the speed limit: dwell at least the chord at 500 mm/s.
  for (std::size_t k = 1; k < fast.dwell_s.size(); ++k) EXPECT_GE(fast.dwell_s[k], 1.0 / 500.0 * (1 - 1e-12));
}

TEST(SolveDwell, FallsBackToTheSparseMatrixWhenThePathLeavesTheGrid) {
  const surfaces::Aperture disc{.shape = surfaces::Aperture::Shape::kCircle, .diameter_mm = 30.0};
  const ErrorMap target =
      RemovalTarget(SmoothMap(-15.0, -15.0, 1.0, 31, 31, 6), disc, {.uniform_layer_um = 0.2});
  // A circle's raster lines each have their own step: their points miss the grid.
  const std::vector<Eigen::Vector2d> path =
      RasterPath(disc, {.line_spacing_mm = 1.0, .point_spacing_mm = 1.0, .extension_mm = 5.0});
  const DwellSolution s = SolveDwell(target, disc, path, GaussianRemovalFunction{.fwhm_mm = 5.0},
                                     {.max_speed_mm_s = 500.0, .max_iterations = 50});
  EXPECT_FALSE(s.fft_products);
  EXPECT_GT(s.nonzeros, 0);
}

}  // namespace
}  // namespace arcwheel::polishing
