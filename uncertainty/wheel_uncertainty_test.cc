// The wheel's uncertainty on observations of known truth: a second-harmonic arc radius, an
// eccentric map, and a budget whose combination is worked by hand.

#include "uncertainty/wheel_uncertainty.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <vector>

#include "core/testing/testing.h"

namespace arcwheel::uncertainty {
namespace {

struct Wheel {
  std::vector<double> radius, radius_sigma, axial, axial_sigma, radial, rho, y;
  std::vector<char> usable;
  WheelObservations observations;
};

// 360 phases; Ra(c) = 55 + 0.004 cos 2c mm with per-phase noise 1 um; a(c) = 0; the map over
// y in [-8, 8] mm is a circle section plus a 3 um eccentricity (runout 6 um) and noise 0.1 um.
Wheel MakeWheel(unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  Wheel w;
  const int phases = 360, ny = 41;
  for (int j = 0; j < ny; ++j) w.y.push_back(-8.0 + 0.4 * j);
  for (int p = 0; p < phases; ++p) {
    const double c = 2.0 * std::numbers::pi * p / phases;
    w.radius.push_back(55.0 + 0.004 * std::cos(2 * c) + 0.001 * noise(rng));
    w.radius_sigma.push_back(0.001);
    w.axial.push_back(0.0001 * noise(rng));
    w.axial_sigma.push_back(0.0001);
    w.radial.push_back(-55.0);
    w.usable.push_back(1);
    for (int j = 0; j < ny; ++j)
      w.rho.push_back(-55.0 + std::sqrt(55.0 * 55.0 - w.y[j] * w.y[j]) + 0.003 * std::cos(c) +
                      1e-4 * noise(rng));
  }
  w.observations = {.mean_arc_radius_mm = 55.0,
                    .mean_arc_radius_sigma_mm = 0.0003,
                    .arc_radius_range_mm = 0.0,
                    .arc_radius_fluctuation_pct = 0.0,
                    .center_axial_deviation_mm = 0.0,
                    .max_arc_error_um = 0.0,
                    .max_runout_um = 0.0,
                    .max_roundness_um = 0.0,
                    .arc_radius_mm = w.radius,
                    .arc_radius_sigma_mm = w.radius_sigma,
                    .center_axial_mm = w.axial,
                    .center_axial_sigma_mm = w.axial_sigma,
                    .center_radial_mm = w.radial,
                    .usable = w.usable,
                    .rho_mm = w.rho,
                    .y_mm = w.y,
                    .map_sigma_mm = 1e-4,
                    .band_low_mm = -8.0,
                    .band_high_mm = 8.0};
  return w;
}

TEST(EvaluateWheelUncertainty, CombinesTheFitsSigmaWithTheBudgetByHand) {
  const Wheel wheel = MakeWheel(7);
  BudgetFile budget;
  budget.quantities["mean_arc_radius_mm"] = {{.input = {.name = "scale",
                                                        .unit = "mm",
                                                        .distribution = Distribution::kRectangular,
                                                        .spread = 0.0004 * std::sqrt(3.0)}}};
  const WheelUncertainty u = EvaluateWheelUncertainty(wheel.observations, budget);
  const QuantityUncertainty* radius = u.Find("mean_arc_radius_mm");
  ASSERT_NE(radius, nullptr);
  // sqrt(0.0003^2 + 0.0004^2) = 0.0005 mm; both exact (infinite dof): k = 1.960.
  EXPECT_NEAR(radius->combined.standard_uncertainty, 0.0005, 1e-15);
  EXPECT_NEAR(radius->combined.expanded, 1.959964 * 0.0005, 1e-9);
  EXPECT_EQ(radius->value, 55.0);
}

TEST(EvaluateWheelUncertainty, RecoversThePeakToValleyTruths) {
  const Wheel wheel = MakeWheel(11);
  const WheelUncertainty u = EvaluateWheelUncertainty(wheel.observations, {});
  const auto near_truth = [&](const char* key, double truth) {
    const QuantityUncertainty* q = u.Find(key);
    ASSERT_NE(q, nullptr);
    EXPECT_NEAR(q->value, truth, 3.0 * q->combined.standard_uncertainty + 1e-12) << key;
    EXPECT_GT(q->combined.standard_uncertainty, 0.0) << key;
  };
  near_truth("arc_radius_range_mm", 0.008);
  near_truth("arc_radius_fluctuation_pct", 0.008 / 55.0 * 100.0);
  near_truth("max_runout_um", 6.0);
  // Roundness leaves out the first harmonic: nothing is left but noise.
  EXPECT_NEAR(u.Find("max_roundness_um")->value, 0.0, 0.02);
}

TEST(WheelUncertaintyToJson, SpellsTheSchemasKeys) {
  const Wheel wheel = MakeWheel(3);
  const nlohmann::json j = WheelUncertaintyToJson(EvaluateWheelUncertainty(wheel.observations, {}));
  const nlohmann::json& radius = j.at("quantities").at("mean_arc_radius_mm");
  for (const char* key : {"measured", "value", "u_c", "nu_eff", "k", "U", "contributions", "unit"})
    EXPECT_TRUE(radius.contains(key)) << key;
  EXPECT_TRUE(j.at("quantities").at("max_runout_um").contains("noise_bias"));
  EXPECT_EQ(j.at("coverage_probability"), 0.95);
}

}  // namespace
}  // namespace arcwheel::uncertainty
