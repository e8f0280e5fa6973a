// Dwell-solve time against the number of dwell points (issue 19: 1e5 points in under 5 s, 1e6 in
// under 60 s, the residual RMS within 1 % of the sparse reference's).
// A square aperture of side ~sqrt(N) mm, dwell points and map nodes every 1 mm, a Gaussian tool of
// 5 mm FWHM, a smooth simulated error map plus a 0.2 um layer; the solver's defaults of the job file
// (2000 iterations at most, relative tolerance 1e-7). Second argument: 1 = FFT products (the
// default), 0 = the sparse removal matrix (the reference). The CPU column is the whole process's
// (the product workers' included), so it can exceed the wall time on an idle machine.

#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "polishing/dwell.h"
#include "polishing/removal_fft.h"

namespace {

using namespace arcwheel::polishing;

void BM_SolveDwell(benchmark::State& state) {
  const double extension_mm = 5.0;
  const double side_mm =
      std::round(std::sqrt(static_cast<double>(state.range(0)))) - 1.0 - 2.0 * extension_mm;
  const arcwheel::surfaces::Aperture aperture{.width_x_mm = side_mm, .width_y_mm = side_mm};
  const std::vector<Eigen::Vector2d> path =
      RasterPath(aperture, {.line_spacing_mm = 1.0, .point_spacing_mm = 1.0, .extension_mm = extension_mm});
  const int nodes = static_cast<int>(side_mm) + 1;
  ErrorMap error{.grid = {.x0_mm = -side_mm / 2,
                          .y0_mm = -side_mm / 2,
                          .dx_mm = 1.0,
                          .dy_mm = 1.0,
                          .nx = nodes,
                          .ny = nodes}};
  for (int j = 0; j < nodes; ++j) {
    for (int i = 0; i < nodes; ++i) {
      const double x = error.grid.X(i) / side_mm, y = error.grid.Y(j) / side_mm;
      error.error_um.push_back(0.3 * (x * x - y * y) + 0.2 * std::cos(9.0 * x) * std::sin(7.0 * y));
    }
  }
  const ErrorMap target = RemovalTarget(error, aperture, {.uniform_layer_um = 0.2});
  const GaussianRemovalFunction tool{.peak_rate_um_per_s = 1.0, .fwhm_mm = 5.0};
  DwellSolution solution;
  for (auto _ : state) {
    solution =
        SolveDwell(target, aperture, path, tool,
                   {.max_speed_mm_s = 500.0, .max_iterations = 2000, .fft_products = state.range(1) != 0});
  }
  state.counters["dwell_points"] = static_cast<double>(path.size());
  state.counters["map_nodes"] = solution.before.nodes;
  state.counters["nonzeros"] = static_cast<double>(solution.nonzeros);
  state.counters["fft"] = solution.fft_products ? 1.0 : 0.0;
  state.counters["iterations"] = solution.iterations;
  state.counters["rms_before_um"] = solution.before.rms_um;
  state.counters["rms_after_um"] = solution.after.rms_um;
}

// One projected-gradient iteration's products at 1e6 points (the 1e6 solve's grid): A y - b with
// its norm, then A^T of it; the solve's loop spends most of its time here.
void BM_FftProducts(benchmark::State& state) {
  const int nodes = 990;
  ErrorMap map{
      .grid = {.x0_mm = -494.5, .y0_mm = -494.5, .dx_mm = 1.0, .dy_mm = 1.0, .nx = nodes, .ny = nodes}};
  map.error_um.assign(static_cast<std::size_t>(nodes) * nodes, 0.1);
  std::vector<int> rows(map.error_um.size());
  for (std::size_t k = 0; k < rows.size(); ++k) rows[k] = static_cast<int>(k);
  std::vector<Eigen::Vector2d> points;
  for (int j = -5; j < nodes + 5; ++j)
    for (int i = -5; i < nodes + 5; ++i) points.emplace_back(map.grid.X(0) + i, map.grid.Y(0) + j);
  const auto f = internal::FftRemoval::Make(map, rows, points, GaussianRemovalFunction{.fwhm_mm = 5.0});
  Eigen::VectorXd t = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(points.size()), 0.01), residual,
                  gradient;
  const Eigen::VectorXd target = Eigen::VectorXd::Constant(static_cast<Eigen::Index>(rows.size()), 0.1);
  for (auto _ : state) {
    benchmark::DoNotOptimize(f->Residual(t, target, residual));
    f->GradientOfResidual(residual, gradient);
  }
}
BENCHMARK(BM_FftProducts)->Unit(benchmark::kMillisecond)->UseRealTime()->MinTime(2.0);

BENCHMARK(BM_SolveDwell)
    ->Args({10000, 1})
    ->Args({10000, 0})
    ->Args({100000, 1})
    ->Args({100000, 0})
    ->Args({1000000, 1})
    ->MeasureProcessCPUTime()
    ->UseRealTime()
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->Repetitions(3);

}  // namespace

BENCHMARK_MAIN();
