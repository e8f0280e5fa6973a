// Speed of the frames stages: best-fit transforms (with leave-one-out outlier scoring), the
// force-sensor centre solve over a 30 s record, and whole-file transforms of programs.

#include <benchmark/benchmark.h>
#include <fmt/core.h>

#include <Eigen/Geometry>
#include <random>
#include <string>
#include <vector>

#include "frames/force_centre.h"
#include "frames/program_transform.h"
#include "frames/transform_fit.h"

namespace {

using namespace arcwheel::frames;

std::vector<PointPair> Pairs(int count) {
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> coordinate(-500.0, 500.0);
  std::normal_distribution<double> noise(0.0, 0.002);
  const Eigen::Matrix3d r = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  std::vector<PointPair> pairs(count);
  for (auto& p : pairs) {
    p.source_mm = {coordinate(rng), coordinate(rng), coordinate(rng)};
    p.target_mm =
        r * p.source_mm + Eigen::Vector3d(100, -50, 20) + Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  return pairs;
}

void BM_FitRigid3d(benchmark::State& state) {
  const auto pairs = Pairs(static_cast<int>(state.range(0)));
  for (auto _ : state) benchmark::DoNotOptimize(FitTransform(pairs, TransformModel::kRigid3d));
}
BENCHMARK(BM_FitRigid3d)->Arg(4)->Arg(10)->Arg(100)->Arg(1000)->Unit(benchmark::kMicrosecond);

void BM_FitSimilarity3dDroppingOutliers(benchmark::State& state) {
  auto pairs = Pairs(static_cast<int>(state.range(0)));
  pairs[3].target_mm.x() += 1.0;
  for (auto _ : state) {
    benchmark::DoNotOptimize(FitTransform(pairs, TransformModel::kSimilarity3d, {.drop_outliers = true}));
  }
}
BENCHMARK(BM_FitSimilarity3dDroppingOutliers)->Arg(10)->Arg(100)->Unit(benchmark::kMicrosecond);

void BM_SolveContactCentre30s(benchmark::State& state) {
  std::mt19937 rng(7);
  ForceSimulation simulation;
  simulation.centre_mm = {20.0, -10.0};
  const ForceRecord record = SimulateForceRecord(simulation, rng);  // 30 s at 1 kHz
  for (auto _ : state) benchmark::DoNotOptimize(SolveContactCentre(record, {.platform_height_mm = 20.0}));
}
BENCHMARK(BM_SolveContactCentre30s)->Unit(benchmark::kMicrosecond);

void BM_TransformGcode(benchmark::State& state) {
  std::string program = "G90 G21\nG0 X0 Y0 Z10\n";
  for (int i = 0; i < state.range(0); ++i)
    program += fmt::format("G1 X{:.4f} Y{:.4f} Z{:.4f} F800\n", 0.1 * i, 0.05 * i, 0.001 * i);
  Transform t;
  t.linear = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  t.translation_mm = {300, 100, -50};
  for (auto _ : state)
    benchmark::DoNotOptimize(TransformProgram(program, ProgramKind::kGcode, t, "bench.nc"));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_TransformGcode)->Arg(100000)->Unit(benchmark::kMillisecond);

void BM_TransformToolpathCsv(benchmark::State& state) {
  std::string csv = "xw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min\n";
  for (int i = 0; i < state.range(0); ++i) {
    csv +=
        fmt::format("{},{},{},{},{},{},0,0,1,1500\n", 0.1 * i, 0.05 * i, 50.0, 0.1 * i, 0.05 * i, 0.001 * i);
  }
  Transform t;
  t.linear = Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  for (auto _ : state)
    benchmark::DoNotOptimize(TransformProgram(csv, ProgramKind::kToolpathCsv, t, "bench.csv"));
  state.SetItemsProcessed(state.iterations() * state.range(0));
}
BENCHMARK(BM_TransformToolpathCsv)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
