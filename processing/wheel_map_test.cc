#include "processing/wheel_map.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <numeric>
#include <random>
#include <span>
#include <vector>

#include "acquisition/simulate.h"
#include "core/error.h"
#include "core/nan.h"
#include "processing/helix_geometry.h"

namespace arcwheel::processing {
namespace {

// A small scan of the lobed test wheel without noise: 500 rpm, 3 deg a sample (starting off the
// 10 deg phase nodes, so no sample sits on a cell boundary), a 0.5 mm pitch, 24 turns.
acquisition::ScanSettings SmallScan() {
  acquisition::ScanSettings s;
  s.sample_period_s = 1e-3;
  s.feed_mm_per_min = 250.0;
  s.start_phase_deg = 0.7;
  s.start_y_mm = -6.0;
  s.end_y_mm = 6.0;
  return s;
}

// Where sample i lies, from the simulator's settings (no encoder, no time or axial column).
double PhaseOfSample(const acquisition::ScanSettings& s, std::size_t i) {
  return s.start_phase_deg + 6.0 * s.spindle_rpm_true * s.sample_period_s * static_cast<double>(i);
}
double AxialOfSample(const acquisition::ScanSettings& s, std::size_t i) {
  return s.start_y_mm + s.feed_mm_per_min / 60.0 * s.sample_period_s * static_cast<double>(i);
}

// The true reading at (phase, y): the rim's radius less the sensor's zero.
double TrueRhoMm(const acquisition::WheelModel& wheel, const acquisition::ScanSettings& s, double phase_deg,
                 double y_mm) {
  return wheel.SmoothRadiusMm(phase_deg, y_mm) - s.sensor_zero_radius_mm;
}

// The map cell (phase node, axial node) nearest to sample i, or -1 outside the axial nodes.
long NearestCell(const acquisition::ScanSettings& s, const WheelMap& map, std::size_t i) {
  const double phase_step = 360.0 / static_cast<double>(map.n_phase());
  const double c = std::fmod(PhaseOfSample(s, i), 360.0);
  const auto j = static_cast<std::size_t>(std::round(c / phase_step)) % map.n_phase();
  const double m = std::round((AxialOfSample(s, i) - map.y_mm.front()) / map.axial_step_mm);
  if (m < 0 || m >= static_cast<double>(map.n_y())) return -1;
  return static_cast<long>(j * map.n_y() + static_cast<std::size_t>(m));
}

// How far a map node may lie from the true rim. Inside, the tolerance covers the helix spline's
// approximation of the lobes at 10 deg knots and its penalty (a few nm) with a wide margin. At
// the two outermost nodes at each end the axial interpolation's natural end condition (zero
// curvature where the arc has curvature kappa ~ 1 / 55 mm) costs up to about what linear
// interpolation over a pitch h would, kappa h^2 / 8 = 0.58 um at h = 0.5 mm.
double MapToleranceMm(const WheelMap& map, std::size_t m) {
  const bool outermost = m < 2 || m + 2 >= map.n_y();
  return outermost ? 0.5 * 0.5 / 55.0 / 8.0 : 2e-5;
}

TEST(BuildWheelMap, MapsASimulatedWheelOntoItsTrueRadiiAndCountsTheSamplesPerCell) {
  const acquisition::WheelModel wheel = acquisition::LobedTestWheel();
  const acquisition::ScanSettings settings = SmallScan();
  const acquisition::Scan scan = acquisition::SimulateScan(wheel, settings).scan;
  const std::vector<std::size_t> despiked = {10, 500, 501, 2000};
  const WheelMap map = BuildWheelMap(scan.z_mm, HelixGeometry(scan, settings.spindle_rpm_nominal), 1e-3,
                                     despiked, {.phases = 36});

  ASSERT_EQ(map.n_phase(), 36u);
  EXPECT_DOUBLE_EQ(map.pitch_mm, 0.5);
  EXPECT_DOUBLE_EQ(map.axial_step_mm, 0.5);
  EXPECT_DOUBLE_EQ(map.knot_step_deg, 10.0);  // 360 / 36, already >= 2.5 samples of 3 deg
  ASSERT_GE(map.n_y(), 20u);
  for (std::size_t m = 1; m < map.n_y(); ++m) EXPECT_NEAR(map.y_mm[m] - map.y_mm[m - 1], 0.5, 1e-12);

  // Every section point lies on the true rim (the helix spline alone, as MapToleranceMm inside).
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    const Section& section = map.sections[j];
    ASSERT_GE(section.y_mm.size(), 20u) << "phase " << map.phase_deg[j];
    for (std::size_t k = 0; k < section.y_mm.size(); ++k) {
      EXPECT_NEAR(section.rho_mm[k], TrueRhoMm(wheel, settings, map.phase_deg[j], section.y_mm[k]), 2e-5)
          << "phase " << map.phase_deg[j] << ", y " << section.y_mm[k];
    }
  }
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    for (std::size_t m = 0; m < map.n_y(); ++m) {
      EXPECT_NEAR(map.rho(j, m), TrueRhoMm(wheel, settings, map.phase_deg[j], map.y_mm[m]),
                  MapToleranceMm(map, m))
          << "phase " << map.phase_deg[j] << ", y " << map.y_mm[m];
    }
  }

