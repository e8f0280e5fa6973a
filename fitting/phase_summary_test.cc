#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

#include "core/statistics.h"
#include "fitting/wheel_fit.h"

namespace arcwheel::fitting {
namespace {

PhaseFit Usable(double radius_mm, double axial_mm, double sigma_mm, double chi2, double arc_error_um) {
  PhaseFit fit;
  fit.usable = true;
  fit.arc_radius_mm = radius_mm;
  fit.center_axial_mm = axial_mm;
  fit.center_radial_mm = -axial_mm;
  fit.arc_radius_sigma_mm = sigma_mm;
  fit.chi2_per_dof = chi2;
  fit.arc_error_um = arc_error_um;
  return fit;
}

// Three usable phases and one flagged, figures worked by hand: radii 10.0, 10.2, 10.1 mm.
TEST(SummariseUsablePhases, GivesTheHeadlineFiguresOfTheUsablePhasesOnly) {
  WheelFit fit;
  fit.phases = {Usable(10.0, 1.0, 0.05, 1.0, 2.0), Usable(10.2, 3.0, 0.05, 3.0, 5.0), PhaseFit{},
                Usable(10.1, 2.0, 0.05, 2.0, 4.0)};
  fit.phases[2].arc_radius_mm = 99.0;  // not usable: must not count
  fit.phases[2].arc_error_um = 99.0;
  SummariseUsablePhases(fit);
  EXPECT_EQ(fit.usable_phases, 3);
  EXPECT_NEAR(fit.mean_arc_radius_mm, 10.1, 1e-12);
  EXPECT_NEAR(fit.mean_center_axial_mm, 2.0, 1e-12);
  EXPECT_NEAR(fit.mean_center_radial_mm, -2.0, 1e-12);
  EXPECT_NEAR(fit.arc_radius_range_mm, 0.2, 1e-12);
  EXPECT_NEAR(fit.arc_radius_fluctuation_pct, 0.2 / 10.1 * 100.0, 1e-10);
  EXPECT_NEAR(fit.center_axial_deviation_mm, 2.0, 1e-12);
  EXPECT_NEAR(fit.arc_radius_std_mm, 0.1, 1e-12);  // sqrt((0.01 + 0.01 + 0) / 2)
  EXPECT_NEAR(fit.arc_radius_noise_std_mm, 0.05, 1e-12);
  EXPECT_NEAR(fit.arc_radius_excess_std_mm, std::sqrt(0.01 - 0.0025), 1e-12);
  EXPECT_EQ(fit.median_chi2_per_dof, 2.0);
  EXPECT_EQ(fit.max_arc_error_um, 5.0);
  EXPECT_THAT(fit.warnings,
              ::testing::ElementsAre("1 of 4 phases were not usable and are left out of the means"));
}

TEST(Statistics, MeanAndMedianOfAFewValues) {
  EXPECT_EQ(Mean(std::vector<double>{1.0, 2.0, 6.0}), 3.0);
  EXPECT_EQ(Median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_EQ(Median({4.0, 1.0, 3.0, 2.0}), 3.0);  // the upper of the two middle values
  EXPECT_TRUE(std::isnan(Mean(std::vector<double>{})));
  EXPECT_TRUE(std::isnan(Median({})));
}

}  // namespace
}  // namespace arcwheel::fitting
