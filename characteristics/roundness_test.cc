// Roundness of profiles whose parameters have a closed form: an eccentric circle (exactly, not
// its limacon approximation) carrying known lobes about the instrument's axis.

#include "characteristics/roundness.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/testing/testing.h"

namespace arcwheel::characteristics {
namespace {

struct Profile {
  std::vector<double> angle_deg, radius_mm;
};

// A circle of radius R whose centre is e from the axis in direction theta0, plus A cos(3 t) +
// B cos(9 t): the lobes' peak-to-valley is 2 (A + B) (both peak at t = 0 and dip at t = pi / 3).
Profile LobedEccentricCircle(int n, double start_deg, double direction) {
  const double radius = 20.0, eccentricity = 0.05, theta0 = 0.6, lobe3 = 2e-3, lobe9 = 0.5e-3;
  Profile profile;
  for (int i = 0; i < n; ++i) {
    const double angle_deg = start_deg + direction * 360.0 * i / n;
    const double t = angle_deg * std::numbers::pi / 180.0;
    const double s = std::sin(t - theta0);
    const double circle = eccentricity * std::cos(t - theta0) +
                          std::sqrt(radius * radius - eccentricity * eccentricity * s * s);
    profile.angle_deg.push_back(angle_deg);
    profile.radius_mm.push_back(circle + lobe3 * std::cos(3 * t) + lobe9 * std::cos(9 * t));
  }
  return profile;
}

double Transmission(double k, double cutoff) { return std::pow(2.0, -(k / cutoff) * (k / cutoff)); }

// The requirement: RONt of a profile of known harmonics within 0.1 % of the closed form.
// Each association's reference gives its own split of RONt into RONp and RONv.
TEST(Roundness, ParametersOfKnownLobesMatchTheClosedFormUnderEveryAssociation) {
  const Profile profile = LobedEccentricCircle(3600, 12.5, 1.0);
  for (const std::optional<double> cutoff :
       {std::optional<double>(), std::optional<double>(15.0), std::optional<double>(50.0)}) {
    const double a = 2.0 * (cutoff ? Transmission(3, *cutoff) : 1.0);  // um
    const double b = 0.5 * (cutoff ? Transmission(9, *cutoff) : 1.0);
    const double ront = 2 * (a + b);
    const double ronq = std::sqrt((a * a + b * b) / 2);
    for (const Association association :
         {Association::kLeastSquares, Association::kMinimumZone, Association::kMaximumInscribed,
          Association::kMinimumCircumscribed}) {
      const RoundnessResult result = EvaluateRoundness(
          profile.angle_deg, profile.radius_mm, {.filter_cutoff_upr = cutoff, .association = association});
      const std::string what = result.op.Describe();
      EXPECT_NEAR(result.ront_um, ront, 1e-3 * ront) << what;
      const double ronp = association == Association::kMaximumInscribed       ? ront
                          : association == Association::kMinimumCircumscribed ? 0.0
                                                                              : ront / 2;
      EXPECT_NEAR(result.ronp_um, ronp, 1e-3 * ront) << what;
      EXPECT_NEAR(result.ronv_um, ront - ronp, 1e-3 * ront) << what;
      // About the mean circle RONq is the lobes' rms; about a circle shifted by s it is sqrt(rms^2 + s^2).
      const double shift = ronp - ront / 2;
      EXPECT_NEAR(result.ronq_um, std::sqrt(ronq * ronq + shift * shift), 1e-3 * ronq) << what;
      // The eccentricity, attenuated by the filter's transmission at 1 UPR. The lobes ride on the
      // axis, not on the circle's centre: seen from the centre they are tilted by up to e / R, which
      // moves a reference's centre by less than (e / R) (A + B) = 6e-6 mm.
      const double eccentricity = 0.05 * (cutoff ? Transmission(1, *cutoff) : 1.0);
      EXPECT_NEAR(result.reference.center_x_mm, eccentricity * std::cos(0.6), 1e-6) << what;
      EXPECT_NEAR(result.reference.center_y_mm, eccentricity * std::sin(0.6), 1e-6) << what;
    }
  }
}

TEST(Roundness, LobesAtTheCutOffKeepHalfTheirHeight) {
  for (const double cutoff : {15.0, 50.0, 150.0, 500.0}) {
    Profile profile;
    for (int i = 0; i < 3600; ++i) {
      profile.angle_deg.push_back(0.1 * i);
      profile.radius_mm.push_back(30.0 + 4e-3 * std::cos(cutoff * 0.1 * i * std::numbers::pi / 180.0));
    }
    const RoundnessResult result =
        EvaluateRoundness(profile.angle_deg, profile.radius_mm,
                          {.filter_cutoff_upr = cutoff, .association = Association::kLeastSquares});
    EXPECT_NEAR(result.ront_um / 8.0, 0.5, 0.001) << cutoff << " UPR";
  }
}

TEST(Roundness, TheSpectrumHoldsTheUnfilteredHarmonics) {
  const Profile profile = LobedEccentricCircle(720, 0.0, 1.0);
  const RoundnessResult result = EvaluateRoundness(profile.angle_deg, profile.radius_mm, {});
  ASSERT_EQ(result.harmonic_amplitude_um.size(), 359u);      // k = 1 .. n / 2 - 1
  EXPECT_NEAR(result.harmonic_amplitude_um[0], 50.0, 1e-9);  // the eccentricity
  EXPECT_NEAR(result.harmonic_amplitude_um[2], 2.0, 1e-9);
  EXPECT_NEAR(result.harmonic_amplitude_um[8], 0.5, 1e-9);
  EXPECT_EQ(result.op.Describe(), "RONt, 50 UPR, MZ");
  EXPECT_EQ((RoundnessOperator{.association = Association::kLeastSquares}.Describe("RONq")),
            "RONq, no filter, LS");
}

// Where the trace starts and which way it turns does not change the roundness: the same samples
// (every 0.36 deg) listed from 180 deg backwards.
TEST(Roundness, DoesNotDependOnTheStartOrDirectionOfTheTrace) {
  const Profile forward = LobedEccentricCircle(1000, 0.0, 1.0);
  const Profile backward = LobedEccentricCircle(1000, 180.0, -1.0);
  const RoundnessResult a = EvaluateRoundness(forward.angle_deg, forward.radius_mm, {});
  const RoundnessResult b = EvaluateRoundness(backward.angle_deg, backward.radius_mm, {});
  EXPECT_NEAR(a.ront_um, b.ront_um, 1e-9);
  EXPECT_NEAR(a.ronq_um, b.ronq_um, 1e-9);
}

TEST(Roundness, RefusesProfilesItCannotEvaluate) {
  Profile profile = LobedEccentricCircle(360, 0.0, 1.0);
  EXPECT_EQ(testing::ErrorMessageOf([&] {
              (void)EvaluateRoundness(std::span(profile.angle_deg).first(7),
                                      std::span(profile.radius_mm).first(7), {});
            }),
            "characteristics.roundness: a closed profile needs at least 8 points, got 7");
  EXPECT_EQ(
      testing::ErrorMessageOf(
          [&] {
            (void)EvaluateRoundness(profile.angle_deg, profile.radius_mm, {.filter_cutoff_upr = 181.0});
          },
          ErrorCode::kInvalidOption),
      "characteristics.roundness: cut-off 181 UPR is above half the 360 points of the profile (180 UPR)");
  EXPECT_EQ(
      testing::ErrorMessageOf(
          [&] { (void)EvaluateRoundness(profile.angle_deg, profile.radius_mm, {.filter_cutoff_upr = 0.0}); },
          ErrorCode::kInvalidOption),
      "characteristics.roundness: filter_cutoff_upr = 0 violates > 0");
  Profile gap = profile;
  gap.angle_deg.erase(gap.angle_deg.begin() + 100);
  gap.radius_mm.erase(gap.radius_mm.begin() + 100);
  const std::string message =
      testing::ErrorMessageOf([&] { (void)EvaluateRoundness(gap.angle_deg, gap.radius_mm, {}); });
  EXPECT_NE(message.find("the largest gap, 2 deg from point 99 to the next"), std::string::npos) << message;
  Profile half = profile;
  for (double& angle : half.angle_deg) angle *= 0.5;
  const std::string half_message =
      testing::ErrorMessageOf([&] { (void)EvaluateRoundness(half.angle_deg, half.radius_mm, {}); });
  EXPECT_NE(half_message.find("not equally spaced over one turn"), std::string::npos) << half_message;
}

TEST(AngleSpacing, AcceptsAnyStartAndEitherDirectionOfOneTurn) {
  EXPECT_TRUE(CheckAngleSpacing(std::vector<double>{-170, -80, 10, 100}).equally_spaced);
  EXPECT_TRUE(CheckAngleSpacing(std::vector<double>{90, 0, -90, 180}).equally_spaced);
  const AngleSpacing two_turns = CheckAngleSpacing(std::vector<double>{0, 180, 360, 540});
  EXPECT_FALSE(two_turns.equally_spaced);
  const AngleSpacing uneven = CheckAngleSpacing(std::vector<double>{0, 90, 185, 270});
  EXPECT_FALSE(uneven.equally_spaced);
  EXPECT_EQ(uneven.largest_gap_index, 1);
  EXPECT_DOUBLE_EQ(uneven.largest_gap_deg, 95.0);
}

}  // namespace
}  // namespace arcwheel::characteristics
