#pragma once
// A least-squares cubic B-spline g(u) of the readings along the helix, in the unwrapped phase u.
//
// The wheel map is built from this spline rather than from one interpolated point per turn: at
// the paper's settings every knot interval (1 deg) holds about three samples, and all of them
// inform the value at each phase (method.md A, "things learned": ~1.8x less noise per phase).
// A small second-difference penalty keeps the normal matrix definite across dropouts and bridges
// them with a straight line; values there rest on few samples, Support() says how many and
// VarianceFactor() how well they are known.
//
// Uncertainty: with white noise of sigma per sample, Var g(u) = sigma^2 b(u)^T (A^T A)^-1 b(u),
// b(u) the four basis values; VarianceFactors() returns the factor after sigma^2, from the band
// of (A^T A)^-1 (the selected inverse), computed in blocks as it goes and never held whole. Values
// at the same phase on different turns are 360 knots apart and uncorrelated for all practical
// purposes; CovarianceFactorOfSum() gives the exact variance factor of any weighted sum of spline
// values.

#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "processing/banded_spd.h"
#include "processing/helix_geometry.h"

namespace arcwheel::processing {

class HelixSpline {
 public:
  // Fits z (NaN = invalid) over the span of valid samples with knots every knot_step_deg.
  // Throws Error{kFitFailed} if the system cannot be factorised.
  HelixSpline(std::span<const double> rho_mm, const HelixGeometry& geometry, double knot_step_deg);
  HelixSpline(std::span<const float> rho_mm, const HelixGeometry& geometry, double knot_step_deg);

  [[nodiscard]] double Value(double u_deg) const;
  // Var g(u) / sigma^2 at every u of each list (each in ascending order), into the entry of
  // `factors` at the same place (each as long as its list): one backward sweep of the selected
  // inverse for all of them.
  void VarianceFactors(std::span<const std::span<const double>> u_lists,
                       std::span<const std::span<double>> factors) const;
  // The same for one point: a whole sweep per call (VarianceFactors for many points).
  [[nodiscard]] double VarianceFactor(double u_deg) const;
  // Valid samples in the two knot intervals around u.
  [[nodiscard]] int Support(double u_deg) const;
  // sum_a sum_b w_a w_b Cov(g(u_a), g(u_b)) / sigma^2 for the (u, w) pairs that `terms` passes to
  // the function it is given: one forward pass of the banded factor.
  using TermSink = std::function<void(double u_deg, double weight)>;
  // `block_rows` > 0 passes the sum through the factor in blocks of that many rows, one pass over
  // the terms each (the same number); 0 holds it whole up to 2^19 rows (4 MB) and in blocks of
  // 2^17 beyond, where the spline is long and the callers' terms are many.
  [[nodiscard]] double CovarianceFactorOfSum(const std::function<void(const TermSink&)>& terms,
                                             std::size_t block_rows = 0) const;
  // Frees what only Value() and Support() read, the coefficients and the cell counts (8 MB at 1e8
  // samples), when a wheel map has taken its sections: it keeps the spline for the variances.
  void ReleaseValues();

  [[nodiscard]] double first_phase_deg() const { return u_first_; }
  [[nodiscard]] double last_phase_deg() const { return u_last_; }
  [[nodiscard]] double knot_step_deg() const { return h_; }

 private:
  struct Basis {
    std::size_t first = 0;
    double w[4] = {0, 0, 0, 0};
  };
  [[nodiscard]] Basis BasisAt(double u_deg) const;
  [[nodiscard]] static double VarianceFactorAt(const Basis& b, const BandedSpd::InverseBlock& inverse);
  // The rows [begin, end) of the normal equations that both halves of the scan reach, as the upper
  // half sums them (row r of the block is row begin + r).
  struct SharedRows {
    std::size_t begin = 0, end = 0;
    BandedSpd normal{0};
    std::vector<double> rhs;
    std::vector<int> counts;
  };
  template <typename T>
  void Fit(std::span<const T> z, const HelixGeometry& geometry);
  // The sums over the samples of one knot interval from which its terms of the normal equations
  // follow: t = (fraction of the interval) - 1/2, sum_i t_i^m (m <= 6, m = 0 the count) and
  // sum_i z_i t_i^m (m <= 3). Fewer operations a sample than adding each sample's fourteen
  // products, and the same terms to rounding (helix_spline_test holds the spline to a dense QR
  // solution within 1e-12).
  struct PowerSums {
    int count = 0;
    double t_powers[7] = {};
    double z_t_powers[4] = {};
    void Add(double t, double z) {
      const double t2 = t * t;
      const double t3 = t2 * t;
      ++count;
      t_powers[1] += t;
      t_powers[2] += t2;
      t_powers[3] += t3;
      t_powers[4] += t2 * t2;
      t_powers[5] += t2 * t3;
      t_powers[6] += t3 * t3;
      z_t_powers[0] += z;
      z_t_powers[1] += z * t;
      z_t_powers[2] += z * t2;
      z_t_powers[3] += z * t3;
    }
    // Adds the interval's terms to rows first .. first + 3 of `normal` and `rhs`, its count to
    // counts[first].
    void AddTo(std::size_t first, BandedSpd& normal, std::vector<double>& rhs,
               std::vector<int>& counts) const;
  };
  // Adds samples [begin, end) to the normal equations, right-hand side and cell counts; with
  // `shared`, those whose interval starts in its rows go there instead.
  template <typename T>
  void Accumulate(std::span<const T> z, const HelixGeometry& geometry, std::size_t begin, std::size_t end,
                  std::vector<double>& rhs, SharedRows* shared);
  // Moves rows [from, to) of `shared` into the normal equations (leaving zeros in the block).
  void AddSharedRows(SharedRows& shared, std::size_t from, std::size_t to, std::vector<double>& rhs);

  double u0_ = 0.0;  // first knot
  double h_ = 1.0;   // knot spacing
  double u_first_ = 0.0;
  double u_last_ = 0.0;
  std::size_t cells_ = 0;  // knot intervals
  std::vector<double> coefficients_;
  std::vector<int> cell_counts_;
  BandedSpd normal_;
};

}  // namespace arcwheel::processing
