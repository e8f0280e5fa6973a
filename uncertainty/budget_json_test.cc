// The budget file: units converted to the quantity's, sensitivities resolved, every problem of a
// bad file named at once.

#include "uncertainty/budget_json.h"

#include <gtest/gtest.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <string>

#include "core/testing/testing.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kGood = R"({
  "coverage_probability": 0.99,
  "quantities": {
    "mean_arc_radius_mm": [
      {"name": "axial_scale", "source": "Y axis", "unit": "ppm", "distribution": "rectangular",
       "half_width": 60, "sensitivity": 1.1e-4, "sensitivity_unit": "mm/ppm"},
      {"name": "temperature", "source": "shop", "unit": "K", "distribution": "rectangular",
       "half_width": 2, "sensitivity": 0.6, "sensitivity_unit": "um/K"},
      {"name": "reference", "source": "certificate", "unit": "um", "distribution": "normal",
       "expanded": 3, "k": 2, "dof": 12, "value": 0.5}],
    "max_runout_um": [
      {"name": "sensor_scale", "source": "certificate", "unit": "%", "distribution": "triangular",
       "half_width": 0.1, "sensitivity": "relative"},
      {"name": "resolution", "source": "data sheet", "unit": "nm", "distribution": "rectangular",
       "half_width": 5}]}})";

TEST(ParseBudget, ConvertsEveryInputToItsQuantitysUnit) {
  const BudgetFile budget = ParseBudget(kGood, "budget.json");
  EXPECT_DOUBLE_EQ(budget.combine.coverage_probability, 0.99);
  const std::vector<Input> radius = ResolveInputs(budget.quantities.at("mean_arc_radius_mm"), 55.0);
  ASSERT_EQ(radius.size(), 3u);
  // 60 ppm rectangular at 1.1e-4 mm/ppm: 60 * 1.1e-4 / sqrt(3) mm.
  EXPECT_NEAR(std::abs(radius[0].sensitivity) * StandardUncertainty(radius[0]), 60 * 1.1e-4 / std::sqrt(3.0),
              1e-15);
  // 2 K at 0.6 um/K = 1.2 um = 0.0012 mm half-width.
  EXPECT_NEAR(radius[1].sensitivity * StandardUncertainty(radius[1]), 0.0012 / std::sqrt(3.0), 1e-15);
  // 3 um at k = 2 = 0.0015 mm; the 0.5 um correction is 0.0005 mm.
  EXPECT_NEAR(radius[2].sensitivity * StandardUncertainty(radius[2]), 0.0015, 1e-15);
  EXPECT_NEAR(radius[2].sensitivity * radius[2].value, 0.0005, 1e-15);
  EXPECT_EQ(radius[2].dof, 12.0);

  // A relative 0.1 % on a 4 um runout: 0.004 um half-width, triangular.
  const std::vector<Input> runout = ResolveInputs(budget.quantities.at("max_runout_um"), 4.0);
  EXPECT_NEAR(runout[0].sensitivity * StandardUncertainty(runout[0]), 0.004 / std::sqrt(6.0), 1e-15);
  EXPECT_NEAR(runout[1].sensitivity * StandardUncertainty(runout[1]), 0.005 / std::sqrt(3.0), 1e-15);
}

TEST(ParseBudget, ReadsWhatBudgetToJsonWrites) {
  const BudgetFile budget = ParseBudget(kGood, "budget.json");
  const BudgetFile again = ParseBudget(BudgetToJson(budget).dump(), "again.json");
  for (const auto& [quantity, inputs] : budget.quantities) {
    const std::vector<Input> a = ResolveInputs(inputs, 3.0);
    const std::vector<Input> b = ResolveInputs(again.quantities.at(quantity), 3.0);
    ASSERT_EQ(a.size(), b.size());
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_EQ(a[i].name, b[i].name);
      EXPECT_DOUBLE_EQ(a[i].sensitivity * StandardUncertainty(a[i]),
                       b[i].sensitivity * StandardUncertainty(b[i]));
      EXPECT_DOUBLE_EQ(a[i].sensitivity * a[i].value, b[i].sensitivity * b[i].value);
    }
  }
}

TEST(ParseBudget, RefusesABadFileNamingEveryProblem) {
  const char* bad = R"({"coverage_probability": 1.5, "quantities": {
    "mean_arc_radius_mm": [
      {"name": "scale", "unit": "ppm", "distribution": "rectangular", "half_width": -3,
       "sensitivity": 1, "sensitivity_unit": "mm/ppm"},
      {"name": "temp", "unit": "K", "distribution": "rectangular", "half_width": 1},
      {"name": "gauss", "unit": "um", "distribution": "gaussian", "sigma": 1}],
    "max_runout_um": [
      {"name": "res", "unit": "um", "distribution": "normal", "sigma": -0.5}],
    "max_wear_um": []}})";
  const std::string message = arcwheel::testing::ErrorMessageOf(
      [&] { (void)ParseBudget(bad, "budget.json"); }, ErrorCode::kInvalidOption);
  for (const char* expected :
       {"coverage_probability = 1.5 violates (0, 1)",
        "mean_arc_radius_mm.scale.half_width = -3 violates a finite number >= 0",
        "mean_arc_radius_mm.temp.unit = 'K' violates a unit of mean_arc_radius_mm (mm) or a sensitivity_unit "
        "'mm/K'",
        "mean_arc_radius_mm.gauss.distribution = 'gaussian' violates one of normal, rectangular, triangular, "
        "arcsine",
        "max_runout_um.res.sigma = -0.5 violates a finite number >= 0",
        "quantities.max_wear_um = [] violates a headline quantity"}) {
    EXPECT_NE(message.find(expected), std::string::npos) << expected << "\nnot in\n" << message;
  }
}

TEST(ParseBudget, RefusesANonFiniteNumberThatJsonCannotHold) {
  // 1e999 is not a double (JSON has no NaN or infinity): refused as a bad option file, by name.
  const std::string message = arcwheel::testing::ErrorMessageOf(
      [&] { (void)ParseBudget(R"({"quantities": {"max_runout_um": [{"sigma": 1e999}]}})", "b.json"); },
      ErrorCode::kInvalidOption);
  EXPECT_NE(message.find("'b.json'"), std::string::npos) << message;
  EXPECT_NE(message.find("1e999"), std::string::npos) << message;
}

TEST(ParseBudget, RefusesAWrongSensitivityUnitAndARelativeLength) {
  const char* bad = R"({"quantities": {"max_arc_error_um": [
      {"name": "a", "unit": "K", "distribution": "rectangular", "half_width": 1, "sensitivity": 2,
       "sensitivity_unit": "um/deg"},
      {"name": "b", "unit": "um", "distribution": "rectangular", "half_width": 1, "sensitivity": "relative"}]}})";
  const std::string message =
      arcwheel::testing::ErrorMessageOf([&] { (void)ParseBudget(bad, "b.json"); }, ErrorCode::kInvalidOption);
  EXPECT_NE(message.find("max_arc_error_um.a.sensitivity_unit = 'um/deg' violates 'um/K'"), std::string::npos)
      << message;
  EXPECT_NE(message.find("max_arc_error_um.b.unit = 'um' violates 1, ppm or % for a relative sensitivity"),
            std::string::npos)
      << message;
}

}  // namespace
}  // namespace arcwheel::uncertainty
