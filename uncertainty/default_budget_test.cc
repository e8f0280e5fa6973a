// The default budget's contributions against hand computations for the paper's wheel
// (Ra = 55.4423 mm, band +-8 mm, wheel radius 200 mm; docs/uncertainty.md).

#include "uncertainty/default_budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <nlohmann/json.hpp>

#include "core/testing/testing.h"

namespace arcwheel::uncertainty {
namespace {

// u_i(y) = |c_i| u(x_i) of each input of `quantity` at the measured `value`.
std::map<std::string, double> Contributions(const BudgetFile& budget, const std::string& quantity,
                                            double value) {
  std::map<std::string, double> out;
  for (const Input& input : ResolveInputs(budget.quantities.at(quantity), value))
    out[input.name] = std::abs(input.sensitivity) * StandardUncertainty(input);
  return out;
}

TEST(DefaultBudget, GivesTheHandComputedContributionsForThePapersWheel) {
  const BudgetFile budget = DefaultBudget({});
  // Sagitta of the band: 8^2 / (2 x 55.4423) = 0.57718 mm.
  EXPECT_NEAR(BandSagittaMm({}), 0.5771766, 1e-7);
  const auto radius = Contributions(budget, "mean_arc_radius_mm", 55.4423);
  // Gain: 55.4423 mm x 200e-6 / sqrt(3).
  EXPECT_NEAR(radius.at("sensor_scale"), 0.006401925, 1e-9);
  // Bow 1.2 um x (0.57718 / 6)^2 = 0.011104 um, times Ra / s = 96.058, over sqrt(3).
  EXPECT_NEAR(radius.at("sensor_linearity"), 0.0006158403, 1e-10);
  // Axial: 1 um over 16 mm = 62.5 ppm, twice, of 55.4423 mm, over sqrt(3).
  EXPECT_NEAR(radius.at("axial_scale"), 0.004001203, 1e-9);
  // 11.5e-6/K x 55.4423 mm = 0.64 um/K (the "about 0.6 um per kelvin"), +-2 K.
  EXPECT_NEAR(radius.at("wheel_temperature"), 0.0007362214, 1e-10);
  // 55.4423 x 0.1^2 / (2 x 200^2) = 6.93 nm, over sqrt(3).
  EXPECT_NEAR(radius.at("beam_offset"), 4.001203e-6, 1e-12);

  // Relative inputs scale with the value: a 4 um runout, 200 ppm gain.
  const auto runout = Contributions(budget, "max_runout_um", 4.0);
  EXPECT_NEAR(runout.at("sensor_scale"), 4.0 * 200e-6 / std::sqrt(3.0), 1e-15);
  EXPECT_NEAR(runout.at("resolution"), 0.005 / std::sqrt(3.0), 1e-15);
  // The range of Ra(c): the gain once and the axial scale twice.
  const auto range = Contributions(budget, "arc_radius_range_mm", 0.01);
  EXPECT_NEAR(range.at("axial_scale"), 0.01 * 2 * 62.5e-6 / std::sqrt(3.0), 1e-15);
  EXPECT_TRUE(budget.quantities.at("arc_radius_fluctuation_pct").empty());
}

TEST(DefaultBudget, SurvivesTheBudgetFileRoundTrip) {
  const BudgetFile budget = DefaultBudget({.arc_radius_mm = 40.0, .band_half_width_mm = 6.0});
  const BudgetFile again = ParseBudget(BudgetToJson(budget).dump(), "default.json");
  for (const auto& [quantity, inputs] : budget.quantities) {
    const auto a = Contributions(budget, quantity, 2.5);
    const auto b = Contributions(again, quantity, 2.5);
    ASSERT_EQ(a.size(), b.size()) << quantity;
    for (const auto& [name, u] : a) EXPECT_NEAR(b.at(name), u, 1e-15 + 1e-12 * u) << quantity << "." << name;
  }
}

TEST(DefaultBudget, RefusesBadOptionsNamingEach) {
  const std::string message = arcwheel::testing::ErrorMessageOf(
      [] { (void)DefaultBudget({.band_half_width_mm = 80.0}, {.scale_ppm = -1.0}); },
      ErrorCode::kInvalidOption);
  EXPECT_EQ(message,
            "uncertainty.budget: WheelGeometry::band_half_width_mm = 80 violates > 0 and < arc_radius_mm; "
            "SensorBudgetOptions::scale_ppm = -1 violates >= 0");
}

}  // namespace
}  // namespace arcwheel::uncertainty
