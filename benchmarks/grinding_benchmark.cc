// Speed of the parallel-grinding toolpath and of the form-error prediction (issue: toolpath from
// the measured wheel). Targets on the 2-core build machine: the 430 x 430 mm trial part at 0.1 mm
// step-over and spacing (about 1.85e7 control points) under 5 s, a 1000 x 1000 map under 5 s.

#include <benchmark/benchmark.h>

#include <atomic>

#include "grinding/prediction.h"
#include "grinding/toolpath.h"
#include "grinding/toolpath_writer.h"
#include "surfaces/surface.h"

namespace {

using namespace arcwheel::grinding;
using arcwheel::surfaces::Aperture;
using arcwheel::surfaces::EvenAsphere;

const EvenAsphere& TrialPart() {  // method.md A.9
  static const EvenAsphere part(
      {.vertex_radius_mm = 4066.172723, .conic = -0.581986, .off_axis_x_mm = 300.0, .off_axis_y_mm = 300.0});
  return part;
}

Wheel PaperWheel() {
  return Wheel{.arc_radius_mm = 55.4423, .base_radius_mm = 200.0 - 55.4423, .half_width_mm = 10.0};
}

// The whole 430 x 430 mm trial part at 0.1 mm, without lead-in or lead-out, on two threads.
Aperture TrialPartAperture() { return {.width_x_mm = 430.0, .width_y_mm = 430.0}; }
ToolpathOptions TrialPartOptions(double gouge_check_spacing_mm) {
  return {.step_over_mm = 0.1,
          .point_spacing_mm = 0.1,
          .feed_mm_per_min = 6000.0,
          .lead_in_mm = 0.0,
          .lead_out_mm = 0.0,
          .gouge_check_spacing_mm = gouge_check_spacing_mm,
          .threads = 2};
}

// Control points of the whole part, counted as they stream out (nothing kept in memory).
// Argument: spacing of the global gouge checks, mm (the local check runs at every point).
void BM_TrialPartControlPoints(benchmark::State& state) {
  const Aperture aperture = TrialPartAperture();
  const ToolpathOptions options = TrialPartOptions(static_cast<double>(state.range(0)));
  long long points = 0;
  for (auto _ : state) {
    const ToolpathSummary s = GenerateToolpath(TrialPart(), aperture, PaperWheel(), options, {});
    points = s.control_points;
    benchmark::DoNotOptimize(points);
  }
  state.counters["control_points"] = static_cast<double>(points);
  state.counters["points_per_s"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_TrialPartControlPoints)
    ->Arg(10)
    ->Arg(2)
    ->Unit(benchmark::kSecond)
    ->Iterations(1)
    ->Repetitions(3)
    ->UseRealTime();

// The same with each row formatted as the CSV's text in the workers (what `arcwheel toolpath`
// writes; the text is dropped here so the disk does not enter the figure).
void BM_TrialPartCsvText(benchmark::State& state) {
  const Aperture aperture = TrialPartAperture();
  const ToolpathOptions options = TrialPartOptions(10.0);
  std::atomic<long long> bytes = 0;
  for (auto _ : state) {
    bytes = 0;
    (void)GenerateToolpath(
        TrialPart(), aperture, PaperWheel(), options,
        {.prepare =
             [](ToolpathRow& row) {
               row.text.resize(1);
               AppendCsvLines(row, 6000.0, row.text[0]);
             },
         .consume = [&bytes](ToolpathRow& row) { bytes += static_cast<long long>(row.text[0].size()); }});
  }
  state.counters["csv_bytes"] = static_cast<double>(bytes.load());
}
BENCHMARK(BM_TrialPartCsvText)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->UseRealTime();

// A 1000 x 1000 prediction map of the fig. 7 part with an arc-radius error and 2 um runout.
void BM_Prediction1000x1000(benchmark::State& state) {
  const EvenAsphere part({.vertex_radius_mm = 800.0, .conic = -2.2, .off_axis_x_mm = 300.0});
  const Aperture aperture{.width_x_mm = 200.0, .width_y_mm = 200.0};
  PredictionOptions options{.arc_radius_error_mm = 0.1,
                            .spindle_rpm = 1432.4,
                            .feed_mm_per_min = 6000.0,
                            .nodes_x = 1000,
                            .nodes_y = 1000,
                            .threads = 2};
  SetEccentricRunout(2.0, options);
  for (auto _ : state) {
    const FormPrediction p = PredictFormError(part, aperture, PaperWheel(), options);
    benchmark::DoNotOptimize(p.pv_um);
  }
}
BENCHMARK(BM_Prediction1000x1000)->Unit(benchmark::kSecond)->Iterations(1)->Repetitions(3)->UseRealTime();

}  // namespace

BENCHMARK_MAIN();
