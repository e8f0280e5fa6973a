// Accuracy of `process` on a large scan of the paper wheel of issue 29
// (acquisition::PaperTestWheel): the mean arc radius against the truth as the contract defines it
// (each phase's least-squares circle over the band of the rim averaged over its 1-degree bin,
// grit included), with the reported sigma. A benchmark, not a test: 1e8 samples take minutes.
//
//   paper_wheel_accuracy [SAMPLES [SEED]]      (default 1e8 samples, seed 1)
//
// The scan is the (500 rpm, 0.2 um noise, 0.2 % spikes, 0.1 % dropouts) over the same
// 22 mm, with the sample period and feed of benchmarks/process_bench.sh at that size (2.5 us and
// 5.28 mm/min at 1e8), the spindle at 501 rpm and the speed estimated.

#include <Eigen/Dense>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <numeric>
#include <vector>

#include "acquisition/simulate.h"
#include "core/progress.h"
#include "workflows/process_pipeline.h"

namespace {

using namespace arcwheel;
constexpr double kBandHalfMm = 8.0;

double BandCircleRadius(const std::vector<double>& y, const std::vector<double>& rho, Eigen::Vector3d p) {
  const auto n = static_cast<Eigen::Index>(y.size());
  Eigen::MatrixXd jacobian(n, 3);
  Eigen::VectorXd residual(n);
  for (int iteration = 0; iteration < 30; ++iteration) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double d = std::hypot(y[k] - p(0), rho[k] - p(1));
      residual(i) = d - p(2);
      jacobian(i, 0) = -(y[k] - p(0)) / d;
      jacobian(i, 1) = -(rho[k] - p(1)) / d;
      jacobian(i, 2) = -1.0;
    }
    const Eigen::Vector3d step = jacobian.colPivHouseholderQr().solve(-residual);
    p += step;
    if (step.norm() < 1e-12) break;
  }
  return p(2);
}

// Mean over the 360 phases of the band circle of the rim averaged over each phase's bin
// (0.005-degree steps, three to a grit cell).
double TruthMeanRadius(const acquisition::WheelModel& wheel, double zero_mm) {
  std::vector<double> y;
  // The band as an interval: the midpoint rule, 0.01 mm steps (6e-4 um from the limit).
  for (int k = 0; k < 1600; ++k) y.push_back(-kBandHalfMm + (k + 0.5) * 0.01);
  std::vector<double> rho(y.size());
  double sum = 0.0;
  for (int j = 0; j < 360; ++j) {
    for (std::size_t k = 0; k < y.size(); ++k) {
      double s = 0.0;
      for (int m = 0; m < 200; ++m) s += wheel.RadiusMm(j - 0.4975 + 0.005 * m, y[k]);
      rho[k] = s / 200.0 - zero_mm;
    }
    sum += BandCircleRadius(
        y, rho, {wheel.CenterAxialMm(j), wheel.CenterDistanceMm(j) - zero_mm, wheel.ArcRadiusMm(j)});
  }
  return sum / 360.0;
}

}  // namespace

int main(int argc, char** argv) {
  const double samples = argc > 1 ? std::atof(argv[1]) : 1e8;
  const auto seed = static_cast<std::uint64_t>(argc > 2 ? std::atoll(argv[2]) : 1);
  const acquisition::WheelModel wheel = acquisition::PaperTestWheel();
  acquisition::ScanSettings settings = acquisition::PaperTestScan(seed);
  settings.sample_period_s = samples >= 1e8 ? 2.5e-6 : 1e-5;
  settings.feed_mm_per_min = 22.0 / (samples * settings.sample_period_s) * 60.0;
  settings.spindle_rpm_true = 501.0;
  const double truth = TruthMeanRadius(wheel, settings.sensor_zero_radius_mm);
  acquisition::SimulatedScan simulated = acquisition::SimulateScan(wheel, settings);
  const std::size_t n = simulated.scan.size();
  workflows::ProcessPipelineOptions options;
  options.no_model = true;
  Progress progress(false);
  const auto start = std::chrono::steady_clock::now();
  const workflows::ProcessPipelineResult result =
      workflows::RunProcessPipeline(std::move(simulated.scan), "", "", options, progress);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const double error = result.fit.mean_arc_radius_mm - truth;
  std::printf(
      "samples %zu seed %llu: mean arc radius %.7f mm, truth %.7f mm, error %+.4f um, sigma %.4f um, z %+.2f "
      "(rpm used %.6f; %.1f s in memory, double, no model)\n",
      n, static_cast<unsigned long long>(seed), result.fit.mean_arc_radius_mm, truth, error * 1e3,
      result.fit.mean_arc_radius_sigma_mm * 1e3, error / result.fit.mean_arc_radius_sigma_mm,
      result.processed.rpm_used, seconds);
  return 0;
}
