#include "characteristics/wheel_characteristics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <random>
#include <vector>

#include "core/error.h"

namespace arcwheel::characteristics {
namespace {

// The ISO 16610-21 transmission, written out here from the standard's formula.
double ClosedFormTransmission(double k, double cutoff) {
  const double alpha = std::sqrt(std::log(2.0) / std::numbers::pi);
  return std::exp(-std::numbers::pi * (alpha * k / cutoff) * (alpha * k / cutoff));
}

// A map of n_phase x 3 axial nodes: rho = 50 mm + e cos(c) + a_k cos(k c) at node 1 (the worst),
// half of it at nodes 0 and 2; the phases' arcs all of radius 20 mm about (y = 0, rho = 30 mm).
struct TestWheel {
  int n_phase = 360;
  std::vector<double> y_mm = {-1.0, 0.0, 1.0};
  std::vector<double> rho_mm, center_axial_mm, center_radial_mm, arc_radius_mm;
  std::vector<char> usable;
  double sigma_mm = 0.0;

  TestWheel(double eccentricity_mm, int k, double amplitude_mm, double sigma, std::uint64_t seed = 1)
      : sigma_mm(sigma) {
    std::mt19937_64 rng(seed);
    std::normal_distribution<double> normal(0.0, 1.0);
    const std::size_t n_y = y_mm.size();
    rho_mm.resize(static_cast<std::size_t>(n_phase) * n_y);
    for (int i = 0; i < n_phase; ++i) {
      const double c = 2.0 * std::numbers::pi * i / n_phase;
      for (std::size_t j = 0; j < n_y; ++j) {
        const double scale = j == 1 ? 1.0 : 0.5;
        rho_mm[static_cast<std::size_t>(i) * n_y + j] = 50.0 + eccentricity_mm * std::cos(c) +
                                                        scale * amplitude_mm * std::cos(k * c) +
                                                        sigma * normal(rng);
      }
    }
    center_axial_mm.assign(static_cast<std::size_t>(n_phase), 0.0);
    center_radial_mm.assign(static_cast<std::size_t>(n_phase), 30.0);
    arc_radius_mm.assign(static_cast<std::size_t>(n_phase), 20.0);
    usable.assign(static_cast<std::size_t>(n_phase), 1);
  }

