// The frames options report every violation at once, each named by the flag that sets it (or by
// its field where there is none) and with the value given. The expected texts are spelled out
// here, from the flags in cli/command_frame.cc, command_transform.cc and command_headcenter.cc.

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing/testing.h"
#include "frames/force_centre.h"
#include "frames/force_record_io.h"
#include "frames/program_transform.h"
#include "frames/three_point_frame.h"
#include "frames/transform_fit.h"

namespace arcwheel::frames {
namespace {

using Problems = std::vector<std::string>;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// The message of the Error{kInvalidOption} that `run` throws; fails the test if there is none.
std::string InvalidOptionMessage(const std::function<void()>& run) {
  return arcwheel::testing::ErrorMessageOf(run, ErrorCode::kInvalidOption);
}

TEST(FramesOptions, DefaultsHaveNoProblems) {
  EXPECT_EQ(ContactSolveOptions{}.Problems(), Problems{});
  EXPECT_EQ(ThreePointFrameOptions{}.Problems(), Problems{});
  EXPECT_EQ(PmacAxisOptions{}.Problems(), Problems{});
  EXPECT_EQ(TransformFitOptions{}.Problems(), Problems{});
  EXPECT_EQ(ProgramTransformOptions{}.Problems(), Problems{});
  EXPECT_EQ(ForceRecordReadOptions{}.Problems(), Problems{});
  EXPECT_EQ(ForceSimulation{}.Problems(), Problems{});
}

TEST(ContactSolveOptions, ReportsEveryViolationWithItsValueNamedByTheFlag) {
  const ContactSolveOptions bad{
      .platform_height_mm = kNan, .min_normal_force_fraction = 1.0, .min_normal_force_N = -2.0};
  EXPECT_EQ(bad.Problems(),
            (Problems{"--z0-mm = nan violates finite", "--min-force-fraction = 1 violates [0, 1)",
                      "--min-force-N = -2 violates >= 0"}));
  EXPECT_EQ(InvalidOptionMessage([&] { (void)SolveContactCentre(ForceRecord{}, bad); }),
            "frames.headcenter: --z0-mm = nan violates finite; --min-force-fraction = 1 violates [0, 1); "
            "--min-force-N = -2 violates >= 0");
}

TEST(ThreePointFrameOptions, RefusesBothBadValuesInOneError) {
  const ThreePointFrameOptions bad{.min_separation_mm = 0.0, .min_angle_deg = 90.0};
  EXPECT_EQ(
      InvalidOptionMessage([&] {
        (void)ThreePointFrame({0, 0, 0}, {100, 0, 0}, {0, 100, 0}, bad);
      }),
      "frames.three_point: --min-separation-mm = 0 violates > 0; --min-angle-deg = 90 violates (0, 90)");
}

TEST(PmacAxisOptions, RefusesEveryBadValueInOneError) {
  const PmacAxisOptions bad{
      .coordinate_system = 0, .motors = {1, 1, 3}, .counts_per_mm = {1000.0, 0.0, kNan}, .decimals = 13};
  EXPECT_EQ(
      InvalidOptionMessage([&] { (void)PmacAxisDefinitions(Transform{}, bad); }),
      "frames.pmac: --coordinate-system = 0 violates >= 1; --motors = 1,1,3 violates distinct and >= 1; "
      "--counts-per-mm = 1000,0,nan violates finite and non-zero; --pmac-decimals = 13 violates [0, 12]");
}

TEST(TransformFitOptions, RefusesBothBadValuesInOneError) {
  const TransformFitOptions bad{.outlier_threshold = -3.0, .degenerate_ratio = 1.0};
  EXPECT_EQ(
      InvalidOptionMessage([&] { (void)FitTransform({}, TransformModel::kRigid3d, bad); }),
      "frames.transform_fit: --outlier-threshold = -3 violates > 0; degenerate_ratio = 1 violates (0, 1)");
}

TEST(ProgramTransformOptions, RefusesDecimalsOutOfRangeWithTheValue) {
  EXPECT_EQ(ProgramTransformOptions{.decimals = 0}.Problems(),
            Problems{"--decimals = 0 violates -1 or [1, 12]"});
  EXPECT_EQ(InvalidOptionMessage([&] {
              (void)TransformProgram("G0 X1\n", ProgramKind::kGcode, Transform{}, "a.nc", {.decimals = 13});
            }),
            "frames.program_transform: --decimals = 13 violates -1 or [1, 12]");
}

TEST(ForceRecordReadOptions, RefusesBothUnknownUnitsInOneErrorBeforeReading) {
  const ForceRecordReadOptions bad{.force_unit = "lbf", .moment_unit = "Nm2"};
  EXPECT_EQ(
      InvalidOptionMessage([&] { (void)ReadForceRecord("no such file.csv", bad); }),
      "frames.force_record: --force-unit = 'lbf' violates N or kN; --moment-unit = 'Nm2' violates Nmm or Nm");
}

TEST(ForceSimulation, ReportsEveryViolationWithItsValueNamedByTheFlag) {
  ForceSimulation bad;
  bad.centre_mm = {kNan, 1.0};
  bad.platform_height_mm = std::numeric_limits<double>::infinity();
  bad.duration_s = 0.0;
  bad.sample_rate_hz = -1.0;
  bad.normal_force_N = -30.0;
  bad.noise_fraction = -0.1;
  EXPECT_EQ(bad.Problems(),
            (Problems{"--centre-mm = nan,1 violates finite", "--z0-mm = inf violates finite",
                      "--duration-s = 0 violates finite and > 0", "--rate-hz = -1 violates finite and > 0",
                      "--normal-force-N = -30 violates finite and >= 0",
                      "--noise = -0.1 violates finite and >= 0"}));
  // With both valid, their product must give 1 .. 1e8 samples.
  ForceSimulation too_long;
  too_long.duration_s = 1e6;
  EXPECT_EQ(too_long.Problems(), Problems{"--duration-s * --rate-hz = 1000000000 samples violates 1 .. 1e8"});
  ForceSimulation too_short;
  too_short.duration_s = 0.5;
  too_short.sample_rate_hz = 1.0;
  std::mt19937 rng(1);
  EXPECT_EQ(InvalidOptionMessage([&] { (void)SimulateUnloadedRecord(too_short, rng); }),
            "frames.headcenter: --duration-s * --rate-hz = 0.5 samples violates 1 .. 1e8");
}

}  // namespace
}  // namespace arcwheel::frames
