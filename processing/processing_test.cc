#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>
#include <span>
#include <vector>

#include "core/nan.h"
#include "processing/banded_spd.h"
#include "processing/cubic_interpolation.h"
#include "processing/despike.h"
#include "processing/noise.h"
#include "processing/stuck_readings.h"

namespace arcwheel::processing {
namespace {

// Fills `banded` with a random diagonally dominant matrix of bandwidth 3 and returns the same
// matrix dense, for checks against Eigen's dense inverse.
Eigen::MatrixXd FillRandomBand(BandedSpd& banded, unsigned seed) {
  const std::size_t n = banded.size();
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  Eigen::MatrixXd dense = Eigen::MatrixXd::Zero(n, n);
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i; j <= std::min(n - 1, i + 3); ++j) {
      const double v = i == j ? 8.0 + unit(rng) : unit(rng);
      dense(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = v;
      dense(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) = v;
      banded.Add(i, j, v);
    }
  }
  return dense;
}

TEST(BandedSpd, SolveAndSelectedInverseMatchADenseInverse) {
  const std::size_t n = 40;
  BandedSpd banded(n);
  const Eigen::MatrixXd dense = FillRandomBand(banded, 3);
  std::mt19937 rng(13);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  ASSERT_TRUE(banded.Factorize());
  banded.ComputeSelectedInverse();
  const Eigen::MatrixXd inverse = dense.inverse();
  for (std::size_t i = 0; i < n; ++i) {
    for (std::size_t j = i; j <= std::min(n - 1, i + 3); ++j) {
      EXPECT_NEAR(banded.Inverse(i, j), inverse(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)),
                  1e-13);
    }
  }
  // b^T A^-1 b, whole and in blocks of rows (the same numbers in the same order).
  std::vector<double> q(n);
  Eigen::VectorXd q_dense(n);
  for (std::size_t i = 0; i < n; ++i) q_dense(static_cast<Eigen::Index>(i)) = q[i] = unit(rng);
  std::vector<double> whole = q;
  const double form = banded.InverseQuadraticForm(whole);
  EXPECT_NEAR(form, q_dense.dot(inverse * q_dense), 1e-13 * form);
  for (const std::size_t block_rows : {1u, 2u, 3u, 7u, 39u, 40u}) {
    std::vector<double> blocks = q;
    BandedSpd::ForwardPass pass;
    for (std::size_t first = 0; first < n; first += block_rows) {
      banded.InverseQuadraticFormRows(std::span(blocks).subspan(first, std::min(block_rows, n - first)),
                                      pass);
    }
    EXPECT_EQ(pass.next_row, n);
    EXPECT_EQ(pass.sum, form) << "blocks of " << block_rows;
  }
  std::vector<double> b(n);
  Eigen::VectorXd rhs(n);
  for (std::size_t i = 0; i < n; ++i) rhs(static_cast<Eigen::Index>(i)) = b[i] = unit(rng);
  banded.Solve(b);
  const Eigen::VectorXd x = dense.ldlt().solve(rhs);
  for (std::size_t i = 0; i < n; ++i) EXPECT_NEAR(b[i], x(static_cast<Eigen::Index>(i)), 1e-13);
}

