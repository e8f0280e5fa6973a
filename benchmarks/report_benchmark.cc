// Rendering both wheel reports (HTML with inline SVG, and the A4 PDF) for a 360 x 2000 map, from
// reading summary.json and wheel_map.h5 to the renamed outputs, with the wheel model (as process
// writes by default) and without it (--no-model). Target: under 1 s.

#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>

#include "reports/report.h"
#include "reports/report_fixture.h"

namespace {

void WriteReports360x2000(benchmark::State& state, bool with_model) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / ("arcwheel-report-benchmark-" + std::to_string(::getpid()));
  arcwheel::reports::testing::WriteFixture(dir, {.n_phase = 360, .n_y = 2000, .with_model = with_model});
  arcwheel::reports::Tolerances tolerances;
  arcwheel::reports::AddToleranceFlag(tolerances, "max_runout_um=10");
  for (auto _ : state) {
    benchmark::DoNotOptimize(arcwheel::reports::WriteReports(dir, tolerances));
  }
  std::filesystem::remove_all(dir);
}

void BM_WriteReports360x2000(benchmark::State& state) { WriteReports360x2000(state, true); }
void BM_WriteReports360x2000WithoutModel(benchmark::State& state) { WriteReports360x2000(state, false); }
BENCHMARK(BM_WriteReports360x2000)->Unit(benchmark::kMillisecond)->Repetitions(5)->ReportAggregatesOnly(true);
BENCHMARK(BM_WriteReports360x2000WithoutModel)
    ->Unit(benchmark::kMillisecond)
    ->Repetitions(5)
    ->ReportAggregatesOnly(true);

}  // namespace

BENCHMARK_MAIN();