  [[nodiscard]] WheelForm Form() const {
    WheelForm form;
    form.rho_mm = rho_mm;
    form.y_mm = y_mm;
    form.map_sigma_mm = sigma_mm;
    form.band_low_mm = -1.5;
    form.band_high_mm = 1.5;
    form.center_axial_mm = center_axial_mm;
    form.center_radial_mm = center_radial_mm;
    form.arc_radius_mm = arc_radius_mm;
    form.usable = usable;
    return form;
  }
};

TEST(WheelCharacteristics, RoundnessIsTwiceTheFilteredHarmonicAtTheWorstNode) {
  const TestWheel wheel(0.0, 30, 0.002, 0.0);
  const WheelCharacteristics result = EvaluateWheelCharacteristics(wheel.Form(), {});
  // A single harmonic k >= 2 about the axis: the minimum zone is centred there and is 2 a T(k).
  EXPECT_NEAR(result.roundness.measured_um, 2.0 * 2.0 * ClosedFormTransmission(30, 50), 1e-6);
  EXPECT_EQ(result.roundness.worst_index, 1);
  EXPECT_DOUBLE_EQ(result.roundness.worst_at, 0.0);
  EXPECT_EQ(result.roundness.op.Describe(), "RONt, 50 UPR, MZ");
  // Without noise the bootstrap has nothing to add.
  EXPECT_NEAR(result.roundness.value_um, result.roundness.measured_um, 1e-9);
  EXPECT_NEAR(result.roundness.u_um, 0.0, 1e-9);
}

// `process` evaluates the turns while the uncertainty runs and the arc profile after it: each part
// draws its own replicates, so the parts give the numbers of the whole to the bit. (The arc
// profile's own numbers go through `process` in tests/same_results_test.)
TEST(WheelCharacteristics, TheTurnsApartAreTheWhole) {
  const TestWheel wheel(0.002, 20, 0.0015, 0.0003, 7);
  const WheelCharacteristics whole = EvaluateWheelCharacteristics(wheel.Form(), {});
  const WheelCharacteristics turns = EvaluateTurnCharacteristics(wheel.Form(), {});
  for (const auto& [part, of_whole] :
       {std::pair{&turns.roundness, &whole.roundness}, std::pair{&turns.runout, &whole.runout}}) {
    EXPECT_GT(of_whole->u_um, 0.0);
    EXPECT_EQ(part->value_um, of_whole->value_um);
    EXPECT_EQ(part->u_um, of_whole->u_um);
    EXPECT_EQ(part->worst_index, of_whole->worst_index);
  }
  EXPECT_EQ(turns.worst_roundness_section.ront_um, whole.worst_roundness_section.ront_um);
}

TEST(WheelCharacteristics, RunoutIsTheFilteredTurnsTotalIndicatorReading) {
  const double e = 0.010, a = 0.002;
  const TestWheel wheel(e, 30, a, 0.0);
  const WheelCharacteristics result = EvaluateWheelCharacteristics(wheel.Form(), {});
  double low = 1e9, high = -1e9;
  for (int i = 0; i < 360; ++i) {
    const double c = 2.0 * std::numbers::pi * i / 360.0;
    const double r = e * ClosedFormTransmission(1, 50) * std::cos(c) +
                     a * ClosedFormTransmission(30, 50) * std::cos(30 * c);
    low = std::min(low, r);
    high = std::max(high, r);
  }
  EXPECT_NEAR(result.runout.measured_um, (high - low) * 1000.0, 1e-6);
  EXPECT_EQ(result.runout.op.Describe(), "TIR, 50 UPR, spindle axis");
}

TEST(WheelCharacteristics, A150UprCutOffPassesMoreOfA100UprLobing) {
  const TestWheel wheel(0.0, 100, 0.001, 0.0);
  CharacteristicsOptions options;
  const double at_50 = EvaluateWheelCharacteristics(wheel.Form(), options).roundness.measured_um;
  options.roundness.cutoff_upr = 150.0;
  const double at_150 = EvaluateWheelCharacteristics(wheel.Form(), options).roundness.measured_um;
  EXPECT_NEAR(at_50, 2.0 * 1.0 * ClosedFormTransmission(100, 50), 1e-6);
  EXPECT_NEAR(at_150, 2.0 * 1.0 * ClosedFormTransmission(100, 150), 1e-6);
}

TEST(WheelCharacteristics, ArcProfileUnderMinimumZoneIsTwiceAnAlternatingForm) {
  // The map's nodes in the band as the sections: residual a cos(2 pi u / 1 mm) over u in [-1, 1]
  // mm alternates five times between +a and -a, more than an arc's three parameters can follow,
  // so the minimum zone is 2 a (to second order in a / R).
  TestWheel wheel(0.0, 2, 0.0, 0.0);
  wheel.y_mm.clear();
  for (int j = 0; j <= 40; ++j) wheel.y_mm.push_back(-1.0 + 0.05 * j);
  const std::size_t n_y = wheel.y_mm.size();
  wheel.rho_mm.assign(360 * n_y, 0.0);
  const double a_mm = 0.0005;
  for (std::size_t p = 0; p < 360; ++p) {
    for (std::size_t j = 0; j < n_y; ++j) {
      const double u = wheel.y_mm[j];
      const double r = 20.0 + a_mm * std::cos(2.0 * std::numbers::pi * u);
      wheel.rho_mm[p * n_y + j] = 30.0 + std::sqrt(r * r - u * u);
    }
  }
  WheelForm form = wheel.Form();
  form.band_low_mm = -1.0;
  form.band_high_mm = 1.0;
  CharacteristicsOptions options;
  options.roundness.cutoff_upr = std::nullopt;
  const WheelCharacteristics result = EvaluateWheelCharacteristics(form, options);
  EXPECT_NEAR(result.arc_profile.measured_um, 2.0 * a_mm * 1000.0, 1e-4);
  EXPECT_EQ(result.arc_profile.op.Describe(), "PV, no filter, MZ");
}

TEST(WheelCharacteristics, RefusesOperatorsItCannotEvaluate) {
  const TestWheel wheel(0.0, 3, 0.001, 0.0);
  CharacteristicsOptions options;
  options.roundness.cutoff_upr = 181.0;  // above 360 / 2
  EXPECT_THROW((void)EvaluateWheelCharacteristics(wheel.Form(), options), Error);
  options = {};
  options.runout.association = Association::kLeastSquares;
  EXPECT_THROW((void)EvaluateWheelCharacteristics(wheel.Form(), options), Error);
  options = {};
  options.arc_profile.association = Association::kMaximumInscribed;
  EXPECT_THROW((void)EvaluateWheelCharacteristics(wheel.Form(), options), Error);
  options = {};
  options.arc_profile.cutoff_upr = 50.0;
  EXPECT_THROW((void)EvaluateWheelCharacteristics(wheel.Form(), options), Error);
}

// Over many noise draws the bias-corrected value scatters about the noise-free truth under the same
// operator, and u is that scatter.
TEST(WheelCharacteristics, TheBiasCorrectedValueCoversTheNoiseFreeTruth) {
  const double sigma_mm = 0.0003;
  const TestWheel truth_wheel(0.002, 20, 0.0015, 0.0);
  const WheelCharacteristics truth = EvaluateWheelCharacteristics(truth_wheel.Form(), {});
  const int draws = 150;
  double sum_error_r = 0, sum2_error_r = 0, sum_u_r = 0, sum_error_t = 0, sum2_error_t = 0, sum_u_t = 0;
  int covered_r = 0, covered_t = 0;
  for (int d = 0; d < draws; ++d) {
    const TestWheel noisy(0.002, 20, 0.0015, sigma_mm, 1000 + static_cast<std::uint64_t>(d));
    const WheelCharacteristics m = EvaluateWheelCharacteristics(noisy.Form(), {});
    const double er = m.roundness.value_um - truth.roundness.measured_um;
    const double et = m.runout.value_um - truth.runout.measured_um;
    sum_error_r += er, sum2_error_r += er * er, sum_u_r += m.roundness.u_um;
    sum_error_t += et, sum2_error_t += et * et, sum_u_t += m.runout.u_um;
    covered_r += std::abs(er) <= 2.0 * m.roundness.u_um ? 1 : 0;
    covered_t += std::abs(et) <= 2.0 * m.runout.u_um ? 1 : 0;
  }
  const double sd_r = std::sqrt(sum2_error_r / draws - std::pow(sum_error_r / draws, 2));
  const double sd_t = std::sqrt(sum2_error_t / draws - std::pow(sum_error_t / draws, 2));
  std::printf(
      "RONt: mean error %.4f um, sd %.4f um, mean u %.4f um, covered %d/%d; TIR: %.4f, %.4f, %.4f, %d/%d\n",
      sum_error_r / draws, sd_r, sum_u_r / draws, covered_r, draws, sum_error_t / draws, sd_t,
      sum_u_t / draws, covered_t, draws);
  // The uncorrected PV would sit several sigma high; the corrected one within a third of u.
  EXPECT_LT(std::abs(sum_error_r / draws), 0.35 * sum_u_r / draws);
  EXPECT_LT(std::abs(sum_error_t / draws), 0.35 * sum_u_t / draws);
  EXPECT_NEAR(sd_r / (sum_u_r / draws), 1.0, 0.25);
  EXPECT_NEAR(sd_t / (sum_u_t / draws), 1.0, 0.25);
  EXPECT_GE(covered_r, static_cast<int>(0.88 * draws));
  EXPECT_GE(covered_t, static_cast<int>(0.88 * draws));
}

}  // namespace
}  // namespace arcwheel::characteristics
