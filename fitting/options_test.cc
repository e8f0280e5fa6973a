// The fitting options report every violation at once, each named as `arcwheel process` spells it
// (a flag, or the field where there is no flag) and with the value given. The expected texts are
// spelled out here, from the flags in cli/command_process.cc.

#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing/testing.h"
#include "fitting/circle_fit.h"
#include "fitting/wheel_fit.h"
#include "processing/wheel_map.h"

namespace arcwheel::fitting {
namespace {

using Problems = std::vector<std::string>;

// The message of the Error{kInvalidOption} that `run` throws; fails the test if there is none.
std::string InvalidOptionMessage(const std::function<void()>& run) {
  return arcwheel::testing::ErrorMessageOf(run, ErrorCode::kInvalidOption);
}

TEST(WheelFitOptions, DefaultsHaveNoProblems) {
  EXPECT_EQ(WheelFitOptions{}.Problems(), Problems{});
  EXPECT_EQ(CircleFitOptions{}.Problems(), Problems{});
}

TEST(WheelFitOptions, ReportsEveryViolationWithItsValueNamedByTheFlag) {
  const WheelFitOptions bad{.band_half_width_mm = -8.0,
                            .min_points = 3,
                            .min_band_coverage = 1.5,
                            .min_phase_coverage = 0.0,
                            .circle = {.max_iterations = 0}};
  EXPECT_EQ(bad.Problems(),
            (Problems{"--band-half-width-mm = -8 violates > 0", "--min-points = 3 violates >= 4",
                      "min_band_coverage = 1.5 violates 0..1", "min_phase_coverage = 0 violates (0, 1]",
                      "circle.max_iterations = 0 violates >= 1"}));
}

TEST(FitWheel, RefusesTwoBadOptionsInOneErrorNamingBothWithTheirValues) {
  WheelFitOptions bad;
  bad.band_half_width_mm = 0.0;
  bad.min_points = 2;
  EXPECT_EQ(InvalidOptionMessage([&] { (void)FitWheel(processing::WheelMap{}, bad); }),
            "fitting: --band-half-width-mm = 0 violates > 0; --min-points = 2 violates >= 4");
}

TEST(FitCircle, RefusesAnInvalidIterationCountInsteadOfReportingNoConvergence) {
  const std::vector<double> x = {-1.0, 0.0, 1.0}, y = {0.0, 1.0, 0.0};
  EXPECT_EQ(InvalidOptionMessage([&] { (void)FitCircle(x, y, {}, {.max_iterations = -5}); }),
            "fitting.circle: max_iterations = -5 violates >= 1");
}

}  // namespace
}  // namespace arcwheel::fitting
