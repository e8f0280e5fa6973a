// Noise-corrected PV against known truths: sinusoids and polynomials with normal noise of known
// sigma, over many seeds, so that the bias removed and the interval's coverage are checked.

#include "uncertainty/noise_corrected.h"

#include <gtest/gtest.h>

#include <boost/random/mersenne_twister.hpp>
#include <cmath>
#include <numbers>
#include <random>
#include <vector>

#include "core/testing/testing.h"

namespace arcwheel::uncertainty {
namespace {

struct Trial {
  double raw_minus_truth = 0.0;
  double value_minus_truth = 0.0;
  bool covered = false;
};

// `rows` rows over 360 phases: row r = amplitude * (1 + 0.1 r) * cos(order * c) + noise `sigma`;
// the true PV is the largest row's 2 * amplitude * (1 + 0.1 (rows - 1)) (cos hits +-1 at the nodes).
Trial FourierTrial(int rows, int order, double amplitude, double sigma, unsigned seed, int across_rows = -1) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  const int columns = 360;
  std::vector<double> values(rows * columns), sigmas(rows * columns, sigma);
  for (int r = 0; r < rows; ++r)
    for (int j = 0; j < columns; ++j)
      values[r * columns + j] =
          amplitude * (1.0 + 0.1 * r) * std::cos(order * 2.0 * std::numbers::pi * j / columns) + noise(rng);
  const double truth = 2.0 * amplitude * (1.0 + 0.1 * (rows - 1));
  const NoiseCorrectedPv pv = EstimateNoiseCorrectedPv(
      values, sigmas, rows, columns,
      {.max_order = 12, .replicates = 100, .across_rows_max_degree = across_rows, .seed = seed});
  return {pv.raw_pv - truth, pv.value - truth, std::abs(pv.value - truth) <= 1.96 * pv.standard_uncertainty};
}

// Rows that are neighbours (a map's axial nodes): the third harmonic's amplitude grows linearly
// from row to row, and the largest row's PV is the figure. Fitting the coefficients along the rows
// (degree 1 is real, the rest noise) takes the maximum over rows of far less noise than each row on
// its own: the estimate scatters less, keeps no bias, and its interval still covers the truth.
TEST(EstimateNoiseCorrectedPv, AlongTheRowsAMaximumOverNeighbouringRowsScattersLessAndCovers) {
  const int trials = 60;
  double alone_ss = 0.0, along_ss = 0.0, along_bias = 0.0;
  int covered = 0;
  for (int t = 0; t < trials; ++t) {
    const Trial alone = FourierTrial(40, 3, 0.5, 1.0, 500 + t);
    const Trial along = FourierTrial(40, 3, 0.5, 1.0, 500 + t, 10);
    alone_ss += alone.value_minus_truth * alone.value_minus_truth;
    along_ss += along.value_minus_truth * along.value_minus_truth;
    along_bias += along.value_minus_truth / trials;
    covered += along.covered;
  }
  const double alone_rms = std::sqrt(alone_ss / trials), along_rms = std::sqrt(along_ss / trials);
  EXPECT_LT(along_rms, 0.6 * alone_rms) << along_rms << " against " << alone_rms;
  EXPECT_LT(std::abs(along_bias), 3.0 * along_rms / std::sqrt(trials));
  // 95 % nominal; 60 trials: binomial sd 2.8 %, bounds at about 3 sd.
  EXPECT_GE(covered, 0.86 * trials);
  EXPECT_LE(covered, trials);
}

TEST(EstimateNoiseCorrectedPv, RemovesTheNoiseBiasOfARangeAndCoversTheTruth) {
  // Ra(c) of the paper's kind: a 4 um second harmonic under 8.5 um of per-phase noise. The raw
  // range of 360 such values is about d2(360) x 8.5 = 52 um too large; the corrected one is not.
  const int trials = 120;
  int covered = 0;
  double raw_bias = 0.0;
  double corrected_bias = 0.0;
  for (int t = 0; t < trials; ++t) {
    const Trial trial = FourierTrial(1, 2, 0.004, 0.0085, 100 + t);
    covered += trial.covered;
    raw_bias += trial.raw_minus_truth / trials;
    corrected_bias += trial.value_minus_truth / trials;
  }
  EXPECT_GT(raw_bias, 0.040);
  EXPECT_LT(std::abs(corrected_bias), 0.0006);  // a few standard errors of the mean over 120 trials
  // 95 % nominal; 120 trials: binomial sd 2 %, bounds at about 3 sd.
  EXPECT_GE(covered, 0.89 * trials);
  EXPECT_LE(covered, 0.995 * trials);
}

// The same harmonic at 6.3 sigma of its amplitude's noise, 24 harmonics tried: an estimator that
// knew which harmonic is real would scatter by 2 sigma_a = 2 x 8.5 um x sqrt(2 / 360) = 1.27 um
// (the information limit of the PV of one harmonic). Data whose harmonic comes out low make many
// replicates lose it; taken over all replicates, the spread (1.79 um on average) would overstate
// the estimate's scatter and cover 97-98 %. The stated u stays within a fifth of the limit, and the
// estimates' scatter within a third.
TEST(EstimateNoiseCorrectedPv, StatesTheScatterOfARangeNearTheInformationLimit) {
  const int trials = 200, columns = 360;
  const double amplitude = 0.004, sigma = 0.0085;
  const double limit = 2.0 * sigma * std::sqrt(2.0 / columns);
  double u_sum = 0.0, error_sum = 0.0, error_squares = 0.0;
  int covered = 0;
  for (int t = 0; t < trials; ++t) {
    std::mt19937 rng(3000 + t);
    std::normal_distribution<double> noise(0.0, sigma);
    std::vector<double> values(columns), sigmas(columns, sigma);
    for (int j = 0; j < columns; ++j)
      values[j] = amplitude * std::cos(2 * 2.0 * std::numbers::pi * j / columns) + noise(rng);
    const NoiseCorrectedPv pv = EstimateNoiseCorrectedPv(
        values, sigmas, 1, columns, {.max_order = 24, .replicates = 100, .seed = 9u + t});
    const double error = pv.value - 2.0 * amplitude;
    u_sum += pv.standard_uncertainty;
    error_sum += error;
    error_squares += error * error;
    covered += std::abs(error) <= 1.96 * pv.standard_uncertainty;
  }
  const double mean_u = u_sum / trials;
  const double scatter = std::sqrt(error_squares / trials - std::pow(error_sum / trials, 2));
  EXPECT_LT(mean_u, 1.2 * limit) << mean_u << " against the limit " << limit;
  EXPECT_LT(scatter, 1.35 * limit) << scatter << " against the limit " << limit;
  // 95 % nominal; 200 trials: binomial sd 1.5 %, bounds at about 3 sd.
  EXPECT_GE(covered, 0.905 * trials);
  EXPECT_LE(covered, 0.99 * trials);
}

TEST(EstimateNoiseCorrectedPv, TakesTheLargestRowOfAMap) {
  const int trials = 60;
  int covered = 0;
  for (int t = 0; t < trials; ++t) covered += FourierTrial(20, 1, 2.0, 0.3, 500 + t).covered;
  EXPECT_GE(covered, 0.85 * trials);
}

TEST(EstimateNoiseCorrectedPv, FitsLegendrePolynomialsAndLeavesOutTheLowOrders) {
  // A P2 + P3 profile with a constant and a slope that pv_from_order = 2 leaves out: the truth
  // is the PV of the profile less its least-squares line over the 81 nodes (solved by hand:
  // the nodes are symmetric, so the line's mean and slope separate).
  const int columns = 81;
  std::vector<double> values(columns), sigmas(columns, 1e-9), u(columns);
  double mean = 0.0, slope_num = 0.0, slope_den = 0.0;
  for (int j = 0; j < columns; ++j) {
    u[j] = -1.0 + 2.0 * j / (columns - 1);
    values[j] =
        7.0 + 2.0 * u[j] + 0.5 * (3 * u[j] * u[j] - 1) + 0.3 * 0.5 * (5 * u[j] * u[j] * u[j] - 3 * u[j]);
    mean += values[j] / columns;
    slope_num += values[j] * u[j];
    slope_den += u[j] * u[j];
  }
  double low = 1e9, high = -1e9;
  for (int j = 0; j < columns; ++j) {
    const double rest = values[j] - mean - slope_num / slope_den * u[j];
    low = std::min(low, rest), high = std::max(high, rest);
  }
  const NoiseCorrectedPv pv = EstimateNoiseCorrectedPv(
      values, sigmas, 1, columns, {.basis = SmoothBasis::kLegendre, .max_order = 8, .pv_from_order = 2});
  EXPECT_EQ(pv.order, 3);
  EXPECT_NEAR(pv.value, high - low, 1e-6);
}

// Sections whose points lie where a helix crossed them: row r's 80 points sit at u_j = -1 +
// (2 j + 1 + f_r) / 81 with f_r = r / rows (a fraction of a spacing, growing with the row), and
// every tenth point is missing. The rows are a P4 of amplitude A (1 + 0.2 cos(2 pi r / rows)) plus
// noise; the truth is the largest row's PV of P4 over the whole interval, 1.2 A (1 + 3/7) (P4 is 1
// at the ends and -3/7 at u^2 = 3/7), which no row's points reach.
Trial PositionedTrial(double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  const int rows = 90, columns = 80;
  const double amplitude = 0.2;
  std::vector<double> values(rows * columns), sigmas(values.size(), sigma), u(values.size());
  for (int r = 0; r < rows; ++r) {
    const double scale = amplitude * (1.0 + 0.2 * std::cos(2.0 * std::numbers::pi * r / rows));
    for (int j = 0; j < columns; ++j) {
      const std::size_t k = static_cast<std::size_t>(r) * columns + j;
      u[k] = -1.0 + (2.0 * j + 1.0 + static_cast<double>(r) / rows) / 81.0;
      const double x2 = u[k] * u[k];
      values[k] = (j + r) % 10 == 0 ? NAN : scale * (35.0 * x2 * x2 - 30.0 * x2 + 3.0) / 8.0 + noise(rng);
    }
  }
  const double truth = 1.2 * amplitude * (1.0 + 3.0 / 7.0);
  const NoiseCorrectedPv pv = EstimateNoiseCorrectedPv(values, sigmas, u, rows, columns,
                                                       {.basis = SmoothBasis::kLegendre,
                                                        .max_order = 6,
                                                        .replicates = 100,
                                                        .across_rows_max_degree = 6,
                                                        .across_rows_basis = SmoothBasis::kFourier,
                                                        .across_rows_keep_sd = 5.0,
                                                        .seed = seed});
  return {pv.raw_pv - truth, pv.value - truth, std::abs(pv.value - truth) <= 1.96 * pv.standard_uncertainty};
}

TEST(EstimateNoiseCorrectedPv, FitsSectionsAtTheirOwnPointsAndTakesThePvOverTheInterval) {
  // Without noise the fit is exact; the PV over a grid of 401 points misses P4's minimum by at
  // most A P4''/2 (h/2)^2 = 0.24 x 15 / 2 x 0.0025^2, about 1e-5 relative.
  EXPECT_NEAR(PositionedTrial(1e-9, 1).value_minus_truth, 0.0, 1e-6);
  const int trials = 60;
  int covered = 0;
  double bias = 0.0, raw_bias = 0.0;
  for (int t = 0; t < trials; ++t) {
    const Trial trial = PositionedTrial(0.05, 700 + t);
    covered += trial.covered;
    bias += trial.value_minus_truth / trials;
    raw_bias += trial.raw_minus_truth / trials;
  }
  EXPECT_GT(raw_bias, 0.05);  // the raw PV of 90 rows of noisy points
  EXPECT_LT(std::abs(bias), 0.004);
  // 95 % nominal; 60 trials: binomial sd 2.8 %, bounds at about 3 sd.
  EXPECT_GE(covered, 0.86 * trials);
}

TEST(EstimateNoiseCorrectedPv, FillsMissingValuesAndRefusesBadShapes) {
  std::vector<double> values(360), sigmas(360, 0.01);
  for (int j = 0; j < 360; ++j) values[j] = std::cos(2.0 * std::numbers::pi * j / 360);
  values[0] = values[1] = NAN;  // the peak at 0 deg is missing: interpolated across the wrap
  const NoiseCorrectedPv pv = EstimateNoiseCorrectedPv(values, sigmas, 1, 360, {.max_order = 6});
  EXPECT_NEAR(pv.value, 2.0, 0.01);
  EXPECT_EQ(arcwheel::testing::ErrorMessageOf(
                [&] { (void)EstimateNoiseCorrectedPv(values, sigmas, 1, 360, {.replicates = 3}); },
                ErrorCode::kInvalidOption),
            "uncertainty.pv: NoiseCorrectedPvOptions::replicates = 3 violates >= 20");
  (void)arcwheel::testing::ErrorMessageOf([&] { (void)EstimateNoiseCorrectedPv(values, sigmas, 2, 360); },
                                          ErrorCode::kBadInput);
}

// The noise-free rows another operator bootstraps about: rows of a third harmonic whose amplitude
// grows along the rows, plus noise. Fitted along the rows, each row keeps the noise of a few
// coefficients: far below the noise of a value, and far below what the one row's own fit of the
// same harmonic would keep (2 coefficients' noise, sigma sqrt(2 / 360) = 0.075 sigma). A row with
// fewer than half its values present is left out: NaN throughout.
TEST(FitNoiseFreeRows, RemovesTheNoiseAndMarksTheRowsLeftOut) {
  const int rows = 40, columns = 360;
  const double sigma = 1.0;
  std::mt19937 rng(77);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> values(rows * columns), truth(values.size()), sigmas(values.size(), sigma);
  for (int r = 0; r < rows; ++r) {
    for (int j = 0; j < columns; ++j) {
      const auto k = static_cast<std::size_t>(r * columns + j);
      truth[k] = 0.5 * (1.0 + 0.1 * r) * std::cos(3.0 * 2.0 * std::numbers::pi * j / columns);
      values[k] = truth[k] + noise(rng);
    }
  }
  for (int j = 0; j < 200; ++j) values[static_cast<std::size_t>(5 * columns + j)] = NAN;
  const std::vector<double> fitted =
      FitNoiseFreeRows(values, sigmas, rows, columns, {.max_order = 12, .across_rows_max_degree = 10});
  ASSERT_EQ(fitted.size(), values.size());
  double squares = 0.0;
  int counted = 0;
  for (int r = 0; r < rows; ++r) {
    for (int j = 0; j < columns; ++j) {
      const auto k = static_cast<std::size_t>(r * columns + j);
      if (r == 5) {
        EXPECT_TRUE(std::isnan(fitted[k])) << j;
        continue;
      }
      squares += (fitted[k] - truth[k]) * (fitted[k] - truth[k]);
      ++counted;
    }
  }
  EXPECT_LT(std::sqrt(squares / counted), 0.05 * sigma);
}

// The bootstraps draw from Boost's twister (its state refill is branch-free) where they drew from
// the standard library's: seeded by the same std::seed_seq, it must be the same stream, or every
// type A uncertainty would move.
TEST(BootstrapStream, BoostsTwisterIsTheStandardsStreamForASeedSequence) {
  for (const std::uint64_t seed : {std::uint64_t{20261203}, std::uint64_t{0}, ~std::uint64_t{0}}) {
    for (const std::uint64_t replicate : {std::uint64_t{0}, std::uint64_t{1}, std::uint64_t{99}}) {
      std::seed_seq standard_seeds{seed, seed >> 32, replicate};
      std::seed_seq boost_seeds{seed, seed >> 32, replicate};
      std::mt19937_64 standard(standard_seeds);
      boost::random::mt19937_64 boost(boost_seeds);
      for (int i = 0; i < 100000; ++i) ASSERT_EQ(boost(), standard()) << "seed " << seed << ", draw " << i;
    }
  }
}

}  // namespace
}  // namespace arcwheel::uncertainty
