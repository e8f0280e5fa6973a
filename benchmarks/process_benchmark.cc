// Stages of `process` in-process: the wheel model's fit, the despiker, and the mean arc radius
// against the simulated truth at sizes beyond the test suite. `process` end to end, with its wall
// time and peak memory, is timed by benchmarks/process_bench.sh on the binary itself.

#include <benchmark/benchmark.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "acquisition/scan_reader.h"
#include "acquisition/simulate.h"
#include "fitting/wheel_fit.h"
#include "fitting/wheel_model.h"
#include "processing/despike.h"
#include "processing/helix_geometry.h"
#include "processing/process_scan.h"

namespace {

namespace fs = std::filesystem;
using namespace arcwheel;

// A 500 rpm scan of the paper's wheel with 10 us samples; the feed sets the sample count.
const fs::path& ScanWithSamples(double samples) {
  static std::map<double, fs::path> cache;
  auto& path = cache[samples];
  if (path.empty()) {
    path =
        fs::temp_directory_path() / ("arcwheel-bench-" + std::to_string(static_cast<long>(samples)) + ".h5");
    acquisition::WheelModel wheel;
    wheel.radial_harmonics_um = {{1, 3.0, 40.0}, {3, 0.8, 15.0}};
    acquisition::ScanSettings settings;
    settings.sample_period_s = 10e-6;
    settings.noise_um = 0.3;
    settings.spike_rate = 1e-5;
    const double duration_s = samples * settings.sample_period_s;
    settings.feed_mm_per_min = (settings.end_y_mm - settings.start_y_mm) / duration_s * 60.0;
    const auto simulated = acquisition::SimulateScan(wheel, settings);
    acquisition::WriteHdf5Scan(simulated.scan, true, path.string());
  }
  return path;
}

// The wheel model's fit alone (fitting/wheel_model.h), on a scan already processed and fitted per
// phase, with the knots chosen from the data as `process` does. Arguments: samples; 1 to read
// them as float32 (as a float32 file holds them), 0 as double; the method: 2 as `process` fits
// (binned above WheelModelOptions::binned_above_samples), 1 every sample with the warm-up on a
// subsample, 0 every Gauss-Newton iteration over every sample. Wall time (the median of 5) and
// the CPU time of the whole process; the scans are made once per process.
struct ModelInput {
  acquisition::Scan scan;
  processing::ProcessedScan processed;
  fitting::WheelFit fit;
  std::vector<float> z_float;
};

const ModelInput& ModelInputWith(long samples) {
  static std::map<long, std::unique_ptr<ModelInput>> cache;
  auto& input = cache[samples];
  if (input == nullptr) {
    input = std::make_unique<ModelInput>();
    input->scan = acquisition::ReadScan(ScanWithSamples(static_cast<double>(samples)));
    input->processed = processing::ProcessScanInPlace(input->scan, {});
    input->fit = fitting::FitWheel(input->processed.map, {});
    input->z_float.assign(input->scan.z_mm.begin(), input->scan.z_mm.end());
  }
  return *input;
}

void BM_WheelModel(benchmark::State& state) {
  const ModelInput& input = ModelInputWith(static_cast<long>(state.range(0)));
  const processing::HelixGeometry geometry(input.scan, input.processed.rpm_used);
  fitting::WheelModelOptions options;
  if (state.range(2) < 2) options.binned_above_samples = std::numeric_limits<std::size_t>::max();
  if (state.range(2) == 0) options.warm_start_samples = 0;
  fitting::WheelModel model;
  for (auto _ : state) {
    model = state.range(1) == 1
                ? fitting::FitWheelModel(input.z_float, geometry, input.processed.map, input.fit, options)
                : fitting::FitWheelModel(input.scan.z_mm, geometry, input.processed.map, input.fit, options);
  }
  state.counters["samples_in_band"] = static_cast<double>(model.samples);
  state.counters["iterations"] = model.iterations;
  state.counters["knots_Ra_a_b"] = model.radius_knots * 10000 + model.axial_knots * 100 + model.runout_knots;
}
BENCHMARK(BM_WheelModel)
    ->Args({1'000'000, 0, 2})
    ->Args({1'000'000, 1, 2})
    ->Args({1'000'000, 0, 1})
    ->Args({10'000'000, 0, 2})
    ->Args({10'000'000, 1, 2})
    ->Args({10'000'000, 1, 1})
    ->Args({100'000'000, 1, 2})
    ->Args({100'000'000, 1, 1})
    ->ArgNames({"samples", "float32", "method"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->MeasureProcessCPUTime()
    ->UseRealTime();

// Heights along the helix of a 500 rpm scan with 10 us samples (12000 a turn), in mm: the sag of a
// 40 mm arc as the sensor crosses 20 mm of it, 3 um of first-order runout and 0.3 um of white
// noise, with isolated spikes (1e-4 of the samples, 5-200 um up or down), bursts of 2-6 spiked
// samples (1e-5) and dropouts of up to 40 samples (1e-5, NaN). Made once per size.
template <typename T>
const std::vector<T>& SpikedArcHeights(std::size_t samples) {
  static std::map<std::size_t, std::vector<T>> cache;
  std::vector<T>& z = cache[samples];
  if (!z.empty()) return z;
  z.resize(samples);
  std::mt19937_64 rng(14);
  std::normal_distribution<double> noise_mm(0.0, 0.3e-3);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const auto n = static_cast<double>(samples);
  for (std::size_t i = 0; i < samples; ++i) {
    const auto at = static_cast<double>(i);
    const double across_mm = -10.0 + 20.0 * at / n;
    const double height_mm = std::sqrt(40.0 * 40.0 - across_mm * across_mm) - 35.0 +
                             0.003 * std::sin(2.0 * std::numbers::pi * at / 12000.0) + noise_mm(rng);
    z[i] = static_cast<T>(height_mm);
  }
  for (std::size_t i = 0; i < samples;) {  // i: the first sample not yet damaged or passed
    const double u = unit(rng);
    const double spike_mm = (unit(rng) < 0.5 ? -1.0 : 1.0) * (0.005 + 0.195 * unit(rng));
    std::size_t spiked = 0, gap = 0;
    if (u < 1e-4) spiked = 1;
    if (u >= 1e-4 && u < 1.1e-4) spiked = 2 + static_cast<std::size_t>(5.0 * unit(rng));
    if (u >= 1.1e-4 && u < 1.2e-4) gap = 1 + static_cast<std::size_t>(40.0 * unit(rng));
    for (std::size_t k = 0; k < spiked && i < samples; ++k, ++i) z[i] = static_cast<T>(z[i] + spike_mm);
    for (std::size_t k = 0; k < gap && i < samples; ++k, ++i) z[i] = std::numeric_limits<T>::quiet_NaN();
    if (spiked + gap == 0) ++i;
  }
  return z;
}

// The median despiker (default options, 6 sigma = 1.8 um) on the spiked arc above. Counters:
// time_per_sample_core is wall time x 2 workers / samples; cpu_ns_per_sample is the CPU time of
// all threads per sample, which a busy machine inflates less than wall time.
template <typename T>
void BM_Despike(benchmark::State& state) {
  const auto samples = static_cast<std::size_t>(state.range(0));
  const std::vector<T>& spiked = SpikedArcHeights<T>(samples);
  std::vector<T> z(samples);
  std::size_t rejected = 0;
  double cpu_s = 0.0;
  for (auto _ : state) {
    state.PauseTiming();
    std::copy(spiked.begin(), spiked.end(), z.begin());
    state.ResumeTiming();
    const std::clock_t start = std::clock();  // the process's CPU time, all threads
    rejected = processing::Despike(std::span<T>(z), 0.3e-3, {}).rejected;
    cpu_s += static_cast<double>(std::clock() - start) / CLOCKS_PER_SEC;
  }
  const double judged = static_cast<double>(samples) * static_cast<double>(state.iterations());
  state.counters["rejected"] = static_cast<double>(rejected);
  state.counters["cpu_ns_per_sample"] = cpu_s / judged * 1e9;
  state.counters["time_per_sample_core"] =
      benchmark::Counter(static_cast<double>(samples) / 2.0,
                         benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_Despike<float>)
    ->Arg(1'000'000)
    ->Arg(10'000'000)
    ->Arg(100'000'000)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();
BENCHMARK(BM_Despike<double>)
    ->Arg(10'000'000)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

// Not a speed figure: the error of the mean arc radius against the simulated truth, in reported
// sigmas, at sizes beyond what the test suite runs (issue "Real-world scans", point 5). One
// iteration each; the counters carry the figures.
void BM_MeanRadiusAgainstTruth(benchmark::State& state) {
  const acquisition::WheelModel wheel = acquisition::LobedTestWheel();
  acquisition::ScanSettings settings;
  settings.noise_um = 0.5;
  const auto samples = static_cast<double>(state.range(0));
  settings.feed_mm_per_min =
      (settings.end_y_mm - settings.start_y_mm) / (samples * settings.sample_period_s) * 60.0;
  settings.spindle_rpm_true =
      state.range(1) != 0 ? 1.002 * settings.spindle_rpm_nominal : settings.spindle_rpm_nominal;
  settings.write_encoder = state.range(1) == 1;
  double error_um = 0.0, sigma_um = 0.0;
  for (auto _ : state) {
    const auto simulated = acquisition::SimulateScan(wheel, settings);
    const auto processed = processing::ProcessScan(simulated.scan, {});
    const auto fit = fitting::FitWheel(processed.map, {});
    error_um = (fit.mean_arc_radius_mm - wheel.arc_radius_mm) * 1000.0;
    sigma_um = fit.mean_arc_radius_sigma_mm * 1000.0;
  }
  state.counters["error_um"] = error_um;
  state.counters["sigma_um"] = sigma_um;
  state.counters["z"] = error_um / sigma_um;
}

// Second argument: 0 nominal speed, 1 encoder with the spindle 0.2 % fast, 2 the same without encoder.
BENCHMARK(BM_MeanRadiusAgainstTruth)
    ->ArgsProduct({{100'000'000}, {0, 1, 2}})
    ->Iterations(1)
    ->Unit(benchmark::kSecond)
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