  // Counts of the samples nearest each cell, from the simulator's own timing.
  std::vector<int> expected(map.n_phase() * map.n_y(), 0), expected_despiked(expected.size(), 0);
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const long cell = NearestCell(settings, map, i);
    if (cell >= 0 && std::isfinite(scan.z_mm[i])) ++expected[static_cast<std::size_t>(cell)];
  }
  for (const std::size_t i : despiked) {
    const long cell = NearestCell(settings, map, i);
    if (cell >= 0) ++expected_despiked[static_cast<std::size_t>(cell)];
  }
  EXPECT_EQ(map.sample_count, expected);
  EXPECT_EQ(map.despiked_count, expected_despiked);
  // About 120 samples a turn over 36 cells: 3 or 4 each inside the nodes' span.
  EXPECT_GT(std::accumulate(expected.begin(), expected.end(), 0), 3 * static_cast<int>(expected.size()));
}

TEST(BuildWheelMap, LeavesCellsWithoutSamplesEmptyAndKeepsTheRest) {
  const acquisition::WheelModel wheel = acquisition::LobedTestWheel();
  const acquisition::ScanSettings settings = SmallScan();
  acquisition::Scan scan = acquisition::SimulateScan(wheel, settings).scan;
  // No valid sample over 3.4 pitches of the axis, at every phase.
  constexpr double kGapLowMm = -0.9, kGapHighMm = 0.8;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double y = AxialOfSample(settings, i);
    if (y >= kGapLowMm && y <= kGapHighMm) scan.z_mm[i] = std::nan("");
  }
  const WheelMap map =
      BuildWheelMap(scan.z_mm, HelixGeometry(scan, settings.spindle_rpm_nominal), 1e-3, {}, {.phases = 36});

  int empty_in_gap = 0;
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    for (std::size_t m = 0; m < map.n_y(); ++m) {
      const double y = map.y_mm[m];
      const auto cell = j * map.n_y() + m;
      if (y > kGapLowMm + 0.25 && y < kGapHighMm - 0.25) {
        // No sample is nearest this node, and no section point lies within a pitch of it.
        EXPECT_EQ(map.sample_count[cell], 0) << "y " << y;
        EXPECT_TRUE(std::isnan(map.rho(j, m))) << "phase " << map.phase_deg[j] << ", y " << y;
        empty_in_gap += std::isnan(map.rho(j, m)) ? 1 : 0;
      } else if (y < kGapLowMm - 1.0 || y > kGapHighMm + 1.0) {
        // More than two pitches from the gap the sections are whole and the map is the wheel.
        EXPECT_NEAR(map.rho(j, m), TrueRhoMm(wheel, settings, map.phase_deg[j], y), MapToleranceMm(map, m))
            << "phase " << map.phase_deg[j] << ", y " << y;
      }
    }
  }
  EXPECT_GE(empty_in_gap, 36 * 2);
  // No section point rests on the gap.
  for (const Section& section : map.sections) {
    for (const double y : section.y_mm) EXPECT_FALSE(y > kGapLowMm + 0.05 && y < kGapHighMm - 0.05) << y;
  }
}

