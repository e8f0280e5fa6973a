#include "processing/helix_spline.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <vector>

#include "acquisition/scan.h"
#include "core/nan.h"
#include "processing/helix_geometry.h"

namespace arcwheel::processing {
namespace {

// A scan without encoder, time or axial columns: sample i lies at phase start + 6 rpm dt i.
acquisition::Scan ScanOfReadings(std::vector<double> z_mm, double rpm, double sample_period_s,
                                 double start_phase_deg) {
  acquisition::Scan scan;
  scan.metadata.spindle_rpm = rpm;
  scan.metadata.feed_mm_per_min = 100.0;
  scan.metadata.sample_period_s = sample_period_s;
  scan.metadata.start_phase_deg = start_phase_deg;
  scan.z_mm = std::move(z_mm);
  return scan;
}

double PhaseOfSample(const acquisition::Scan& scan, std::size_t i) {
  return scan.metadata.start_phase_deg +
         6.0 * *scan.metadata.spindle_rpm * *scan.metadata.sample_period_s * static_cast<double>(i);
}

// The cardinal cubic B-spline on [0, 4] from its truncated-power form,
// (1/6) sum_k (-1)^k C(4, k) (t - k)_+^3: written independently of the code's four pieces.
// It vanishes outside [0, 4]; there the power sum cancels only to rounding of t^3.
double CardinalCubicBSpline(double t) {
  if (t <= 0.0 || t >= 4.0) return 0.0;
  constexpr double kBinomial[5] = {1, 4, 6, 4, 1};
  double sum = 0.0;
  for (int k = 0; k <= 4; ++k) {
    const double x = std::max(0.0, t - k);
    sum += (k % 2 == 0 ? 1.0 : -1.0) * kBinomial[k] * x * x * x;
  }
  return sum / 6.0;
}

// The penalised least-squares spline of helix_spline.h solved densely: knots u0 + k h from the
// knot at or below the first valid phase to the one after the last, basis function j =
// M((u - u0) / h - j + 3), penalty lambda |D2 c|^2 with lambda = 1e-4 times the mean diagonal
// of B^T B. Solved by QR of the stacked system [B; sqrt(lambda) D2] c = [z; 0], not through the
// normal equations the code forms.
struct DenseSpline {
  double u0 = 0.0, h = 1.0;
  Eigen::VectorXd coefficients;
  Eigen::MatrixXd inverse_normal;  // (B^T B + lambda D2^T D2)^-1