TEST(BandedSpd, SweepInBlocksGivesEveryEntryOfTheSelectedInverseOnce) {
  const std::size_t n = 23;
  BandedSpd banded(n);
  const Eigen::MatrixXd dense = FillRandomBand(banded, 5);
  std::mt19937 rng(15);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  ASSERT_TRUE(banded.Factorize());
  const Eigen::MatrixXd inverse = dense.inverse();
  banded.ComputeSelectedInverse();
  // Block sizes below, at and beyond the band and the size, and one that leaves a short last block.
  for (const std::size_t block_rows : {1u, 2u, 3u, 4u, 5u, 22u, 23u, 40u}) {
    std::vector<int> visits(n, 0);
    std::size_t expected_end = n;
    banded.SweepSelectedInverse(block_rows, [&](const BandedSpd::InverseBlock& block) {
      EXPECT_EQ(block.end, expected_end) << "blocks run downwards without gaps";
      EXPECT_LT(block.first, block.end);
      EXPECT_LE(block.end - block.first, block_rows);
      expected_end = block.first;
      for (std::size_t i = block.first; i < block.end; ++i) {
        ++visits[i];
        for (int d = 0; d <= 3 && i + static_cast<std::size_t>(d) < n; ++d) {
          const auto j = static_cast<Eigen::Index>(i) + d;
          EXPECT_NEAR(block.InverseInBand(i, d), inverse(static_cast<Eigen::Index>(i), j), 1e-13);
          // The same recurrence in the same order: the numbers of the whole computation.
          EXPECT_EQ(block.InverseInBand(i, d), banded.InverseInBand(i, d)) << i << ", " << d;
        }
      }
      // The three rows above the block are still readable (a spline value needs four rows).
      for (std::size_t i = block.end; i < std::min(n, block.end + 3); ++i) {
        EXPECT_EQ(block.InverseInBand(i, 0), banded.InverseInBand(i, 0)) << "row " << i;
      }
    });
    EXPECT_EQ(expected_end, 0u);
    for (std::size_t i = 0; i < n; ++i)
      EXPECT_EQ(visits[i], 1) << "row " << i << ", blocks of " << block_rows;
  }
}

TEST(NaturalCubicSpline, InterpolatesItsPointsAndIsExactForStraightLines) {
  const std::vector<double> x = {0.0, 0.7, 1.1, 2.0, 3.5};
  std::vector<double> line, curve;
  for (const double v : x) {
    line.push_back(2.0 - 3.0 * v);
    curve.push_back(std::sin(v));
  }
  const NaturalCubicSpline straight(x, line), wavy(x, curve);
  for (double v = 0.0; v <= 3.5; v += 0.05) EXPECT_NEAR(straight(v), 2.0 - 3.0 * v, 1e-12);
  for (std::size_t i = 0; i < x.size(); ++i) EXPECT_NEAR(wavy(x[i]), curve[i], 1e-12);
}

std::vector<double> NoisySine(std::size_t n, double noise_mm, std::uint32_t seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> normal(0.0, noise_mm);
  std::vector<double> z(n);
  for (std::size_t i = 0; i < n; ++i)
    z[i] = 0.005 * std::sin(2.0 * std::numbers::pi * static_cast<double>(i) / 1200.0) + normal(rng);
  return z;
}

TEST(Noise, SecondDifferencesRecoverTheSensorNoiseDespiteSpikes) {
  std::vector<double> z = NoisySine(200000, 0.5e-3, 1);
  for (std::size_t i = 0; i < z.size(); i += 997) z[i] += 0.05;  // 0.1 % spikes of 50 um
  EXPECT_NEAR(EstimateNoiseSigmaMm(z), 0.5e-3, 0.02e-3);
}

// The estimator as its header states it, with a sorted copy for each median.
double NoiseByDefinition(const std::vector<double>& z) {
  std::vector<double> d;
  for (std::size_t i = 1; i + 1 < z.size(); ++i) {
    const double value = z[i - 1] - 2.0 * z[i] + z[i + 1];
    if (std::isfinite(value)) d.push_back(value);
  }
  std::sort(d.begin(), d.end());
  const double center = d[d.size() / 2];
  for (double& value : d) value = std::abs(value - center);
  std::sort(d.begin(), d.end());
  return 1.4826 * d[d.size() / 2] / std::sqrt(6.0);
}

TEST(Noise, IsTheMedianAbsoluteDeviationOfTheSecondDifferences) {
  // Gaussian noise, a sensor quantised to 0.1 um (many equal differences, zeros among them),
  // invalid samples, and an odd and an even count of differences.
  for (const std::size_t n : {2001u, 50000u, 50001u}) {
    std::vector<double> z = NoisySine(n, 0.5e-3, static_cast<std::uint32_t>(n));
    std::vector<double> quantised = z;
    for (double& v : quantised) v = std::round(v * 1e4) / 1e4;
    for (std::size_t i = 7; i < n; i += 101) quantised[i] = kNaN;
    EXPECT_EQ(EstimateNoiseSigmaMm(z), NoiseByDefinition(z)) << n;
    EXPECT_EQ(EstimateNoiseSigmaMm(quantised), NoiseByDefinition(quantised)) << n;
  }
}