// The coverage counts by the plain per-sample rule: each finite sample in the cell of the phase
// node nearest fmod(u, 360) (by std::lround) and the axial node nearest y.
std::vector<int> PlainCoverage(std::span<const double> rho, const HelixGeometry& geometry,
                               const WheelMap& map, std::span<const std::size_t> only) {
  std::vector<int> counts(map.n_phase() * map.n_y(), 0);
  const double phase_step = 360.0 / static_cast<double>(map.n_phase());
  const auto count = [&](std::size_t i) {
    double c = std::fmod(geometry.PhaseAt(i), 360.0);
    if (c < 0.0) c += 360.0;
    const auto j = static_cast<std::size_t>(std::lround(c / phase_step)) % map.n_phase();
    const long m = std::lround((geometry.AxialAt(i) - map.y_mm.front()) / map.axial_step_mm);
    if (m >= 0 && m < static_cast<long>(map.n_y())) ++counts[j * map.n_y() + static_cast<std::size_t>(m)];
  };
  if (!only.empty()) {
    for (const std::size_t i : only) count(i);
    return counts;
  }
  for (std::size_t i = 0; i < rho.size(); ++i) {
    if (std::isfinite(rho[i])) count(i);
  }
  return counts;
}

// One helix of the coverage test: the small scan's readings laid on a helix of other settings.
struct CoverageCase {
  double rpm = 500.0;
  double sample_period_s = 1e-4;
  double feed_mm_per_min = 250.0;
  double start_phase_deg = 0.7;
  int phases = 36;
  double axial_step_mm = 0.0;
};

void ExpectPlainCoverage(const CoverageCase& c, double dropout_fraction, std::mt19937_64& random) {
  acquisition::ScanSettings settings = SmallScan();
  settings.sample_period_s = 1e-4;
  acquisition::Scan scan = acquisition::SimulateScan(acquisition::LobedTestWheel(), settings).scan;
  scan.metadata.sample_period_s = c.sample_period_s;
  scan.metadata.start_phase_deg = c.start_phase_deg;
  scan.metadata.feed_mm_per_min = c.feed_mm_per_min;
  if (c.feed_mm_per_min < 0) scan.metadata.start_y_mm = settings.end_y_mm;
  std::bernoulli_distribution dropped(dropout_fraction);
  std::uniform_int_distribution<std::size_t> any_sample(0, scan.size() - 1);
  for (double& z : scan.z_mm) {
    if (dropped(random)) z = std::nan("");
  }
  const std::size_t block = any_sample(random);  // a longer dropout
  for (std::size_t i = block; i < std::min(scan.size(), block + 700); ++i) scan.z_mm[i] = std::nan("");
  std::vector<std::size_t> despiked;
  for (int k = 0; k < 50; ++k) despiked.push_back(any_sample(random));
  std::sort(despiked.begin(), despiked.end());

  const HelixGeometry geometry(scan, c.rpm);
  ASSERT_TRUE(geometry.from_settings());
  const WheelMap map = BuildWheelMap(scan.z_mm, geometry, 1e-3, despiked,
                                     {.phases = c.phases, .axial_step_mm = c.axial_step_mm});
  EXPECT_EQ(map.sample_count, PlainCoverage(scan.z_mm, geometry, map, {}))
      << "rpm " << c.rpm << ", period " << c.sample_period_s << ", feed " << c.feed_mm_per_min << ", start "
      << c.start_phase_deg << ", phases " << c.phases;
  EXPECT_EQ(map.despiked_count, PlainCoverage(scan.z_mm, geometry, map, despiked));
  EXPECT_GT(std::accumulate(map.sample_count.begin(), map.sample_count.end(), 0),
            static_cast<int>(scan.size() / 2));
}

