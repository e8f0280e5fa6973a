// Reading a scan: the same samples as the contract's CSV (formats.md 2.2: `z_mm,t_s`, decimal point)
// and as Micro-Epsilon sensorTOOL writes them (formats.md 2.4: header lines, `;`, decimal comma,
// CRLF, an epoch-time column the reader skips), with the settings the sensor's file lacks from a
// settings file. docs/benchmarks.md quotes the 1e7-sample figures: the sensorTOOL file must read in
// at most twice the contract CSV's time. Argument: samples. Wall time, the median of 3; the files
// are written once per process, into the temporary folder.

#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <random>
#include <string>

#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"

namespace {

namespace fs = std::filesystem;
using namespace arcwheel;

constexpr double kPeriodS = 1e-5;  // 100 kHz

struct Files {
  fs::path contract;
  fs::path sensortool;
  acquisition::ScanSettingsFile settings;
};

void Write(const fs::path& path, const std::string& text) {
  FILE* out = std::fopen(path.c_str(), "wb");
  std::fwrite(text.data(), 1, text.size(), out);
  std::fclose(out);
}

const Files& FilesWith(long samples) {
  static std::map<long, Files> cache;
  Files& files = cache[samples];
  if (!files.contract.empty()) return files;
  const double duration_s = static_cast<double>(samples) * kPeriodS;
  const double feed_mm_per_min = 22.0 / duration_s * 60.0;
  std::mt19937 rng(20261205);
  std::normal_distribution<double> noise(0.0, 0.3e-3);
  std::string contract =
      fmt::format("# spindle_rpm: 500\n# feed_mm_per_min: {:.17g}\n# sample_period_s: {}\nz_mm,t_s\n",
                  feed_mm_per_min, kPeriodS);
  std::string sensortool =
      "\xEF\xBB\xBFsensorTOOL;1.9.0\r\nSensor;ILD2300\r\nMeasuring rate;100 kHz\r\n"
      "Acquisition time;Epoch time (ms);Distance1 (mm)\r\n";
  contract.reserve(static_cast<std::size_t>(samples) * 22);
  sensortool.reserve(static_cast<std::size_t>(samples) * 40);
  for (long i = 0; i < samples; ++i) {
    const double t_s = static_cast<double>(i) * kPeriodS;
    const double z_mm = 0.5 * std::cos(t_s * 52.3) + noise(rng);
    const std::string z = fmt::format("{:.6f}", z_mm);
    const std::string t = fmt::format("{:.5f}", t_s);
    contract += z + "," + t + "\n";
    std::string line = fmt::format("{};{};{}\r\n", t, 1505296800000 + i / 100, z);
    std::replace(line.begin(), line.end(), '.', ',');
    sensortool += line;
  }
  const fs::path folder = fs::temp_directory_path();
  files.contract = folder / fmt::format("arcwheel-bench-read-{}.csv", samples);
  files.sensortool = folder / fmt::format("arcwheel-bench-read-{}-sensortool.csv", samples);
  Write(files.contract, contract);
  Write(files.sensortool, sensortool);
  files.settings = acquisition::ParseScanSettings(
      fmt::format(R"({{"spindle_rpm": 500, "feed_mm_per_min": {:.17g}}})", feed_mm_per_min), "settings.json");
  return files;
}

void BM_ReadContractCsv(benchmark::State& state) {
  const Files& files = FilesWith(state.range(0));
  for (auto _ : state) {
    const acquisition::Scan scan = acquisition::ReadScan(files.contract);
    benchmark::DoNotOptimize(scan.z_mm.data());
  }
  state.counters["MB"] = static_cast<double>(fs::file_size(files.contract)) / 1e6;
}

void BM_ReadSensorToolCsv(benchmark::State& state) {
  const Files& files = FilesWith(state.range(0));
  acquisition::ReadOptions options;
  options.settings = &files.settings;
  for (auto _ : state) {
    const acquisition::Scan scan = acquisition::ReadScan(files.sensortool, options);
    benchmark::DoNotOptimize(scan.z_mm.data());
  }
  state.counters["MB"] = static_cast<double>(fs::file_size(files.sensortool)) / 1e6;
}

BENCHMARK(BM_ReadContractCsv)
    ->Arg(1'000'000)
    ->Arg(10'000'000)
    ->ArgNames({"samples"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true)
    ->UseRealTime();
BENCHMARK(BM_ReadSensorToolCsv)
    ->Arg(1'000'000)
    ->Arg(10'000'000)
    ->ArgNames({"samples"})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly(true)
    ->UseRealTime();

}  // namespace
BENCHMARK_MAIN();