// Runs of equal valid readings by their definition: one pass that ends a run at each change.
StuckReadingsResult StuckRunsByDefinition(std::vector<double>& z, std::size_t min_run) {
  StuckReadingsResult r;
  r.min_run = min_run;
  std::size_t start = 0;
  for (std::size_t i = 1; i <= z.size(); ++i) {
    if (i < z.size() && std::isfinite(z[start]) && z[i] == z[start]) continue;
    if (std::isfinite(z[start])) {
      r.valid += i - start;
      if (min_run >= 2 && i - start >= min_run) {
        for (std::size_t k = start; k < i; ++k) z[k] = kNaN;
        r.dropped += i - start;
        ++r.runs;
        r.longest_run = std::max(r.longest_run, i - start);
      }
    }
    start = i;
  }
  return r;
}

TEST(StuckReadings, DropsTheSameRunsAsOnePassWhereverTheMiddleFalls) {
  // Runs across the middle, ending and starting at it, a scan that is one run, invalid samples
  // inside and beside runs, and -0 beside +0 (equal readings).
  std::vector<std::vector<double>> scans;
  std::mt19937 rng(14);
  std::uniform_int_distribution<int> level(0, 2);
  for (std::size_t n : {1u, 2u, 7u, 40u, 41u, 1000u}) {
    std::vector<double> z(n);
    for (double& v : z) v = 0.001 * level(rng);
    scans.push_back(z);
  }
  std::vector<double> across(100, 0.5);
  for (std::size_t i = 0; i < 30; ++i) across[i] = 0.001 * static_cast<double>(i);
  scans.push_back(across);                        // a run from 30 to the end, through the middle
  scans.push_back(std::vector<double>(64, 2.0));  // one run
  std::vector<double> gaps(90, 1.0);
  gaps[45] = kNaN;
  gaps[44] = -0.0;
  gaps[43] = 0.0;
  gaps[46] = std::numeric_limits<double>::infinity();
  scans.push_back(gaps);
  // Long stretches of distinct readings (checked 64 at a time) with runs, invalid readings and
  // -0 beside +0 at and across the ends of those stretches.
  std::vector<double> long_scan(1000);
  for (std::size_t i = 0; i < long_scan.size(); ++i) long_scan[i] = 0.001 * static_cast<double>(i);
  for (std::size_t i = 62; i < 66; ++i) long_scan[i] = 7.0;
  for (std::size_t i = 127; i < 129; ++i) long_scan[i] = 8.0;
  long_scan[200] = kNaN;
  long_scan[255] = std::numeric_limits<double>::infinity();
  long_scan[319] = -0.0;
  long_scan[320] = 0.0;
  for (std::size_t i = 400; i < 470; ++i) long_scan[i] = 9.0;
  long_scan[999] = long_scan[998];
  scans.push_back(long_scan);
  for (const std::size_t min_run : {0u, 2u, 3u, 16u}) {
    for (const std::vector<double>& scan : scans) {
      std::vector<double> expected_z = scan, z = scan;
      const StuckReadingsResult expected = StuckRunsByDefinition(expected_z, min_run);
      const StuckReadingsResult got = DropStuckReadings(z, min_run);
      EXPECT_EQ(got.dropped, expected.dropped) << scan.size() << ", " << min_run;
      EXPECT_EQ(got.runs, expected.runs) << scan.size() << ", " << min_run;
      EXPECT_EQ(got.longest_run, expected.longest_run) << scan.size() << ", " << min_run;
      EXPECT_EQ(got.valid, expected.valid) << scan.size() << ", " << min_run;
      EXPECT_EQ(got.min_run, min_run);
      for (std::size_t i = 0; i < z.size(); ++i) {
        EXPECT_EQ(std::isnan(z[i]), std::isnan(expected_z[i])) << "sample " << i << " of " << z.size();
      }
      // The same readings as float32 (distinct as doubles, distinct as floats).
      std::vector<float> z_float(scan.begin(), scan.end());
      const StuckReadingsResult got_float = DropStuckReadings(z_float, min_run);
      EXPECT_EQ(got_float.dropped, expected.dropped) << scan.size() << ", " << min_run;
      EXPECT_EQ(got_float.runs, expected.runs) << scan.size() << ", " << min_run;
      EXPECT_EQ(got_float.valid, expected.valid) << scan.size() << ", " << min_run;
      for (std::size_t i = 0; i < z_float.size(); ++i) {
        EXPECT_EQ(std::isnan(z_float[i]), std::isnan(expected_z[i]))
            << "float sample " << i << " of " << z.size();
      }
    }
  }
}

