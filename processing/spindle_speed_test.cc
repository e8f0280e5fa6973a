#include "processing/spindle_speed.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "acquisition/simulate.h"

namespace arcwheel::processing {
namespace {

// 120 turns of the lobed test wheel (lobes of orders 3 and 5 carry the phase) at 120 samples a
// turn and 0.5 um of noise, with the spindle `relative_error` off the nominal 500 rpm.
acquisition::ScanSettings ScanWithSpeedError(double relative_error, std::uint64_t seed) {
  acquisition::ScanSettings s;
  s.spindle_rpm_nominal = 500.0;
  s.spindle_rpm_true = 500.0 * (1.0 + relative_error);
  s.sample_period_s = 1e-3;
  s.feed_mm_per_min = 0.15 * s.spindle_rpm_nominal;  // a 0.15 mm pitch
  s.start_y_mm = -9.0;
  s.end_y_mm = 9.0;
  s.noise_um = 0.5;
  s.seed = seed;
  return s;
}

SpindleSpeedEstimate Estimate(const acquisition::ScanSettings& settings) {
  const acquisition::Scan scan = acquisition::SimulateScan(acquisition::LobedTestWheel(), settings).scan;
  return EstimateSpindleSpeed(scan, scan.z_mm, SpindleSpeedOptions{});
}

class SpeedOffNominal : public ::testing::TestWithParam<double> {};

TEST_P(SpeedOffNominal, IsRecoveredWithinItsSigmaWhichMatchesTheSpreadOverSeeds) {
  constexpr int kSeeds = 12;
  double sum_error2 = 0.0, sum_sigma2 = 0.0;
  for (int seed = 1; seed <= kSeeds; ++seed) {
    const acquisition::ScanSettings settings =
        ScanWithSpeedError(GetParam(), static_cast<std::uint64_t>(seed));
    const SpindleSpeedEstimate estimate = Estimate(settings);
    ASSERT_TRUE(estimate.available) << estimate.note;
    EXPECT_TRUE(estimate.significant);
    EXPECT_FALSE(estimate.used_first_harmonic);
    EXPECT_EQ(estimate.nominal_rpm, settings.spindle_rpm_nominal);
    EXPECT_EQ(estimate.used_rpm, estimate.fitted_rpm);
    const double error_rpm = estimate.fitted_rpm - settings.spindle_rpm_true;
    EXPECT_LT(std::abs(error_rpm), 4.0 * estimate.sigma_rpm) << "seed " << seed;
    sum_error2 += error_rpm * error_rpm;
    sum_sigma2 += estimate.sigma_rpm * estimate.sigma_rpm;
  }
  // The rms error over 12 seeds estimates the true sigma within about +-40 % (95 %, chi with 12
  // degrees of freedom); a reported sigma within a factor 2 of it is honest.
  const double observed = std::sqrt(sum_error2 / kSeeds);
  const double reported = std::sqrt(sum_sigma2 / kSeeds);
  EXPECT_GT(reported, observed / 2.0);
  EXPECT_LT(reported, observed * 2.0);
}

INSTANTIATE_TEST_SUITE_P(FastAndSlow, SpeedOffNominal, ::testing::Values(0.002, -0.001));

TEST(EstimateSpindleSpeed, KeepsTheNominalSpeedWhenTheSpindleRunsAtIt) {
  const acquisition::ScanSettings settings = ScanWithSpeedError(0.0, 3);
  const SpindleSpeedEstimate estimate = Estimate(settings);
  ASSERT_TRUE(estimate.available) << estimate.note;
  EXPECT_LT(std::abs(estimate.fitted_rpm - 500.0), 4.0 * estimate.sigma_rpm);
  EXPECT_FALSE(estimate.significant);
  EXPECT_EQ(estimate.used_rpm, 500.0);
}

// A scan with a time column is binned whole; one whose phase follows from its settings only over
// the windows fitted. With the time column holding exactly the settings' times the two must agree
// to the last bit: 400 turns (more than the 64 windows of 4 turns) at 3000 samples a turn (every
// second sample binned).
TEST(EstimateSpindleSpeed, BinsOnlyTheFittedWindowsToTheSameBitsAsTheWholeScan) {
  acquisition::ScanSettings settings = ScanWithSpeedError(0.001, 3);
  settings.sample_period_s = 4e-5;
  settings.feed_mm_per_min = 0.04 * settings.spindle_rpm_nominal;
  settings.start_y_mm = -8.0;
  settings.end_y_mm = 8.0;
  acquisition::Scan scan = acquisition::SimulateScan(acquisition::LobedTestWheel(), settings).scan;
  const SpindleSpeedEstimate by_windows = EstimateSpindleSpeed(scan, scan.z_mm, SpindleSpeedOptions{});
  scan.t_s.resize(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i)
    scan.t_s[i] = static_cast<double>(i) * settings.sample_period_s;
  const SpindleSpeedEstimate whole = EstimateSpindleSpeed(scan, scan.z_mm, SpindleSpeedOptions{});

  ASSERT_TRUE(whole.available);
  EXPECT_EQ(by_windows.fitted_rpm, whole.fitted_rpm);
  EXPECT_EQ(by_windows.sigma_rpm, whole.sigma_rpm);
  EXPECT_EQ(by_windows.turns_used, whole.turns_used);
  EXPECT_NEAR(whole.fitted_rpm, 500.5, 3.0 * whole.sigma_rpm);
}

TEST(EstimateSpindleSpeed, GivesUpOnAScanTooShortForFourWindows) {
  acquisition::ScanSettings settings = ScanWithSpeedError(0.002, 1);
  settings.end_y_mm = settings.start_y_mm + 10 * 0.15;  // 10 turns
  const SpindleSpeedEstimate estimate = Estimate(settings);
  EXPECT_FALSE(estimate.available);
  EXPECT_EQ(estimate.used_rpm, 500.0);
  EXPECT_FALSE(estimate.note.empty());
}

}  // namespace
}  // namespace arcwheel::processing
