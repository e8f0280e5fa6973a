// Cost of one roundness evaluation (filter, association, parameters, spectrum) per profile, for
// the profile sizes of an axial node of a scan (360-3600 points). `process` will run it on
// hundreds of profiles per scan.

#include <benchmark/benchmark.h>

#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "characteristics/roundness.h"

namespace {

using arcwheel::characteristics::Association;

// An eccentric trace with lobes and 0.3 um of noise, as a wheel section looks.
void MakeTrace(int n, std::vector<double>& angle_deg, std::vector<double>& radius_mm) {
  std::mt19937 rng(1);
  std::normal_distribution<double> noise(0.0, 0.3e-3);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * i / n;
    angle_deg.push_back(360.0 * i / n);
    radius_mm.push_back(55.0 + 0.004 * std::cos(t - 0.3) + 0.001 * std::cos(3 * t) +
                        0.0005 * std::sin(17 * t) + noise(rng));
  }
}

void BM_Roundness(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const auto association = static_cast<Association>(state.range(1));
  std::vector<double> angle_deg, radius_mm;
  MakeTrace(n, angle_deg, radius_mm);
  for (auto _ : state) {
    benchmark::DoNotOptimize(arcwheel::characteristics::EvaluateRoundness(
        angle_deg, radius_mm, {.filter_cutoff_upr = 50.0, .association = association}));
  }
}
BENCHMARK(BM_Roundness)
    ->ArgsProduct({{360, 3600},
                   {static_cast<int>(Association::kLeastSquares), static_cast<int>(Association::kMinimumZone),
                    static_cast<int>(Association::kMaximumInscribed),
                    static_cast<int>(Association::kMinimumCircumscribed)}})
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
