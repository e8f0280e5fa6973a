// `process` of a line-profile scan (issue 47): the paper wheel scanned by a line profiler with 1600
// points a frame, 2000 frames a turn, 3 turns (9.6e6 readings), in the contract's HDF5 layout with
// its settings file, read, sectioned, fitted, its uncertainty evaluated and its outputs written, as
// `arcwheel process` does. docs/benchmarks.md quotes the figure (at most 1 s). Also the Gocator CSV
// of the same scan, whose reading is text parsing. Wall time, the median of 3; the files are written
// once per process, into the temporary folder.

#include <benchmark/benchmark.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "acquisition/profile_scan.h"
#include "acquisition/simulate.h"
#include "core/progress.h"
#include "workflows/process_pipeline.h"

namespace {

namespace fs = std::filesystem;
using namespace arcwheel;

fs::path Written(acquisition::ScanFormat format, const std::string& name) {
  static const acquisition::ProfileScan scan = [] {
    acquisition::ProfileScanSettings settings;  // 1600 x 2000 x 3 by default
    settings.noise_um = 1.0;
    settings.start_phase_deg = 0.05;
    return acquisition::SimulateProfileScan(acquisition::PaperTestWheel(), settings);
  }();
  const fs::path path = fs::temp_directory_path() / name;
  if (!fs::exists(path)) {
    acquisition::WriteProfileScan(scan, format, path);
    std::ofstream(path.string() + ".settings.json") << acquisition::ProfileScanSettingsJson(scan);
  }
  return path;
}

void Process(benchmark::State& state, acquisition::ScanFormat format, const std::string& name) {
  const fs::path path = Written(format, name);
  const fs::path outdir = fs::temp_directory_path() / ("arcwheel_bench_" + name + "_out");
  for (auto _ : state) {
    workflows::ProcessPipelineOptions options;
    options.scan_settings_path = path.string() + ".settings.json";
    Progress progress(false);
    const workflows::ProcessPipelineResult result =
        workflows::RunProcessPipeline(path.string(), outdir, options, progress);
    benchmark::DoNotOptimize(result.fit.mean_arc_radius_mm);
  }
  fs::remove_all(outdir);
}

void BM_ProcessProfileHdf5(benchmark::State& state) {
  Process(state, acquisition::ScanFormat::kProfileHdf5, "arcwheel_bench_profile.h5");
}
void BM_ProcessGocatorCsv(benchmark::State& state) {
  Process(state, acquisition::ScanFormat::kGocator, "arcwheel_bench_profile_gocator.csv");
}

BENCHMARK(BM_ProcessProfileHdf5)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly()
    ->UseRealTime();
BENCHMARK(BM_ProcessGocatorCsv)
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->ReportAggregatesOnly()
    ->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