TEST(BuildWheelMap, CountsCoverageAsThePlainPerSampleRuleOnRandomHelices) {
  std::mt19937_64 random(14);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  const int phase_counts[] = {4, 7, 36, 360, 1000};
  for (int trial = 0; trial < 16; ++trial) {
    CoverageCase c;
    c.rpm = 300.0 + 500.0 * unit(random);
    c.sample_period_s = 1e-4 * (0.5 + unit(random));
    c.feed_mm_per_min = (trial % 3 == 0 ? -1.0 : 1.0) * (150.0 + 200.0 * unit(random));
    c.start_phase_deg = 1440.0 * unit(random) - 720.0;
    c.phases = phase_counts[trial % 5];
    c.axial_step_mm = trial % 4 == 1 ? 0.13 + 0.5 * unit(random) : 0.0;
    ExpectPlainCoverage(c, trial % 2 == 0 ? 0.0 : 0.05, random);
  }
}

// Samples exactly on phase cell boundaries: 1024 phases (a step of 45/256 deg) and 375/2048 deg a
// sample from a boundary put every 48th sample on one (the rule rounds half away from zero), also
// on the turns below u = 0 and with the feed towards -y.
TEST(BuildWheelMap, CountsCoverageAsThePlainPerSampleRuleOnCellBoundaries) {
  std::mt19937_64 random(7);
  for (const double start : {45.0 / 256.0, 45.0 / 256.0 - 720.0, 45.0 / 256.0 + 3600.0}) {
    for (const double feed : {250.0, -250.0}) {
      const CoverageCase c{.sample_period_s = std::ldexp(1.0, -14),
                           .feed_mm_per_min = feed,
                           .start_phase_deg = start,
                           .phases = 1024};
      ExpectPlainCoverage(c, 0.01, random);
    }
  }
}

// The knot step is the first multiple of the phase step that spans 2.5 valid samples on average
// (for the helix spline): counted over the whole scan, wherever its valid samples lie. A long scan
// (3.5 million samples, over three blocks of the count) valid only at every 1900th sample needs
// 15 phase steps; valid only in its first 1.2 million, one.
TEST(PlanWheelMap, ChoosesTheKnotStepFromAllTheValidSamples) {
  acquisition::ScanSettings settings = SmallScan();
  settings.sample_period_s = 1e-5;  // 0.03 deg a sample
  settings.feed_mm_per_min = 12.0 / 35.0 * 60.0;
  settings.float32 = false;
  acquisition::Scan scan = acquisition::SimulateScan(acquisition::LobedTestWheel(), settings).scan;
  ASSERT_GT(scan.size(), 3'400'000u);
  const HelixGeometry geometry(scan, settings.spindle_rpm_nominal);
  const double span_deg = PhaseOfSample(settings, scan.size() - 1) - PhaseOfSample(settings, 0);
  const auto expected_step = [&](std::size_t valid) {
    return 10.0 * std::ceil(2.5 * span_deg / static_cast<double>(valid) / 10.0);
  };
  const std::vector<double> readings = scan.z_mm;
  for (const auto& [valid_at, expected_valid] :
       {std::pair<std::function<bool(std::size_t)>, std::size_t>{[](std::size_t i) { return i % 1900 == 0; },
                                                                 (scan.size() + 1899) / 1900},
        {[](std::size_t i) { return i < 1'200'000; }, 1'200'000}}) {
    for (std::size_t i = 0; i < scan.size(); ++i) scan.z_mm[i] = valid_at(i) ? readings[i] : kNaN;
    const WheelMap map = PlanWheelMap(std::span<const double>(scan.z_mm), geometry, 1e-3, {}, {.phases = 36});
    EXPECT_DOUBLE_EQ(map.knot_step_deg, expected_step(expected_valid)) << expected_valid << " valid samples";
  }
  EXPECT_DOUBLE_EQ(expected_step((scan.size() + 1899) / 1900), 150.0);
  EXPECT_DOUBLE_EQ(expected_step(1'200'000), 10.0);
}

TEST(BuildWheelMap, RefusesOptionsOutOfRange) {
  const acquisition::Scan scan = acquisition::SimulateScan(acquisition::LobedTestWheel(), SmallScan()).scan;
  EXPECT_THROW((void)BuildWheelMap(scan.z_mm, HelixGeometry(scan, 500.0), 1e-3, {}, {.phases = 3}), Error);
}

}  // namespace
}  // namespace arcwheel::processing
