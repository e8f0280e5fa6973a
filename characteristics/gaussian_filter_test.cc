// The Gaussian filter checked by what it does to known profiles: its transmission (measured by
// projecting the output on the input's harmonic, a sum written here, not an FFT), and the
// periodised ISO 16610-21 weighting function applied in the space domain.

#include "characteristics/gaussian_filter.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "core/testing/testing.h"

namespace arcwheel::characteristics {
namespace {

std::vector<double> Harmonic(int n, double k, double amplitude, double phase, double mean = 0.0) {
  std::vector<double> values(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i)
    values[static_cast<std::size_t>(i)] =
        mean + amplitude * std::cos(2 * std::numbers::pi * k * i / n + phase);
  return values;
}

// Amplitude of harmonic k by projection: 2 / n |sum_j x_j exp(-2 pi i j k / n)|.
double AmplitudeOf(const std::vector<double>& values, int k) {
  const auto n = static_cast<double>(values.size());
  double c = 0.0, s = 0.0;
  for (std::size_t j = 0; j < values.size(); ++j) {
    c += values[j] * std::cos(2 * std::numbers::pi * k * static_cast<double>(j) / n);
    s += values[j] * std::sin(2 * std::numbers::pi * k * static_cast<double>(j) / n);
  }
  return 2.0 * std::hypot(c, s) / n;
}

// exp(-pi (alpha k / K)^2) with alpha^2 = ln 2 / pi is 2^-(k/K)^2: half at the cut-off.
double Expected(double k, double cutoff) { return std::pow(2.0, -(k / cutoff) * (k / cutoff)); }

TEST(ClosedGaussianFilter, PassesHalfTheAmplitudeAtTheCutOff) {
  const int n = 3600;
  for (const double cutoff : {15.0, 50.0, 150.0, 500.0}) {
    const std::vector<double> profile = Harmonic(n, cutoff, 3e-3, 0.7, 25.0);
    const std::vector<double> mean_line = FilterClosedProfile(profile, cutoff);
    const double transmission = AmplitudeOf(mean_line, static_cast<int>(cutoff)) / 3e-3;
    EXPECT_NEAR(transmission, 0.5, 0.001) << cutoff << " UPR";
    // The mean radius passes unchanged.
    double mean = 0.0;
    for (const double v : mean_line) mean += v / n;
    EXPECT_NEAR(mean, 25.0, 1e-12);
  }
}

TEST(ClosedGaussianFilter, FollowsTheGaussianTransmissionAtEveryHarmonic) {
  const int n = 1024;
  const double cutoff = 50.0;
  for (const int k : {1, 5, 25, 35, 75, 100, 150}) {
    const std::vector<double> mean_line = FilterClosedProfile(Harmonic(n, k, 1.0, 0.2), cutoff);
    EXPECT_NEAR(AmplitudeOf(mean_line, k), Expected(k, cutoff), 1e-12) << k << " UPR";
    EXPECT_NEAR(GaussianTransmission(k, cutoff), Expected(k, cutoff), 1e-15);
  }
}

// ISO 16610-21's weighting function s(x) = 1 / (alpha lambda_c) exp(-pi (x / (alpha lambda_c))^2),
// lambda_c = 2 pi / K rad on the circle, periodised and sampled, convolved directly.
TEST(ClosedGaussianFilter, EqualsThePeriodisedWeightingFunctionInTheSpaceDomain) {
  const int n = 720;
  const double cutoff = 50.0;
  std::vector<double> profile(n);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * i / n;
    profile[static_cast<std::size_t>(i)] = 10.0 + 0.01 * std::cos(3 * t) + 0.004 * std::sin(40 * t + 1.0) +
                                           0.002 * std::cos(97 * t) + (i % 7 == 0 ? 0.003 : 0.0);
  }
  const double alpha = std::sqrt(std::log(2.0) / std::numbers::pi);
  const double width = alpha * 2 * std::numbers::pi / cutoff;
  const double step = 2 * std::numbers::pi / n;
  std::vector<double> kernel(n, 0.0);
  for (int j = 0; j < n; ++j) {
    for (int period = -2; period <= 2; ++period) {
      const double x = (j + period * n) * step;
      kernel[static_cast<std::size_t>(j)] +=
          std::exp(-std::numbers::pi * (x / width) * (x / width)) / width * step;
    }
  }
  const std::vector<double> mean_line = FilterClosedProfile(profile, cutoff);
  for (int i = 0; i < n; ++i) {
    double convolved = 0.0;
    for (int j = 0; j < n; ++j) {
      convolved += kernel[static_cast<std::size_t>(j)] * profile[static_cast<std::size_t>((i - j + n) % n)];
    }
    ASSERT_NEAR(mean_line[static_cast<std::size_t>(i)], convolved, 1e-12) << "sample " << i;
  }
}

TEST(ClosedGaussianFilter, KeptForManyProfilesFiltersEachAsTheTransmissionSays) {
  // One filter object, profiles of several harmonics in turn, some filtered in place: each comes
  // out with its harmonic scaled by the closed-form transmission and its mean kept.
  ClosedProfileFilter filter(360, 50.0);
  for (const double k : {1.0, 15.0, 50.0, 120.0}) {
    std::vector<double> values = Harmonic(360, k, 2.0, 0.3 * k, 7.0);
    std::vector<double> out(values.size());
    filter.Apply(values, out);
    EXPECT_NEAR(AmplitudeOf(out, static_cast<int>(k)), 2.0 * Expected(k, 50.0), 1e-12) << k;
    double mean = 0.0;
    for (const double v : out) mean += v / 360.0;
    EXPECT_NEAR(mean, 7.0, 1e-12) << k;
    filter.Apply(values, values);
    for (std::size_t i = 0; i < values.size(); ++i) ASSERT_EQ(values[i], out[i]) << k << " " << i;
  }
  std::vector<double> wrong(100);
  EXPECT_THROW(filter.Apply(wrong, wrong), Error);
  EXPECT_THROW(ClosedProfileFilter(360, 181.0), Error);
}

TEST(ClosedGaussianFilter, RefusesACutOffOfZeroOrAboveHalfThePoints) {
  const std::vector<double> profile = Harmonic(100, 3, 1.0, 0.0, 5.0);
  EXPECT_EQ(
      testing::ErrorMessageOf([&] { (void)FilterClosedProfile(profile, 0.0); }, ErrorCode::kInvalidOption),
      "characteristics.filter: cut-off 0 UPR violates 0 < cut-off <= 50 (half the 100 points of the "
      "profile)");
  EXPECT_NE(
      testing::ErrorMessageOf([&] { (void)FilterClosedProfile(profile, 50.5); }, ErrorCode::kInvalidOption)
          .find("cut-off 50.5 UPR violates"),
      std::string::npos);
  EXPECT_EQ(testing::ErrorMessageOf([&] { (void)FilterClosedProfile(std::vector<double>(7, 1.0), 2.0); }),
            "characteristics.filter: a closed profile needs at least 8 points, got 7");
}

TEST(HarmonicAmplitudes, GiveTheAmplitudeOfEachHarmonic) {
  const int n = 64;
  std::vector<double> profile(n);
  for (int i = 0; i < n; ++i) {
    const double t = 2 * std::numbers::pi * i / n;
    profile[static_cast<std::size_t>(i)] =
        7.0 + 3.0 * std::cos(2 * t) + 4.0 * std::sin(2 * t) + 0.5 * std::sin(31 * t);
  }
  const std::vector<double> amplitudes = HarmonicAmplitudes(profile, 500);
  ASSERT_EQ(amplitudes.size(), 31u);  // k = 1 .. n / 2 - 1
  for (int k = 1; k <= 31; ++k) {
    const double expected = k == 2 ? 5.0 : k == 31 ? 0.5 : 0.0;
    EXPECT_NEAR(amplitudes[static_cast<std::size_t>(k - 1)], expected, 1e-12) << k;
  }
  EXPECT_EQ(HarmonicAmplitudes(profile, 10).size(), 10u);
}

// A long open profile: far from its ends (more than lambda_c) the sampled weighting function
// passes a wave of the cut-off wavelength at half its amplitude.
TEST(OpenGaussianFilter, PassesHalfTheAmplitudeAtTheCutOffWavelength) {
  const double cutoff_mm = 0.8, spacing_mm = cutoff_mm / 100;
  const int n = 2000;  // 20 cut-offs
  for (const double wavelength_factor : {1.0, 0.5, 2.0}) {
    const double wavelength = cutoff_mm * wavelength_factor;
    std::vector<double> profile(n);
    for (int i = 0; i < n; ++i)
      profile[static_cast<std::size_t>(i)] = std::sin(2 * std::numbers::pi * i * spacing_mm / wavelength);
    const std::vector<double> mean_line = FilterOpenProfile(profile, spacing_mm, cutoff_mm);
    double peak = 0.0;
    for (int i = 200; i < n - 200; ++i)
      peak = std::max(peak, std::abs(mean_line[static_cast<std::size_t>(i)]));
    // 1 / wavelength in units of 1 / lambda_c; the peak of sampled sine is within (1 - cos(pi / 100)) of its
    // amplitude.
    EXPECT_NEAR(peak, Expected(1.0 / wavelength_factor, 1.0), 0.001) << wavelength << " mm";
  }
}

TEST(OpenGaussianFilter, KeepsAConstantToTheEnds) {
  const std::vector<double> profile(50, 3.25);
  for (const double v : FilterOpenProfile(profile, 0.01, 0.25)) EXPECT_NEAR(v, 3.25, 1e-14);
  EXPECT_EQ(testing::ErrorMessageOf([&] { (void)FilterOpenProfile(profile, 0.01, 0.04); },
                                    ErrorCode::kInvalidOption),
            "characteristics.filter: cut-off 0.04 mm with spacing 0.01 mm violates spacing > 0 and cut-off "
            ">= 5 spacings");
}

}  // namespace
}  // namespace arcwheel::characteristics
