// The budget arithmetic against closed forms and against the worked example of JCGM 100:2008
// (GUM) annex H.1, the calibration of an end gauge, to the digits the GUM prints.

#include "uncertainty/budget.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "core/number_format.h"
#include "core/testing/testing.h"

namespace arcwheel::uncertainty {
namespace {

TEST(StandardUncertainty, FollowsEachDistributionsClosedForm) {
  // GUM 4.3.7 (a / sqrt 3), 4.3.9 (a / sqrt 6), H.1.3.2 (a / sqrt 2), 4.3.3 (U / k).
  EXPECT_DOUBLE_EQ(
      StandardUncertainty({.distribution = Distribution::kRectangular, .spread = std::sqrt(3.0)}), 1.0);
  EXPECT_DOUBLE_EQ(StandardUncertainty({.distribution = Distribution::kTriangular, .spread = std::sqrt(6.0)}),
                   1.0);
  EXPECT_DOUBLE_EQ(StandardUncertainty({.distribution = Distribution::kArcsine, .spread = std::sqrt(2.0)}),
                   1.0);
  EXPECT_DOUBLE_EQ(
      StandardUncertainty({.distribution = Distribution::kNormal, .spread = 3.0, .coverage_factor = 2.0}),
      1.5);
}

TEST(TypeAFromReadings, IsTheMeanWithSOverRootNAndNMinusOneDof) {
  const std::vector<double> readings = {1.0, 2.0, 3.0, 4.0, 5.0};  // s^2 = 10 / 4
  const Input input = TypeAFromReadings("x", "um", readings);
  EXPECT_DOUBLE_EQ(input.value, 3.0);
  EXPECT_DOUBLE_EQ(StandardUncertainty(input), std::sqrt(2.5 / 5.0));
  EXPECT_DOUBLE_EQ(input.dof, 4.0);
  EXPECT_EQ(input.type, EvaluationType::kA);
}

TEST(WelchSatterthwaite, MatchesClosedForms) {
  // Two equal contributions of 4 dof each: (2u^2)^2 / (2 u^4 / 4) = 8.
  EXPECT_DOUBLE_EQ(WelchSatterthwaite(std::vector<double>{0.3, 0.3}, std::vector<double>{4.0, 4.0}), 8.0);
  // One finite term among exact ones: nu_eff = nu (u_c / u_1)^4 = 3 * (5/3)^4 for u = (3, 4).
  EXPECT_NEAR(WelchSatterthwaite(std::vector<double>{3.0, 4.0}, std::vector<double>{3.0, kInfiniteDof}),
              3.0 * std::pow(5.0 / 3.0, 4), 1e-12);
  EXPECT_TRUE(std::isinf(WelchSatterthwaite(std::vector<double>{1.0}, std::vector<double>{kInfiniteDof})));
}

TEST(CoverageFactor, MatchesGumTableG2) {
  // JCGM 100:2008 table G.2, t_p(nu), as printed there (2 decimals; 3 for nu = infinity).
  EXPECT_EQ(ShowFixed(CoverageFactor(1.0, 0.95), 2), "12.71");
  EXPECT_EQ(ShowFixed(CoverageFactor(2.0, 0.95), 2), "4.30");
  EXPECT_EQ(ShowFixed(CoverageFactor(10.0, 0.95), 2), "2.23");
  EXPECT_EQ(ShowFixed(CoverageFactor(16.0, 0.99), 2), "2.92");
  EXPECT_EQ(ShowFixed(CoverageFactor(16.0, 0.95), 2), "2.12");
  EXPECT_EQ(ShowFixed(CoverageFactor(kInfiniteDof, 0.95), 3), "1.960");
  EXPECT_EQ(ShowFixed(CoverageFactor(kInfiniteDof, 0.9545), 3), "2.000");
  // Rounded down to an integer first (G.4.1), unless asked not to.
  EXPECT_DOUBLE_EQ(CoverageFactor(16.7, 0.95), CoverageFactor(16.0, 0.95));
  EXPECT_LT(CoverageFactor(16.7, 0.95, false), CoverageFactor(16.0, 0.95, false));
}

TEST(Combine, AddsContributionsInQuadratureAndCorrectionsLinearly) {
  const std::vector<Input> inputs = {
      {.name = "a", .value = 1.0, .distribution = Distribution::kNormal, .spread = 3.0, .sensitivity = 2.0},
      {.name = "b",
       .value = 5.0,
       .distribution = Distribution::kRectangular,
       .spread = 8.0 * std::sqrt(3.0),
       .sensitivity = -1.0}};
  const Combined combined = Combine(inputs);
  EXPECT_DOUBLE_EQ(combined.contributions[0].contribution, 6.0);
  EXPECT_DOUBLE_EQ(combined.contributions[1].contribution, 8.0);
  EXPECT_DOUBLE_EQ(combined.standard_uncertainty, 10.0);
  EXPECT_DOUBLE_EQ(combined.correction, 2.0 * 1.0 - 5.0);
  EXPECT_TRUE(std::isinf(combined.effective_dof));
  EXPECT_NEAR(combined.coverage_factor, 1.959964, 1e-6);
  EXPECT_NEAR(combined.expanded, 19.59964, 1e-5);
}

TEST(Combine, NoInputsGiveZeroUncertainty) {
  const Combined combined = Combine({});
  EXPECT_EQ(combined.standard_uncertainty, 0.0);
  EXPECT_EQ(combined.expanded, 0.0);
}

TEST(Combine, RefusesBadInputsNamingEveryProblem) {
  const std::vector<Input> inputs = {{.name = "scale", .value = std::nan(""), .spread = -1.0},
                                     {.name = "scale",
                                      .distribution = Distribution::kNormal,
                                      .spread = 1.0,
                                      .coverage_factor = 0.0,
                                      .dof = 0.0}};
  const std::string message = arcwheel::testing::ErrorMessageOf(
      [&] { (void)Combine(inputs, {.coverage_probability = 1.5}); }, ErrorCode::kInvalidOption);
  EXPECT_EQ(message,
            "uncertainty.budget: scale.value = n/a violates finite; scale.spread = -1 violates finite, >= 0; "
            "scale.coverage_factor = 0 violates finite, > 0; scale.dof = 0 violates > 0 (may be infinite); "
            "scale.name = 'scale' violates unique in its budget; "
            "CombineOptions::coverage_probability = 1.5 violates (0, 1)");
}

// JCGM 100:2008 annex H.1, calibration of a nominally 50 mm end gauge against a standard:
// l = l_s + d - l_s (delta_alpha theta + alpha_s delta_theta) (H.1.2). Inputs as H.1.3 states
// them, in nm, degC and 1/degC; the figures checked are those of table H.1 and clause H.1.6.
TEST(Combine, ReproducesGumAnnexH1EndGaugeCalibration) {
  const double l_s_nm = 50.000623e6;  // H.1.3.1: the standard's certificate, 50.000 623 mm
  const double theta_c = -0.1;        // H.1.3.2: the bed's mean temperature, 19.9 degC
  const double alpha_s = 11.5e-6;     // H.1.3.3

  // H.1.3.1 u(l_s): U = 0.075 um at k = 3, nu = 18.
  const Input l_s{
      .name = "l_s", .unit = "nm", .value = l_s_nm, .spread = 75.0, .coverage_factor = 3.0, .dof = 18.0};
  // H.1.3.2 u(d): five readings with the pooled s = 13 nm of 25 readings (nu = 24), the
  // comparator's random effects (0.01 um at 95 % from 6 readings: k = 2.57, nu = 5) and its
  // systematic effects (0.02 um at "three sigma", nu = 8). d = 215 nm (H.1.3 d-bar).
  const std::vector<Input> d_parts = {
      {.name = "d_mean",
       .unit = "nm",
       .value = 215.0,
       .spread = 13.0 / std::sqrt(5.0),
       .dof = 24.0,
       .type = EvaluationType::kA},
      {.name = "d1", .unit = "nm", .spread = 10.0, .coverage_factor = 2.57, .dof = 5.0},
      {.name = "d2", .unit = "nm", .spread = 20.0, .coverage_factor = 3.0, .dof = 8.0}};
  const Combined d = Combine(d_parts);
  EXPECT_EQ(ShowFixed(d.contributions[0].contribution, 1), "5.8");
  EXPECT_EQ(ShowFixed(d.contributions[1].contribution, 1), "3.9");
  EXPECT_EQ(ShowFixed(d.contributions[2].contribution, 1), "6.7");
  EXPECT_EQ(ShowFixed(d.standard_uncertainty, 1), "9.7");  // table H.1: u(d) = 9.7 nm
  EXPECT_EQ(ShowFixed(d.effective_dof, 1), "25.6");        // H.1.3.2: nu_eff(d) = 25.6

  // H.1.3.2 u(theta): the mean 0.2 degC and a cyclic variation of amplitude 0.5 degC (arcsine).
  const std::vector<Input> theta_parts = {
      {.name = "theta_mean", .unit = "degC", .spread = 0.2},
      {.name = "cyclic", .unit = "degC", .distribution = Distribution::kArcsine, .spread = 0.5}};
  const Combined theta = Combine(theta_parts);
  EXPECT_EQ(ShowFixed(theta.contributions[1].contribution, 2), "0.35");
  EXPECT_EQ(ShowFixed(theta.standard_uncertainty, 2), "0.41");

  const std::vector<Input> inputs = {
      l_s,
      InputFromCombined("d", "nm", d),
      // H.1.3.3 alpha_s: +-2e-6 rectangular; sensitivity -l_s delta_theta = 0 (delta_theta = 0).
      {.name = "alpha_s",
       .unit = "1/degC",
       .distribution = Distribution::kRectangular,
       .spread = 2e-6,
       .sensitivity = 0.0},
      // theta: sensitivity -l_s delta_alpha = 0 (delta_alpha = 0); its second order in H.1.7.
      InputFromCombined("theta", "degC", theta, 0.0),
      // H.1.3.4 delta_alpha: +-1e-6 rectangular, reliable to 10 %: nu = 50; c = -l_s theta.
      {.name = "delta_alpha",
       .unit = "1/degC",
       .distribution = Distribution::kRectangular,
       .spread = 1e-6,
       .sensitivity = -l_s_nm * theta_c,
       .dof = 50.0},
      // H.1.3.5 delta_theta: +-0.05 degC rectangular, reliable to 50 %: nu = 2; c = -l_s alpha_s.
      {.name = "delta_theta",
       .unit = "degC",
       .distribution = Distribution::kRectangular,
       .spread = 0.05,
       .sensitivity = -l_s_nm * alpha_s,
       .dof = 2.0}};
  const Combined l = Combine(inputs, {.coverage_probability = 0.99});

  // Table H.1, column u(x_i) and u_i(l).
  EXPECT_EQ(ShowFixed(l.contributions[0].contribution, 0), "25");
  EXPECT_EQ(ShowFixed(l.contributions[2].standard_uncertainty * 1e6, 1), "1.2");
  EXPECT_EQ(l.contributions[2].contribution, 0.0);
  EXPECT_EQ(l.contributions[3].contribution, 0.0);
  EXPECT_EQ(ShowFixed(l.contributions[4].standard_uncertainty * 1e6, 2), "0.58");
  EXPECT_EQ(ShowFixed(l.contributions[4].contribution, 1), "2.9");
  EXPECT_EQ(ShowFixed(l.contributions[5].standard_uncertainty, 3), "0.029");
  EXPECT_EQ(ShowFixed(l.contributions[5].contribution, 1), "16.6");
  // u_c^2(l) = 1002 nm^2, u_c(l) = 32 nm (table H.1, H.1.4).
  EXPECT_EQ(ShowFixed(l.standard_uncertainty * l.standard_uncertainty, 0), "1002");
  EXPECT_EQ(ShowFixed(l.standard_uncertainty, 0), "32");
  // H.1.6: nu_eff(l) = 16.7, t_99(16) = 2.92, U_99 = t_99(16) u_c(l) = 2.92 x (32 nm) = 93 nm.
  EXPECT_EQ(ShowFixed(l.effective_dof, 1), "16.7");
  EXPECT_EQ(ShowFixed(l.coverage_factor, 2), "2.92");
  EXPECT_EQ(ShowFixed(l.coverage_factor * std::round(l.standard_uncertainty), 0), "93");
  // The same without rounding u_c first: 92.5 nm, which the GUM's "93 nm" rounds up from 2.92 x 32.
  EXPECT_NEAR(l.expanded, 2.921 * 31.66, 0.1);
  // H.1.5: l = l_s + d = 50.000 838 mm (checked as its excess over 50 mm, in nm).
  EXPECT_EQ(ShowFixed(l.correction - 50e6, 0), "838");

  // At 95 %: t_95(16) = 2.12, U_95 = 67 nm.
  const Combined l95 = Combine(inputs);
  EXPECT_EQ(ShowFixed(l95.coverage_factor, 2), "2.12");
  EXPECT_EQ(ShowFixed(l95.expanded, 0), "67");
}

}  // namespace
}  // namespace arcwheel::uncertainty
