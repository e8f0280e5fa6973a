#include "processing/helix_spline.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

#include "core/check.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/parallel.h"
#include "processing/uniform_cubic_bspline.h"
#include "processing/valid_span.h"

namespace arcwheel::processing {
namespace {

// Relative weight (to the mean diagonal of the normal matrix) of the second-difference penalty
// (a P-spline, Eilers & Marx 1996). Inside a gap it makes the coefficients a straight line
// between the data around, and it holds the few-sample coefficients at a gap's edge to their
// neighbours. At 1e-4 it damps a lobe of order 100 (a 3.6 deg wave) by 0.06 % where the samples
// are dense; at 1e-7 the edge coefficients of a dropout swung by tens of micrometres.
constexpr double kPenaltyRelative = 1e-4;

std::size_t CountCells(double u_last, double u0, double h) {
  return static_cast<std::size_t>(std::floor((u_last - u0) / h)) + 1;
}

}  // namespace

// The weights of uniform_cubic_bspline.h as polynomials in t = f - 1/2 (times 6), lowest power
// first: centred, so that no power of t exceeds 1/2 and the sums of products below cancel no more
// than the products themselves would.
constexpr double kWeightPolynomials[4][4] = {
    {0.125, -0.75, 1.5, -1.0}, {2.875, -3.75, -1.5, 3.0}, {2.875, 3.75, -1.5, -3.0}, {0.125, 0.75, 1.5, 1.0}};

void HelixSpline::PowerSums::AddTo(std::size_t first, BandedSpd& normal, std::vector<double>& rhs,
                                   std::vector<int>& counts) const {
  // sum_i w_a(t_i) w_c(t_i) = sum_{k,l} W[a][k] W[c][l] sum_i t_i^(k+l) / 36, and
  // sum_i w_a(t_i) z_i = sum_k W[a][k] sum_i z_i t_i^k / 6.
  double t_sums[7];
  t_sums[0] = static_cast<double>(count);
  for (int m = 1; m < 7; ++m) t_sums[m] = t_powers[m];
  counts[first] += count;
  for (int a = 0; a < 4; ++a) {
    const double* wa = kWeightPolynomials[a];
    rhs[first + a] +=
        (wa[0] * z_t_powers[0] + wa[1] * z_t_powers[1] + wa[2] * z_t_powers[2] + wa[3] * z_t_powers[3]) / 6.0;
    for (int c = a; c < 4; ++c) {
      const double* wc = kWeightPolynomials[c];
      double product = 0.0;
      for (int k = 0; k < 4; ++k) {
        product += wa[k] * (wc[0] * t_sums[k] + wc[1] * t_sums[k + 1] + wc[2] * t_sums[k + 2] +
                            wc[3] * t_sums[k + 3]);
      }
      normal.Add(first + a, first + c, product / 36.0);
    }
  }
}

HelixSpline::Basis HelixSpline::BasisAt(double u) const {
  const double s = (u - u0_) / h_;
  double cell = std::floor(s);
  const double max_cell = static_cast<double>(cells_ - 1);
  cell = std::clamp(cell, 0.0, max_cell);
  const double f = s - cell;
  Basis b;
  b.first = static_cast<std::size_t>(cell);
  const UniformCubicWeights weights = UniformCubicBSplineWeights(f);
  for (int k = 0; k < 4; ++k) b.w[k] = weights.w[static_cast<std::size_t>(k)];
  return b;
}

HelixSpline::HelixSpline(std::span<const double> z, const HelixGeometry& geometry, double knot_step_deg)
    : h_(knot_step_deg), normal_(0) {
  Fit(z, geometry);
}

HelixSpline::HelixSpline(std::span<const float> z, const HelixGeometry& geometry, double knot_step_deg)
    : h_(knot_step_deg), normal_(0) {
  Fit(z, geometry);
}

template <typename T>
void HelixSpline::Fit(std::span<const T> z, const HelixGeometry& geometry) {
  const auto [first, last] = ValidSpan(z);
  ARCWHEEL_CHECK(first < last) << "no valid samples reached the helix spline";
  u_first_ = geometry.PhaseAt(first);
  u_last_ = geometry.PhaseAt(last - 1);
  u0_ = std::floor(u_first_ / h_) * h_;
  const std::size_t cells = CountCells(u_last_, u0_, h_);
  cells_ = cells;
  cell_counts_.assign(cells, 0);
  const std::size_t n = cells + 3;
  normal_ = BandedSpd(n);
  std::vector<double> rhs(n, 0.0);

  // Two workers accumulate the two halves of the scan into the normal equations. The phase rises
  // with the sample index, so the halves meet in one knot interval: the upper half sums what it
  // adds to the few rows the lower half also reaches in a small block of its own, added after
  // both have finished, and the rest in place. Always two halves, so that the order of the sums,
  // and with it every coefficient, does not depend on the machine.
  const std::size_t middle = first + (last - first) / 2;
  const std::size_t lower_last = middle > first ? middle - 1 : first;
  SharedRows shared;
  shared.begin = middle < last ? BasisAt(geometry.PhaseAt(middle)).first : n;
  shared.end = std::max(shared.begin, BasisAt(geometry.PhaseAt(lower_last)).first + BandedSpd::kBand + 1);
  shared.normal = BandedSpd(shared.end - shared.begin + BandedSpd::kBand);
  shared.rhs.assign(shared.end - shared.begin + BandedSpd::kBand, 0.0);
  shared.counts.assign(shared.end - shared.begin, 0);
  RunOnWorkers(2, [&, begin = first, end = last](int half) {
    if (half == 0) {
      Accumulate(z, geometry, begin, middle, rhs, nullptr);
    } else {
      Accumulate(z, geometry, middle, end, rhs, &shared);
    }
  });
  AddSharedRows(shared, shared.begin, shared.end + BandedSpd::kBand, rhs);
  ThrowIfInterrupted();
  // Penalty lambda * |D2 c|^2 with lambda relative to the mean diagonal.
  double mean_diagonal = 0.0;
  for (std::size_t i = 0; i < n; ++i) mean_diagonal += normal_.Get(i, i);
  mean_diagonal /= static_cast<double>(n);
  const double lambda = kPenaltyRelative * std::max(mean_diagonal, 1e-12);
  for (std::size_t r = 0; r + 2 < n; ++r) {
    const double d[3] = {1.0, -2.0, 1.0};
    for (int a = 0; a < 3; ++a) {
      for (int c = a; c < 3; ++c) normal_.Add(r + a, r + c, lambda * d[a] * d[c]);
    }
  }
  if (!normal_.Factorize()) {
    throw Error(ErrorCode::kFitFailed, "processing.spline",
                "the helix spline's normal matrix is not definite");
  }
  normal_.Solve(rhs);
  coefficients_ = std::move(rhs);
}

void HelixSpline::ReleaseValues() {
  std::vector<double>().swap(coefficients_);
  std::vector<int>().swap(cell_counts_);
}

void HelixSpline::AddSharedRows(SharedRows& shared, std::size_t from, std::size_t to,
                                std::vector<double>& rhs) {
  const std::size_t n = rhs.size();
  for (std::size_t i = from; i < std::min(to, n); ++i) {
    const std::size_t r = i - shared.begin;
    rhs[i] += shared.rhs[r];
    shared.rhs[r] = 0.0;
    if (r < shared.counts.size()) {
      cell_counts_[i] += shared.counts[r];
      shared.counts[r] = 0;
    }
    for (std::size_t j = i; j <= std::min(n - 1, i + BandedSpd::kBand); ++j) {
      normal_.Add(i, j, shared.normal.Get(r, j - shared.begin));
      shared.normal.Add(r, j - shared.begin, -shared.normal.Get(r, j - shared.begin));
    }
  }
}

template <typename T>
void HelixSpline::Accumulate(std::span<const T> z, const HelixGeometry& geometry, std::size_t begin,
                             std::size_t end, std::vector<double>& rhs, SharedRows* shared) {
  bool rows_of_its_own_added = shared == nullptr;
  // The samples of one knot interval in a row are summed as powers of t (below), and the
  // interval's sums go into the normal equations when the next interval begins.
  const auto add_interval = [&](std::size_t cell, const PowerSums& sums) {
    if (!rows_of_its_own_added && cell >= shared->end) {
      // The block's rows from `end` on are this half's alone: they go in now, before the samples
      // after them, so that every row sums its intervals in their order.
      AddSharedRows(*shared, shared->end, shared->end + BandedSpd::kBand, rhs);
      rows_of_its_own_added = true;
    }
    if (shared != nullptr && cell < shared->end) {
      sums.AddTo(cell - shared->begin, shared->normal, shared->rhs, shared->counts);
    } else {
      sums.AddTo(cell, normal_, rhs, cell_counts_);
    }
  };
  const double max_cell = static_cast<double>(cells_ - 1);
  std::size_t cell = 0;
  PowerSums sums;
  for (std::size_t i = begin; i < end; ++i) {
    const double value = z[i];
    if (!std::isfinite(value)) continue;
    // BasisAt's interval and fraction. s > -1 (u0 is the knot at or below the first phase), where
    // truncation and clamping to 0 give BasisAt's clamp(floor(s), 0, cells - 1), without the
    // compare-and-mask sequence that floor takes on the baseline x86-64 (no SSE4.1 rounding).
    const double s = (geometry.PhaseAt(i) - u0_) / h_;
    const double interval = std::min(static_cast<double>(static_cast<std::int64_t>(s)), max_cell);
    const auto this_cell = static_cast<std::size_t>(interval);
    if (this_cell != cell && sums.count > 0) {
      add_interval(cell, sums);
      sums = {};
    }
    cell = this_cell;
    sums.Add(s - interval - 0.5, value);
  }
  if (sums.count > 0) add_interval(cell, sums);
}

double HelixSpline::Value(double u) const {
  ARCWHEEL_CHECK(!coefficients_.empty()) << "the spline's values were released";
  const Basis b = BasisAt(u);
  double value = 0.0;
  for (int a = 0; a < 4; ++a) value += b.w[a] * coefficients_[b.first + a];
  return value;
}

double HelixSpline::VarianceFactorAt(const Basis& b, const BandedSpd::InverseBlock& inverse) {
  // The inverse is symmetric: the diagonal once, each entry above it twice.
  double v = 0.0;
  for (int a = 0; a < 4; ++a) {
    v += b.w[a] * b.w[a] * inverse.InverseInBand(b.first + a, 0);
    for (int c = a + 1; c < 4; ++c) v += 2.0 * b.w[a] * b.w[c] * inverse.InverseInBand(b.first + a, c - a);
  }
  return v;
}

void HelixSpline::VarianceFactors(std::span<const std::span<const double>> u_lists,
                                  std::span<const std::span<double>> factors) const {
  ARCWHEEL_CHECK(u_lists.size() == factors.size())
      << u_lists.size() << " lists, " << factors.size() << " outputs";
  // Points not yet given their factor: [0, remaining[k]) of list k. A point is due in the block
  // that holds the first of its four coefficients; the lists ascend, so their last points come
  // first in the downward sweep.
  std::vector<std::size_t> remaining(u_lists.size());
  for (std::size_t k = 0; k < u_lists.size(); ++k) {
    ARCWHEEL_CHECK(u_lists[k].size() == factors[k].size()) << "list " << k;
    ARCWHEEL_CHECK(std::is_sorted(u_lists[k].begin(), u_lists[k].end()))
        << "list " << k << " does not ascend";
    remaining[k] = u_lists[k].size();
  }
  // 128 kB of the inverse at a time.
  constexpr std::size_t kBlockRows = 4096;
  normal_.SweepSelectedInverse(kBlockRows, [&](const BandedSpd::InverseBlock& block) {
    for (std::size_t k = 0; k < u_lists.size(); ++k) {
      for (std::size_t& p = remaining[k]; p > 0; --p) {
        const Basis b = BasisAt(u_lists[k][p - 1]);
        if (b.first < block.first) break;
        factors[k][p - 1] = VarianceFactorAt(b, block);
      }
    }
  });
}

double HelixSpline::VarianceFactor(double u) const {
  double factor = 0.0;
  const std::span<const double> list(&u, 1);
  const std::span<double> out(&factor, 1);
  VarianceFactors(std::span(&list, 1), std::span(&out, 1));
  return factor;
}

int HelixSpline::Support(double u) const {
  ARCWHEEL_CHECK(!cell_counts_.empty()) << "the spline's cell counts were released";
  const double s = (u - u0_) / h_;
  const auto cell = static_cast<long>(std::floor(s));
  const double f = s - static_cast<double>(cell);
  // The two cells nearest u: its own and the neighbour on the nearer side.
  const long other = f < 0.5 ? cell - 1 : cell + 1;
  int count = 0;
  for (const long c : {cell, other}) {
    if (c >= 0 && c < static_cast<long>(cell_counts_.size()))
      count += cell_counts_[static_cast<std::size_t>(c)];
  }
  return count;
}

double HelixSpline::CovarianceFactorOfSum(const std::function<void(const TermSink&)>& terms,
                                          std::size_t block_rows) const {
  // v = sum_k w_k b(u_k) goes forward through the factor a block of rows at a time, each block
  // summed from its own pass over the terms: on a long spline no vector as long as it is held
  // beside the callers' terms (6 MB at 1e8 samples), for a pass over the terms per block (about
  // 10 ms at 1e7 samples, where v is held whole). Each entry of v sums its terms in their order, as
  // a whole vector would.
  const std::size_t n = normal_.size();
  if (block_rows == 0) block_rows = n <= (std::size_t{1} << 19) ? n : std::size_t{1} << 17;
  block_rows = std::max<std::size_t>(1, block_rows);
  std::vector<double> v(std::min(n, block_rows));
  BandedSpd::ForwardPass pass;
  for (std::size_t first = 0; first < n; first += block_rows) {
    const std::size_t end = std::min(n, first + block_rows);
    std::fill(v.begin(), v.end(), 0.0);
    terms([&](double u, double weight) {
      const Basis b = BasisAt(u);
      if (b.first + BandedSpd::kBand < first || b.first >= end) return;
      for (std::size_t a = 0; a < 4; ++a) {
        const std::size_t row = b.first + a;
        if (row >= first && row < end) v[row - first] += weight * b.w[a];
      }
    });
    normal_.InverseQuadraticFormRows(std::span(v).first(end - first), pass);
  }
  return pass.sum;
}

}  // namespace arcwheel::processing