  Eigen::VectorXd BasisRow(double u) const {
    Eigen::VectorXd row(coefficients.size());
    for (Eigen::Index j = 0; j < row.size(); ++j)
      row(j) = CardinalCubicBSpline((u - u0) / h - static_cast<double>(j) + 3.0);
    return row;
  }
  double Value(double u) const { return BasisRow(u).dot(coefficients); }
  double VarianceFactor(double u) const {
    const Eigen::VectorXd b = BasisRow(u);
    return b.dot(inverse_normal * b);
  }
};

DenseSpline SolveDensely(const acquisition::Scan& scan, double h) {
  std::vector<double> u, z;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (std::isfinite(scan.z_mm[i])) {
      u.push_back(PhaseOfSample(scan, i));
      z.push_back(scan.z_mm[i]);
    }
  }
  DenseSpline s;
  s.h = h;
  s.u0 = std::floor(u.front() / h) * h;
  const auto n = static_cast<Eigen::Index>(std::floor((u.back() - s.u0) / h)) + 4;
  s.coefficients = Eigen::VectorXd::Zero(n);
  const auto m = static_cast<Eigen::Index>(u.size());
  Eigen::MatrixXd design(m, n);
  for (Eigen::Index r = 0; r < m; ++r) design.row(r) = s.BasisRow(u[static_cast<std::size_t>(r)]).transpose();
  const double lambda = 1e-4 * design.colwise().squaredNorm().mean();
  Eigen::MatrixXd stacked = Eigen::MatrixXd::Zero(m + n - 2, n);
  Eigen::VectorXd rhs = Eigen::VectorXd::Zero(m + n - 2);
  stacked.topRows(m) = design;
  for (Eigen::Index r = 0; r < m; ++r) rhs(r) = z[static_cast<std::size_t>(r)];
  for (Eigen::Index r = 0; r + 2 < n; ++r) {
    stacked(m + r, r) = std::sqrt(lambda);
    stacked(m + r, r + 1) = -2.0 * std::sqrt(lambda);
    stacked(m + r, r + 2) = std::sqrt(lambda);
  }
  const Eigen::HouseholderQR<Eigen::MatrixXd> qr(stacked);
  s.coefficients = qr.solve(rhs);
  // (S^T S)^-1 = R^-1 R^-T from the same QR.
  const Eigen::MatrixXd r_factor = qr.matrixQR().topRows(n).triangularView<Eigen::Upper>();
  const Eigen::MatrixXd r_inverse =
      r_factor.triangularView<Eigen::Upper>().solve(Eigen::MatrixXd::Identity(n, n));
  s.inverse_normal = r_inverse * r_inverse.transpose();
  return s;
}

TEST(HelixSpline, AgreesWithADenseQrSolveOfTheSamePenalisedProblem) {
  // 2.2 turns at 2.5 deg a sample with knots every 5 deg: two samples a knot interval, few enough
  // that the penalty matters. Invalid ends, a 15-sample dropout and a few invalid samples test the
  // valid span and the bridging.
  std::mt19937 rng(20261202);
  std::normal_distribution<double> noise(0.0, 1e-3);
  std::vector<double> z(317);
  for (std::size_t i = 0; i < z.size(); ++i) {
    const double u = 17.3 + 2.5 * static_cast<double>(i);
    z[i] = 0.02 * std::sin(u * std::numbers::pi / 60.0) + 1e-4 * u + noise(rng);
  }
  for (std::size_t i = 0; i < 4; ++i) z[i] = kNaN;
  for (std::size_t i = 310; i < z.size(); ++i) z[i] = kNaN;
  for (std::size_t i = 140; i < 155; ++i) z[i] = kNaN;
  for (const std::size_t i : {30u, 31u, 200u}) z[i] = kNaN;
  const acquisition::Scan scan = ScanOfReadings(z, 60.0, 2.5 / 360.0, 17.3);
  const HelixGeometry geometry(scan, 60.0);
  const HelixSpline spline(scan.z_mm, geometry, 5.0);
  const DenseSpline dense = SolveDensely(scan, 5.0);

  EXPECT_DOUBLE_EQ(spline.first_phase_deg(), PhaseOfSample(scan, 4));
  EXPECT_DOUBLE_EQ(spline.last_phase_deg(), PhaseOfSample(scan, 309));
  // The code solves the normal equations (condition number about 1e5 here, so rounding of about
  // 1e-11 relative); the two solutions agreed to 2e-14 when this test was written.
  double largest_value = 0.0, largest_variance = 0.0;
  for (double u = spline.first_phase_deg(); u <= spline.last_phase_deg(); u += 0.37) {
    largest_value = std::max(largest_value, std::abs(dense.Value(u)));
    largest_variance = std::max(largest_variance, dense.VarianceFactor(u));
  }
  for (double u = spline.first_phase_deg(); u <= spline.last_phase_deg(); u += 0.37) {
    EXPECT_NEAR(spline.Value(u), dense.Value(u), 1e-10 * largest_value) << "u = " << u;
    EXPECT_NEAR(spline.VarianceFactor(u), dense.VarianceFactor(u), 1e-10 * largest_variance) << "u = " << u;
  }
  // Many points at once, as a wheel map asks for its sections: three ascending lists (one empty)
  // whose points interleave along the helix, answered in one sweep.
  std::vector<std::vector<double>> lists(3);
  for (double u = spline.first_phase_deg(); u <= spline.last_phase_deg(); u += 0.37) {
    lists[static_cast<std::size_t>(std::lround(u / 0.37)) % 2].push_back(u);
  }
  std::vector<std::vector<double>> factors = {
      std::vector<double>(lists[0].size(), -1.0), std::vector<double>(lists[1].size(), -1.0), {}};
  const std::vector<std::span<const double>> list_views(lists.begin(), lists.end());
  const std::vector<std::span<double>> factor_views(factors.begin(), factors.end());
  spline.VarianceFactors(list_views, factor_views);
  for (std::size_t k = 0; k < 2; ++k) {
    ASSERT_GT(lists[k].size(), 100u);
    for (std::size_t p = 0; p < lists[k].size(); ++p) {
      EXPECT_NEAR(factors[k][p], dense.VarianceFactor(lists[k][p]), 1e-10 * largest_variance)
          << "u = " << lists[k][p];
    }
  }
  // The variance factor of a weighted sum: w^T B (S^T S)^-1 B^T w.
  const std::vector<std::pair<double, double>> terms = {
      {40.0, 0.5}, {41.2, -1.0}, {400.0, 2.0}, {700.1, 0.3}};
  Eigen::VectorXd v = Eigen::VectorXd::Zero(dense.coefficients.size());
  for (const auto& [u, w] : terms) v += w * dense.BasisRow(u);
  const double expected = v.dot(dense.inverse_normal * v);
  const double factor = spline.CovarianceFactorOfSum([&](const HelixSpline::TermSink& add) {
    for (const auto& [u, w] : terms) add(u, w);
  });
  EXPECT_NEAR(factor, expected, 1e-10 * expected);
  // In blocks of rows, down to one row a block (the terms' basis rows straddle the blocks): the
  // same sums in the same order.
  for (const std::size_t block_rows : {1u, 2u, 5u, 64u}) {
    EXPECT_EQ(spline.CovarianceFactorOfSum(
                  [&](const HelixSpline::TermSink& add) {
                    for (const auto& [u, w] : terms) add(u, w);
                  },
                  block_rows),
              factor)
        << "blocks of " << block_rows;
  }
}

// The normal equations are summed a knot interval at a time from powers of the fraction (the
// samples of a 1e7-sample scan come 33 to an interval, 140 at 1e8): the spline must stay the
// least-squares one to 1e-12, here with 50 samples an interval, invalid ones among them, and
// values far from zero (the sums of z t^k must not cancel digits away).
TEST(HelixSpline, ManySamplesAKnotIntervalGiveTheDenseSolutionTo1e12) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 3e-4);
  std::vector<double> z(5400);
  for (std::size_t i = 0; i < z.size(); ++i) {
    const double u = 3.1 + 0.1 * static_cast<double>(i);
    z[i] = 12.5 + 0.02 * std::sin(u * std::numbers::pi / 45.0) + noise(rng);
  }
  for (const std::size_t i : {0u, 999u, 1000u, 1001u, 4321u}) z[i] = kNaN;
  const acquisition::Scan scan = ScanOfReadings(z, 60.0, 0.1 / 360.0, 3.1);
  const HelixGeometry geometry(scan, 60.0);
  const HelixSpline spline(scan.z_mm, geometry, 5.0);
  const DenseSpline dense = SolveDensely(scan, 5.0);
  int compared = 0;
  for (double u = spline.first_phase_deg(); u <= spline.last_phase_deg(); u += 0.37, ++compared) {
    EXPECT_NEAR(spline.Value(u), dense.Value(u), 1e-12 * std::abs(dense.Value(u))) << "u = " << u;
  }
  EXPECT_GT(compared, 1000);
}