TEST(Despike, FindsEachSpikeBesideTheSplitBetweenTheTwoHalvesOnce) {
  // A scan long enough to be judged in two halves, split at the middle sample; noiseless, so
  // that the spikes put in are exactly the samples to be found. A dropout just before the split
  // makes the halves' context skip invalid samples.
  const std::size_t middle = 100000;
  const std::vector<double> clean = NoisySine(2 * middle, 0.0, 3);
  std::vector<double> with_dropout = clean;
  with_dropout[middle - 4] = with_dropout[middle - 3] = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> median = with_dropout, mean = with_dropout;
  // A 5 um burst across the split for the median. For the mean, 6 um spikes 12 valid samples
  // apart: every window holds at most one, which moves the mean of a full window of 10 others by
  // 0.6 um (kept), but that of the 5 on one side by 1.2 um (rejected): the first sample of the
  // upper half stays only if its half saw the lower half's samples as context.
  const std::vector<std::size_t> burst = {middle - 2, middle - 1, middle, middle + 1};
  const std::vector<std::size_t> isolated = {middle - 12, middle + 2};
  for (const std::size_t i : burst) median[i] += 0.005;
  for (const std::size_t i : isolated) mean[i] += 0.006;

  const auto by_median = Despike(median, 0.0, {.method = DespikeMethod::kMedian, .threshold_um = 1.0});
  const auto by_mean = Despike(mean, 0.0, {.method = DespikeMethod::kMovingMean, .threshold_um = 1.0});

  EXPECT_EQ(by_median.indices, burst);
  EXPECT_EQ(by_mean.indices, isolated);
  // Replaced by the mean of the other samples in its window: the 5 valid ones on each side.
  for (const std::size_t i : isolated) {
    std::vector<double> others;
    for (std::size_t k = i - 1; others.size() < 5; --k) {
      if (std::isfinite(with_dropout[k])) others.push_back(clean[k]);
    }
    for (std::size_t k = i + 1; others.size() < 10; ++k) others.push_back(clean[k]);
    const double mean_of_others = std::accumulate(others.begin(), others.end(), 0.0) / 10.0;
    EXPECT_NEAR(mean[i], mean_of_others, 1e-12) << "sample " << i;
  }
}

TEST(Despike, MedianFilterRemovesFiveSampleBurstsThatTheMovingMeanLeaves) {
  // Long enough for the two-thread path (each half streams the other's edge as context).
  std::vector<double> clean = NoisySine(240000, 0.2e-3, 2);
  std::vector<double> spiked = clean;
  std::vector<std::size_t> injected;
  for (std::size_t start = 500; start + 5 < spiked.size(); start += 1499) {
    for (std::size_t k = 0; k < 5; ++k) {
      spiked[start + k] += 0.04;  // a 40 um burst of 5 samples
      injected.push_back(start + k);
    }
  }
  std::vector<double> median = spiked, mean = spiked;
  const auto by_median = Despike(median, 0.2e-3, {.method = DespikeMethod::kMedian});
  const auto by_mean = Despike(mean, 0.2e-3, {.method = DespikeMethod::kMovingMean, .threshold_um = 1.2});
  EXPECT_EQ(by_median.indices, injected);
  double worst_left_by_mean = 0.0;
  for (const std::size_t i : injected) worst_left_by_mean = std::max(worst_left_by_mean, mean[i] - clean[i]);
  // method.md A: the one-pass moving average keeps tens of micrometres of a 5-sample burst.
  EXPECT_GT(worst_left_by_mean, 0.01);
}

TEST(Despike, OptionsOutOfRangeAreReported) {
  EXPECT_FALSE((DespikeOptions{.window_half_width = 0}).Problems().empty());
  EXPECT_TRUE(DespikeOptions{}.Problems().empty());
}

}  // namespace
}  // namespace arcwheel::processing
