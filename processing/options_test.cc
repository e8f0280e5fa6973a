// The options of every processing step report every violation at once, each named as `arcwheel
// process` spells it (a flag, or a field of ProcessOptions where there is no flag) and with the
// value given. The expected texts are spelled out here, from the flags in cli/command_process.cc.

#include <gtest/gtest.h>

#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "acquisition/scan.h"
#include "core/error.h"
#include "core/testing/testing.h"
#include "processing/despike.h"
#include "processing/process_scan.h"
#include "processing/spindle_speed.h"
#include "processing/wheel_map.h"

namespace arcwheel::processing {
namespace {

using Problems = std::vector<std::string>;

// The message of the Error{kInvalidOption} that `run` throws; fails the test if there is none.
std::string InvalidOptionMessage(const std::function<void()>& run) {
  return arcwheel::testing::ErrorMessageOf(run, ErrorCode::kInvalidOption);
}

TEST(ProcessOptions, DefaultsHaveNoProblems) {
  EXPECT_EQ(ProcessOptions{}.Problems(), Problems{});
  EXPECT_EQ(DespikeOptions{}.Problems(), Problems{});
  EXPECT_EQ(MapOptions{}.Problems(), Problems{});
  EXPECT_EQ(SpindleSpeedOptions{}.Problems(), Problems{});
}

TEST(DespikeOptions, ReportsEveryViolationWithItsValueNamedByTheFlag) {
  const DespikeOptions bad{.window_half_width = 51,
                           .threshold_um = std::numeric_limits<double>::infinity(),
                           .threshold_sigmas = 0.0,
                           .min_threshold_um = -0.25};
  EXPECT_EQ(bad.Problems(),
            (Problems{"--despike-window = 51 violates 1..50", "--despike-sigmas = 0 violates > 0",
                      "despike.min_threshold_um = -0.25 violates >= 0",
                      "--despike-threshold-um = inf violates finite"}));
}

TEST(MapOptions, ReportsEveryViolationWithItsValueNamedByTheFlag) {
  const MapOptions bad{.phases = 3,
                       .knot_step_deg = 90.5,
                       .axial_step_mm = std::numeric_limits<double>::quiet_NaN(),
                       .min_support = 0,
                       .max_sigma_ratio = 0.5};
  EXPECT_EQ(bad.Problems(),
            (Problems{"--phases = 3 violates 4..36000", "--knot-step-deg = 90.5 violates finite and <= 90",
                      "--axial-step-mm = nan violates finite", "map.min_support = 0 violates >= 1",
                      "map.max_sigma_ratio = 0.5 violates >= 1"}));
}

TEST(SpindleSpeedOptions, ReportsEveryViolationWithItsValueNamedByItsField) {
  const SpindleSpeedOptions bad{.max_harmonic = 61,
                                .min_harmonic_snr = -1.0,
                                .min_harmonic_amplitude_um = std::numeric_limits<double>::quiet_NaN(),
                                .significance_sigmas = -3.0,
                                .iterations = -1};
  EXPECT_EQ(bad.Problems(), (Problems{"speed.max_harmonic = 61 violates 1..60",
                                      "speed.min_harmonic_snr = -1 violates finite and >= 0",
                                      "speed.min_harmonic_amplitude_um = nan violates finite and >= 0",
                                      "speed.significance_sigmas = -3 violates finite and >= 0",
                                      "speed.iterations = -1 violates >= 0"}));
}

TEST(ProcessOptions, ReportsItsOwnViolationsAfterThoseOfItsSteps) {
  ProcessOptions bad;
  bad.speed.max_harmonic = 0;
  bad.beam_offset_mm = std::numeric_limits<double>::infinity();
  bad.wheel_radius_mm = std::numeric_limits<double>::quiet_NaN();
  bad.stuck_run_deg = 361.0;
  EXPECT_EQ(bad.Problems(),
            (Problems{"speed.max_harmonic = 0 violates 1..60", "--beam-offset-mm = inf violates finite",
                      "--wheel-radius-mm = nan violates finite", "--stuck-run-deg = 361 violates 0..360"}));
}

TEST(ProcessScan, RefusesTwoBadOptionsInOneErrorNamingBothWithTheirValues) {
  ProcessOptions bad;
  bad.map.phases = 2;
  bad.despike.threshold_sigmas = -1.5;
  EXPECT_EQ(InvalidOptionMessage([&] { (void)ProcessScan(acquisition::Scan{}, bad); }),
            "processing: --despike-sigmas = -1.5 violates > 0; --phases = 2 violates 4..36000");
}

TEST(Despike, RefusesTwoBadOptionsInOneErrorBeforeTouchingTheData) {
  std::vector<double> z_mm = {0.0, 1.0, 0.0};
  EXPECT_EQ(InvalidOptionMessage(
                [&] { (void)Despike(z_mm, 0.001, {.window_half_width = 0, .min_threshold_um = -1.0}); }),
            "processing.despike: --despike-window = 0 violates 1..50; "
            "despike.min_threshold_um = -1 violates >= 0");
  EXPECT_EQ(z_mm, (std::vector<double>{0.0, 1.0, 0.0}));
}

TEST(EstimateSpindleSpeed, RefusesTwoBadOptionsInOneError) {
  const std::vector<double> z_mm;
  EXPECT_EQ(InvalidOptionMessage([&] {
              (void)EstimateSpindleSpeed(acquisition::Scan{}, z_mm, {.max_harmonic = 0, .iterations = -2});
            }),
            "processing.speed: speed.max_harmonic = 0 violates 1..60; speed.iterations = -2 violates >= 0");
}

}  // namespace
}  // namespace arcwheel::processing