TEST(HelixSpline, SupportCountsTheValidSamplesInTheTwoNearestKnotIntervals) {
  std::vector<double> z(300, 0.0);
  for (std::size_t i = 100; i < 120; ++i) z[i] = kNaN;
  // Samples at 3.15 + 0.7 i deg never fall on a knot (even degrees), nor u = 5.1 + 0.25 k on a
  // knot or a knot interval's middle, so rounding cannot move a sample or u across a boundary.
  const acquisition::Scan scan = ScanOfReadings(z, 60.0, 0.7 / 360.0, 3.15);
  const HelixSpline spline(scan.z_mm, HelixGeometry(scan, 60.0), 2.0);
  const double u0 = 2.0;
  for (double u = 5.1; u < spline.last_phase_deg() - 2.0; u += 0.25) {
    // The knot interval of u and its neighbour on the side nearer to u.
    const double cell = std::floor((u - u0) / 2.0);
    const double other = (u - u0) / 2.0 - cell < 0.5 ? cell - 1 : cell + 1;
    const double low = u0 + 2.0 * std::min(cell, other), high = low + 4.0;
    int expected = 0;
    for (std::size_t i = 0; i < z.size(); ++i) {
      const double phase = PhaseOfSample(scan, i);
      expected += std::isfinite(z[i]) && phase >= low && phase < high ? 1 : 0;
    }
    EXPECT_EQ(spline.Support(u), expected) << "u = " << u;
  }
}

TEST(HelixSpline, RecoversAKnownSmoothSignalWithinItsOwnSigma) {
  // Five turns at 0.36 deg a sample, knots every deg, 0.5 um of white noise.
  const auto truth = [](double u) {
    return 0.01 * std::sin(2.0 * std::numbers::pi * u / 72.0) +
           0.003 * std::cos(3.0 * u * std::numbers::pi / 180.0) + 1e-5 * u;
  };
  constexpr double kNoiseMm = 0.5e-3;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, kNoiseMm);
  std::vector<double> z(5000);
  for (std::size_t i = 0; i < z.size(); ++i) z[i] = truth(0.36 * static_cast<double>(i)) + noise(rng);
  const acquisition::Scan scan = ScanOfReadings(z, 60.0, 0.001, 0.0);
  const HelixSpline spline(scan.z_mm, HelixGeometry(scan, 60.0), 1.0);
  double sum_z2 = 0.0;
  int n = 0;
  for (double u = 2.0; u < spline.last_phase_deg() - 2.0; u += 1.0, ++n) {
    const double sigma = kNoiseMm * std::sqrt(spline.VarianceFactor(u));
    const double z_score = (spline.Value(u) - truth(u)) / sigma;
    EXPECT_LT(std::abs(z_score), 4.5) << "u = " << u;
    sum_z2 += z_score * z_score;
  }
  // About 1800 nodes, neighbours correlated: the rms z-score is 1 within about 10 %, if the
  // smoothing bias is negligible and the variance factor is honest.
  EXPECT_NEAR(std::sqrt(sum_z2 / n), 1.0, 0.15);
  // Three samples per knot interval average down the noise (helix_spline.h: ~1.8x less).
  EXPECT_LT(kNoiseMm * std::sqrt(spline.VarianceFactor(900.5)), kNoiseMm / 1.3);
}

}  // namespace
}  // namespace arcwheel::processing
