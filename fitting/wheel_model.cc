#include "fitting/wheel_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <Eigen/Sparse>
#include <algorithm>
#include <array>
#include <boost/math/distributions/chi_squared.hpp>
#include <cmath>
#include <cstdint>
#include <map>
#include <numbers>
#include <numeric>

#include "core/check.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/parallel.h"
#include "processing/helix_geometry.h"
#include "processing/uniform_cubic_bspline.h"

namespace arcwheel::fitting {
namespace {

constexpr const char* kStage = "fitting.model";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

using Eigen::MatrixXd;
using Eigen::VectorXd;

// processing::UniformCubicBSplineWeights with 1/6 as a product: a division by 6 costs as much as
// the rest of a sample's row, and the weights differ in the last bit at most.
void CubicWeights(double f, double w[4]) {
  constexpr double kSixth = 1.0 / 6.0;
  const double g = 1.0 - f, f2 = f * f, f3 = f2 * f;
  w[0] = g * g * g * kSixth;
  w[1] = (3.0 * f3 - 6.0 * f2 + 4.0) * kSixth;
  w[2] = (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0) * kSixth;
  w[3] = f3 * kSixth;
}

// A periodic basis at one phase: the knot interval, the four coefficients it touches and their
// weights.
struct PeriodicAt {
  int interval = 0;
  int column[4];
  double w[4];
};

// Ra(c), a(c), b(c): `knots` coefficients spread evenly over a turn, wrapping around.
struct PeriodicBasis {
  int knots = 0;
  // The coefficients of interval j (0 <= j <= knots; j = knots at c just below 360 degrees,
  // where the division rounds up).
  void Columns(int j, int column[4]) const {
    for (int k = 0; k < 4; ++k) {
      const int i = j - 1 + k;
      column[k] = knots == 1 ? 0 : (i < 0 ? i + knots : (i >= knots ? i - knots : i));
    }
  }
  // As At, without the library's floor and the integer divisions (0 <= phase_deg < 360;
  // knots_per_deg = knots / 360).
  void Weights(double phase_deg, double knots_per_deg, PeriodicAt& at) const {
    if (knots == 1) {
      // A constant: its four weights, on the one coefficient, sum to 1.
      at = {0, {0, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}};
      return;
    }
    const double t = phase_deg * knots_per_deg;
    at.interval = static_cast<int>(t);
    CubicWeights(t - at.interval, at.w);
    Columns(at.interval, at.column);
  }
  void At(double phase_deg, int index[4], double weight[4]) const {
    const double t = phase_deg / 360.0 * knots;
    const double interval = std::floor(t);
    const processing::UniformCubicWeights cw = processing::UniformCubicBSplineWeights(t - interval);
    const int j = static_cast<int>(interval);
    for (int k = 0; k < 4; ++k) {
      index[k] = ((j - 1 + k) % knots + knots) % knots;
      weight[k] = cw.w[static_cast<std::size_t>(k)];
    }
  }
  // Row r of the returned matrix holds every coefficient's weight at phases_deg[r].
  [[nodiscard]] MatrixXd Matrix(std::span<const double> phases_deg) const {
    MatrixXd m = MatrixXd::Zero(static_cast<Eigen::Index>(phases_deg.size()), knots);
    for (std::size_t r = 0; r < phases_deg.size(); ++r) {
      int index[4];
      double weight[4];
      At(phases_deg[r], index, weight);
      for (int k = 0; k < 4; ++k) m(static_cast<Eigen::Index>(r), index[k]) += weight[k];
    }
    return m;
  }
};

// p(u): a cubic B-spline with uniform knots over [low_mm, low_mm + intervals * step_mm].
struct ProfileBasis {
  double low_mm = 0, step_mm = 1;
  int intervals = 1;
  [[nodiscard]] int size() const { return intervals + 3; }
  // First coefficient, weights and d(weight)/du at u (clamped to the span).
  int At(double u_mm, double weight[4], double slope[4]) const {
    const double t = std::clamp((u_mm - low_mm) / step_mm, 0.0, static_cast<double>(intervals));
    const int j = std::min(static_cast<int>(t), intervals - 1);
    const processing::UniformCubicWeights cw = processing::UniformCubicBSplineWeights(t - j);
    for (int k = 0; k < 4; ++k) {
      weight[k] = cw.w[static_cast<std::size_t>(k)];
      slope[k] = cw.dw[static_cast<std::size_t>(k)] / step_mm;
    }
    return j;
  }
  // As At, with 1 / step_mm given (a division per sample costs as much as the rest of the weights).
  int At(double u_mm, double per_step, double weight[4], double slope[4]) const {
    const double t = std::clamp((u_mm - low_mm) * per_step, 0.0, static_cast<double>(intervals));
    const int j = std::min(static_cast<int>(t), intervals - 1);
    const double f = t - j, g = 1.0 - f;
    CubicWeights(f, weight);
    slope[0] = -0.5 * g * g * per_step;
    slope[1] = (1.5 * f * f - 2.0 * f) * per_step;
    slope[2] = (-1.5 * f * f + f + 0.5) * per_step;
    slope[3] = 0.5 * f * f * per_step;
    return j;
  }
};

// Knots per turn of Ra(c), a(c) and b(c).
struct Knots {
  int radius = 0, axial = 0, runout = 0;
  bool operator==(const Knots&) const = default;
};

// Where each function's coefficients sit in the parameter vector [Ra, a, b, p].
struct Layout {
  PeriodicBasis radius, axial, runout;
  ProfileBasis profile;
  [[nodiscard]] Knots knots() const { return {radius.knots, axial.knots, runout.knots}; }
  [[nodiscard]] int a0() const { return radius.knots; }
  [[nodiscard]] int b0() const { return radius.knots + axial.knots; }
  [[nodiscard]] int p0() const { return b0() + runout.knots; }
  [[nodiscard]] int size() const { return p0() + profile.size(); }
};

// Where a sample's cells lie: the map's (phase, axial) grid, for the residual map.
struct Grid {
  std::size_t n_phase = 0, n_y = 0;
  double phase_step_deg = 0, y0_mm = 0, y_step_mm = 0;
  [[nodiscard]] bool empty() const { return n_phase == 0 || n_y < 2; }
  [[nodiscard]] std::size_t size() const { return n_phase * n_y; }
};

Grid GridOf(const processing::WheelMap& map) {
  Grid grid;
  grid.n_phase = map.n_phase();
  grid.n_y = map.n_y();
  if (grid.empty()) return grid;
  grid.phase_step_deg = 360.0 / static_cast<double>(grid.n_phase);
  grid.y0_mm = map.y_mm.front();
  grid.y_step_mm = map.y_mm[1] - map.y_mm[0];
  return grid;
}

// A sample's row of the Jacobian: the residual and the 16 non-zero entries, whose columns follow
// from `key` (the knot interval of Ra, a and b, and the profile interval).
struct Row {
  std::array<int, 4> key{};
  double value[16];
  double residual = 0;
};

// Evaluates the model at the coefficients theta for one sample after another. Where two of Ra, a
// and b have the same knots they share their B-spline weights.
class RowModel {
 public:
  RowModel(const Layout& layout, const VectorXd& theta)
      : layout_(layout),
        theta_(theta.data()),
        radius_per_deg_(layout.radius.knots / 360.0),
        axial_per_deg_(layout.axial.knots / 360.0),
        runout_per_deg_(layout.runout.knots / 360.0),
        profile_per_mm_(1.0 / layout.profile.step_mm) {}

  // False where the sample lies beyond the arc (never for a sane band).
  bool Evaluate(double phase_deg, double y_mm, double rho_mm, Row& row) const {
    PeriodicAt r, a, b;
    layout_.radius.Weights(phase_deg, radius_per_deg_, r);
    if (layout_.axial.knots == layout_.radius.knots) {
      a = r;
    } else {
      layout_.axial.Weights(phase_deg, axial_per_deg_, a);
    }
    if (layout_.runout.knots == layout_.radius.knots) {
      b = r;
    } else if (layout_.runout.knots == layout_.axial.knots) {
      b = a;
    } else {
      layout_.runout.Weights(phase_deg, runout_per_deg_, b);
    }
    double ra = 0, center_axial = 0, center_radial = 0;
    const double* theta_a = theta_ + layout_.a0();
    const double* theta_b = theta_ + layout_.b0();
    for (int k = 0; k < 4; ++k) {
      ra += r.w[k] * theta_[r.column[k]];
      center_axial += a.w[k] * theta_a[a.column[k]];
      center_radial += b.w[k] * theta_b[b.column[k]];
    }
    const double u = y_mm - center_axial;
    const double s2 = ra * ra - u * u;
    if (!(s2 > 0.0)) return false;
    const double s = std::sqrt(s2);
    double wp[4], sp[4];
    const int jp = layout_.profile.At(u, profile_per_mm_, wp, sp);
    const double* theta_p = theta_ + layout_.p0() + jp;
    double p = 0, dp = 0;
    for (int k = 0; k < 4; ++k) {
      p += wp[k] * theta_p[k];
      dp += sp[k] * theta_p[k];
    }
    row.residual = rho_mm - (center_radial + s + p);
    const double per_s = 1.0 / s;
    const double d_ra = ra * per_s, d_a = u * per_s - dp;
    for (int k = 0; k < 4; ++k) {
      row.value[k] = d_ra * r.w[k];
      row.value[4 + k] = d_a * a.w[k];
      row.value[8 + k] = b.w[k];
      row.value[12 + k] = wp[k];
    }
    row.key = {r.interval, a.interval, b.interval, jp};
    return true;
  }

  // The 16 columns of a row with this key.
  void Columns(const std::array<int, 4>& key, int column[16]) const {
    layout_.radius.Columns(key[0], column);
    layout_.axial.Columns(key[1], column + 4);
    layout_.runout.Columns(key[2], column + 8);
    for (int k = 0; k < 4; ++k) {
      column[4 + k] += layout_.a0();
      column[8 + k] += layout_.b0();
      column[12 + k] = layout_.p0() + key[3] + k;
    }
  }

 private:
  const Layout& layout_;
  const double* theta_;
  double radius_per_deg_, axial_per_deg_, runout_per_deg_, profile_per_mm_;
};

// J^T J (lower triangle until Symmetrise), J^T r and r^T r of the samples at one set of
// coefficients (J: d(model)/d(coefficient)).
struct NormalEquations {
  MatrixXd jtj;  // empty when the pass did not ask for it
  VectorXd jtr;
  double rss = 0.0;
  std::size_t samples = 0;
  void Add(const NormalEquations& other) {
    if (jtj.size() != 0) jtj += other.jtj;
    jtr += other.jtr;
    rss += other.rss;
    samples += other.samples;
  }
  void Symmetrise() {
    if (jtj.size() != 0) jtj.triangularView<Eigen::StrictlyUpper>() = jtj.transpose();
  }
};

// Neighbouring samples touch the same 16 coefficients (the phase crosses a knot every few dozen
// samples or more, u a profile knot every few turns): their Jacobian rows are summed into a small
// fixed-size block (its lower triangle), which is added into the normal equations only when the
// coefficients change.
class BlockAccumulator {
 public:
  BlockAccumulator(const RowModel& model, NormalEquations& into, bool normal_matrix)
      : model_(model), into_(into), normal_matrix_(normal_matrix) {}
  ~BlockAccumulator() { Flush(); }
  BlockAccumulator(const BlockAccumulator&) = delete;
  BlockAccumulator& operator=(const BlockAccumulator&) = delete;

  void Add(const Row& row) {
    if (row.key != key_) {
      Flush();
      key_ = row.key;
    }
    const Eigen::Map<const Vector16> values(row.value);
    if (normal_matrix_) {
      // The lower triangle, column by column (contiguous, so the compiler vectorises it): the same
      // products and sums as Eigen's rankUpdate, which as a generic call cost a fifth of a pass.
      for (int c = 0; c < 16; ++c) {
        const double vc = row.value[c];
        double* column = block_.col(c).data();
        for (int r = c; r < 16; ++r) column[r] += vc * row.value[r];
      }
    }
    rhs_.noalias() += row.residual * values;
    pending_ = true;
  }

  void Flush() {
    if (!pending_) return;
    int column[16];
    model_.Columns(key_, column);
    for (int r = 0; r < 16; ++r) into_.jtr[column[r]] += rhs_[r];
    if (normal_matrix_) {
      for (int c = 0; c < 16; ++c) {
        into_.jtj(column[c], column[c]) += block_(c, c);
        for (int r = c + 1; r < 16; ++r) {
          // Columns repeat where a function has one knot: block(r, c) is then also block(c, r).
          const int high = std::max(column[r], column[c]), low = std::min(column[r], column[c]);
          into_.jtj(high, low) += high == low ? 2.0 * block_(r, c) : block_(r, c);
        }
      }
      block_.setZero();
    }
    rhs_.setZero();
    pending_ = false;
  }

 private:
  using Block = Eigen::Matrix<double, 16, 16>;
  using Vector16 = Eigen::Matrix<double, 16, 1>;
  const RowModel& model_;
  NormalEquations& into_;
  bool normal_matrix_;
  std::array<int, 4> key_{-1, -1, -1, -1};
  Block block_ = Block::Zero();
  Vector16 rhs_ = Vector16::Zero();
  bool pending_ = false;
};

// The work is cut into this many parts whatever the number of cores, and their sums are added in
// order, so that the rounding, hence the result, does not depend on the machine.
constexpr int kParts = 8;

// The samples (per sample, NaN = invalid), read through the helix geometry on every pass (no copy
// of the scan).
struct HelixCells;

template <typename Sample>
struct Samples {
  std::span<const Sample> rho_mm;
  const processing::HelixGeometry& geometry;
  double band_low_mm, band_high_mm;
  const HelixCells* cells = nullptr;  // when set, the passes run on these instead of the samples
};

// What a pass over the samples accumulates.
struct PassRequest {
  // 1: every sample; k > 1: one sample from each run of k, at a pseudo-random place in the run
  // (fixed), so that the subsample cannot alias with the turn.
  std::size_t stride = 1;
  bool normal_matrix = true;   // J^T J (else J^T r and r^T r only)
  const Grid* grid = nullptr;  // also the residuals' sums per cell of the map's grid
};

// Sums of the residuals and their counts per cell of the grid, over part of its axial range.
struct CellSums {
  long first_axial = 0, axial_cells = 0;
  std::vector<double> sum;
  std::vector<std::uint32_t> count;
};

// The axial range of each part's samples in the band (whatever the coefficients).
struct PartRanges {
  std::array<double, kParts> low_y_mm{}, high_y_mm{};
};

struct PassResult {
  NormalEquations normal;
  std::vector<CellSums> cells;  // per part, when a grid was asked for
  PartRanges ranges;
};

std::size_t RunStart(std::size_t run, std::size_t stride) {
  // splitmix64's finaliser: a fixed, well-spread place in each run.
  std::uint64_t z = run + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return run * stride + static_cast<std::size_t>(z % stride);
}

// The axial cells that a part's samples between low_y_mm and high_y_mm can fall into.
CellSums CellSumsFor(const Grid& grid, double low_y_mm, double high_y_mm) {
  CellSums cells;
  if (!(low_y_mm <= high_y_mm)) return cells;
  const long last = static_cast<long>(grid.n_y) - 1;
  cells.first_axial =
      std::clamp(processing::RoundHalfAway((low_y_mm - grid.y0_mm) / grid.y_step_mm), 0L, last);
  const long high =
      std::clamp(processing::RoundHalfAway((high_y_mm - grid.y0_mm) / grid.y_step_mm), 0L, last);
  cells.axial_cells = high - cells.first_axial + 1;
  cells.sum.assign(grid.n_phase * static_cast<std::size_t>(cells.axial_cells), 0.0);
  cells.count.assign(cells.sum.size(), 0);
  return cells;
}

// The binned fit (docs/wheel_model.md, "Binned fit"). On a helix from the scan's settings the
// phase and the axial position are linear in the sample index, so the samples of a cell (a run on
// one turn within one knot interval) lie on a segment of a line in (phase, axial). Every sum of
// the normal equations over the cell is then taken from three weighted points on that line: the
// three-point Gauss rule of the samples' positions, which sums every polynomial of the position up
// to degree 5 as the samples do, with pseudo-values that give the sums of z, z d and z d^2 (d the
// position) as the samples' z do. The sums are exact where the model is a polynomial of degree 2
// along the cell; the error comes from its third derivative along a cell (docs: measured).
struct HelixCell {
  std::uint64_t first = 0;          // index of its first sample; it ends where the next cell begins
  std::uint32_t count = 0;          // valid samples in the band
  float rss_offset_mm2 = 0;         // the cell's sum of squares less the points' (constant in the model)
  double z_mean_mm = 0;             // the mean z of its samples
  std::array<float, 3> node{};      // the points' positions, index - first (within 2.5e-4)
  std::array<float, 3> weight{};    // the points' weights (they sum to count; unused points 0)
  std::array<float, 3> value_mm{};  // each point's pseudo-value less z_mean_mm
  [[nodiscard]] std::size_t points() const { return std::min<std::size_t>(count, 3); }
};

// Each part's cells, in the order of their samples, and the axial range of its samples.
struct HelixCells {
  std::array<std::vector<HelixCell>, kParts> parts;
  PartRanges ranges;
};

// A cell ends at the turn's end, at every knot of the fine fit's functions and of a 64-knot grid
// (so that it spans at most 1/64 turn whatever the knots), and after this many samples.
constexpr std::uint64_t kMaxCellSpan = 4096;
constexpr int kCellsPerTurn = 64;

// The knot counts at whose knots cells end: kCellsPerTurn and those of the fine fit's functions
// that do not divide it.
std::vector<double> CellCutsPerDeg(const Layout& fine) {
  std::vector<double> per_deg = {kCellsPerTurn / 360.0};
  for (const int knots : {fine.radius.knots, fine.axial.knots, fine.runout.knots}) {
    if (knots > 1 && kCellsPerTurn % knots != 0) per_deg.push_back(knots / 360.0);
  }
  return per_deg;
}

// The sums of a closed cell's samples about their mean position d and mean z.
struct CentralMoments {
  double n = 0, d2 = 0, d3 = 0, d4 = 0, d5 = 0, zd = 0, zd2 = 0, z2 = 0;
};

// The three-point Gauss rule of positions with these central moments: nodes x (sorted) and
// weights w with sum w x^j = the samples' sum d^j for j = 0..5.
void GaussRule(const CentralMoments& m, std::array<double, 3>& x, std::array<double, 3>& w) {
  // In units of the positions' standard deviation: moments 1, 0, 1, m3, m4, m5 per sample.
  const double sigma = std::sqrt(m.d2 / m.n);
  const double m3 = m.d3 / (m.n * sigma * sigma * sigma), m4 = m.d4 / (m.n * std::pow(sigma, 4)),
               m5 = m.d5 / (m.n * std::pow(sigma, 5));
  // The monic cubic orthogonal to 1, x and x^2 under the samples' positions: x^3 + a x^2 + b x + c.
  Eigen::Matrix3d hankel;
  hankel << 1.0, 0.0, 1.0, 0.0, 1.0, m3, 1.0, m3, m4;
  const Eigen::Vector3d cba = hankel.partialPivLu().solve(Eigen::Vector3d(-m3, -m4, -m5));
  const double c = cba[0], b = cba[1], a = cba[2];
  // Its three real roots (trigonometric form of the depressed cubic t^3 + p t + q).
  const double p = b - a * a / 3.0, q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
  const double r = 2.0 * std::sqrt(std::max(-p / 3.0, 0.0));
  const double cos3 = r > 0.0 ? std::clamp(3.0 * q / (p * r), -1.0, 1.0) : 0.0;
  const double theta = std::acos(cos3) / 3.0;
  for (std::size_t k = 0; k < 3; ++k) {
    x[k] = r * std::cos(theta - 2.0 * std::numbers::pi * static_cast<double>(k) / 3.0) - a / 3.0;
  }
  std::sort(x.begin(), x.end());
  // Powers as products: pow() per entry cost a fifth of a cell's closing.
  Eigen::Matrix3d vandermonde;
  for (int k = 0; k < 3; ++k) {
    const double xk = x[static_cast<std::size_t>(k)];
    vandermonde.col(k) << 1.0, xk, xk * xk;
  }
  const Eigen::Vector3d weights = vandermonde.partialPivLu().solve(Eigen::Vector3d(m.n, 0.0, m.n));
  for (std::size_t k = 0; k < 3; ++k) {
    w[k] = weights[static_cast<Eigen::Index>(k)];
    x[k] *= sigma;
  }
}

// A cell of the valid samples first..last (all in the band; n of them, their positions summing
// to sum_s and their z to sum_z_mm), from a second look at its samples (still in cache).
template <typename Sample>
HelixCell CloseCell(const Samples<Sample>& samples, std::uint64_t first, std::uint64_t last, double n,
                    double sum_s, double sum_z_mm) {
  HelixCell cell;
  cell.first = first;
  cell.count = static_cast<std::uint32_t>(n);
  const double center = sum_s / n;
  cell.z_mean_mm = sum_z_mm / n;
  CentralMoments m;
  m.n = n;
  std::size_t seen = 0;
  for (std::uint64_t i = first; i <= last; ++i) {
    const auto rho = static_cast<double>(samples.rho_mm[i]);
    if (!std::isfinite(rho)) continue;
    const double d = static_cast<double>(i - first) - center, e = rho - cell.z_mean_mm;
    if (seen < 3) {  // a cell of up to three samples keeps them as its points
      cell.node[seen] = static_cast<float>(i - first);
      cell.weight[seen] = 1.0f;
      cell.value_mm[seen] = static_cast<float>(e);
    }
    ++seen;
    const double d2 = d * d;
    m.d2 += d2;
    m.d3 += d2 * d;
    m.d4 += d2 * d2;
    m.d5 += d2 * d2 * d;
    m.zd += e * d;
    m.zd2 += e * d2;
    m.z2 += e * e;
  }
  if (seen <= 3) return cell;
  std::array<double, 3> x{}, w{};
  GaussRule(m, x, w);
  // Pseudo-values v / w: sum v = 0 (about the mean), sum v x = sum (z - mean) d, sum v x^2 =
  // sum (z - mean) d^2.
  Eigen::Matrix3d vandermonde;
  for (int k = 0; k < 3; ++k) {
    const double xk = x[static_cast<std::size_t>(k)];
    vandermonde.col(k) << 1.0, xk, xk * xk;
  }
  const Eigen::Vector3d v = vandermonde.partialPivLu().solve(Eigen::Vector3d(0.0, m.zd, m.zd2));
  double carried = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double vk = v[static_cast<Eigen::Index>(k)];
    cell.node[k] = static_cast<float>(center + x[k]);
    cell.weight[k] = static_cast<float>(w[k]);
    cell.value_mm[k] = static_cast<float>(vk / w[k]);
    carried += vk * vk / w[k];
  }
  cell.rss_offset_mm2 = static_cast<float>(m.z2 - carried);
  return cell;
}

// The samples of begin..end in the band, as an index range: on a helix from the settings the
// axial position is monotonic in the index (each operation of AxialAt rounds monotonically), so
// the band holds a run of them, found by bisection with the same test as a pass over each sample.
template <typename Sample>
std::pair<std::size_t, std::size_t> BandRun(const Samples<Sample>& samples, std::size_t begin,
                                            std::size_t end) {
  if (begin >= end) return {begin, begin};
  const processing::HelixGeometry& geometry = samples.geometry;
  const auto below = [&](std::size_t i) { return geometry.AxialAt(i) < samples.band_low_mm; };
  const auto above = [&](std::size_t i) { return geometry.AxialAt(i) > samples.band_high_mm; };
  // The first index in begin..end where `test` holds, for a test that holds from some index on.
  const auto first_where = [&](const auto& test) {
    std::size_t low = begin, high = end;
    while (low < high) {
      const std::size_t mid = low + (high - low) / 2;
      if (test(mid)) {
        high = mid;
      } else {
        low = mid + 1;
      }
    }
    return low;
  };
  const bool rising = geometry.AxialAt(end - 1) >= geometry.AxialAt(begin);
  const std::size_t first = rising ? first_where([&](std::size_t i) { return !below(i); })
                                   : first_where([&](std::size_t i) { return !above(i); });
  const std::size_t last = rising ? first_where(above) : first_where(below);
  return {first, std::max(first, last)};
}

// The index after `i` at which the next cell begins: the first sample past the next knot of any
// cut (the phase is linear in the index), at most kMaxCellSpan on.
std::size_t CellEnd(const processing::HelixGeometry& geometry, const std::vector<double>& cuts_per_deg,
                    std::size_t i) {
  const double deg_per_sample = geometry.PhaseAtIndex(1.0) - geometry.PhaseAtIndex(0.0);
  std::size_t end = i + kMaxCellSpan;
  if (deg_per_sample == 0.0) return end;
  const double phase = geometry.PhaseAtIndex(static_cast<double>(i));
  for (const double per_deg : cuts_per_deg) {
    const double knot = std::floor(phase * per_deg) + (deg_per_sample > 0.0 ? 1.0 : 0.0);
    const double at = std::ceil((knot / per_deg - phase) / deg_per_sample);
    if (at >= 1.0 && at < static_cast<double>(kMaxCellSpan))
      end = std::min(end, i + static_cast<std::size_t>(at));
  }
  return std::max(end, i + 1);
}

// One part's samples into cells: the binned fit's one pass before the residual map's.
template <typename Sample>
void BinPart(const Samples<Sample>& samples, const std::vector<double>& cuts_per_deg, int part,
             std::vector<HelixCell>& cells, double& low_y_mm, double& high_y_mm) {
  const std::size_t total = samples.rho_mm.size();
  const auto [begin, end] = BandRun(samples, total * static_cast<std::size_t>(part) / kParts,
                                    total * static_cast<std::size_t>(part + 1) / kParts);
  const processing::HelixGeometry& geometry = samples.geometry;
  if (begin < end) {  // a cell per cut per turn, and per kMaxCellSpan samples
    const double turns = std::abs(geometry.PhaseAt(end - 1) - geometry.PhaseAt(begin)) / 360.0 + 1.0;
    const double cuts = 360.0 * std::accumulate(cuts_per_deg.begin(), cuts_per_deg.end(), 0.0);
    cells.reserve(static_cast<std::size_t>(
        std::min(turns * cuts + static_cast<double>((end - begin) / kMaxCellSpan) + 1.0,
                 static_cast<double>(end - begin))));
  }
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (std::size_t from = begin; from < end;) {
    const std::size_t to = std::min(CellEnd(geometry, cuts_per_deg, from), end);
    double n = 0.0, sum_s = 0.0, sum_z = 0.0;
    std::size_t first = to, last = to;
    for (std::size_t i = from; i < to; ++i) {
      const auto rho = static_cast<double>(samples.rho_mm[i]);
      if (!std::isfinite(rho)) continue;
      if (n == 0.0) first = i;
      last = i;
      n += 1.0;
      sum_s += static_cast<double>(i - first);
      sum_z += rho;
    }
    if (n > 0.0) {
      cells.push_back(CloseCell(samples, first, last, n, sum_s, sum_z));
      for (const std::size_t i : {first, last}) {
        low = std::min(low, geometry.AxialAt(i));
        high = std::max(high, geometry.AxialAt(i));
      }
    }
    from = to;
  }
  low_y_mm = low;
  high_y_mm = high;
}

template <typename Sample>
HelixCells BinSamples(const Samples<Sample>& samples, const Layout& fine) {
  HelixCells cells;
  const std::vector<double> cuts_per_deg = CellCutsPerDeg(fine);
  ARCWHEEL_CHECK(cuts_per_deg.size() <= 4) << cuts_per_deg.size();
  const int workers = std::min(WorkerCount(0), kParts);
  RunOnWorkers(workers, [&](int worker) {
    for (int part = worker; part < kParts; part += workers) {
      const auto p = static_cast<std::size_t>(part);
      BinPart(samples, cuts_per_deg, part, cells.parts[p], cells.ranges.low_y_mm[p],
              cells.ranges.high_y_mm[p]);
    }
  });
  return cells;
}

// One part's cells as weighted points: J^T J, J^T r and r^T r of its samples, exact where the
// model is quadratic along each cell. The points' rows are scaled by the root of their weights.
void AccumulateCellsPart(const std::vector<HelixCell>& cells, const processing::HelixGeometry& geometry,
                         const RowModel& model, NormalEquations& normal, bool normal_matrix) {
  BlockAccumulator block(model, normal, normal_matrix);
  double rss = 0.0;
  std::size_t used = 0;
  std::array<Row, 3> rows;
  for (const HelixCell& cell : cells) {
    const std::size_t points = cell.points();
    const auto base = static_cast<double>(cell.first);
    bool inside = true;
    for (std::size_t k = 0; k < points && inside; ++k) {
      const double at = base + cell.node[k];
      const double c = processing::PhaseInTurn(geometry.PhaseAtIndex(at));
      inside = model.Evaluate(c, geometry.AxialAtIndex(at), cell.z_mean_mm + cell.value_mm[k], rows[k]);
    }
    if (!inside) continue;
    for (std::size_t k = 0; k < points; ++k) {
      Row& row = rows[k];
      const double root = std::sqrt(static_cast<double>(cell.weight[k]));
      for (double& value : row.value) value *= root;
      row.residual *= root;
      block.Add(row);
      rss += row.residual * row.residual;
    }
    rss += cell.rss_offset_mm2;
    used += cell.count;
  }
  normal.rss += rss;
  normal.samples += used;
}

// One part's share of a pass.
template <typename Sample>
void AccumulatePart(const Samples<Sample>& samples, const RowModel& model, const PassRequest& request,
                    int part, NormalEquations& normal, CellSums* cells, double& low_y_mm, double& high_y_mm) {
  const std::size_t total = samples.rho_mm.size();
  const std::size_t runs = (total + request.stride - 1) / request.stride;
  const std::size_t begin = runs * static_cast<std::size_t>(part) / kParts;
  const std::size_t end = runs * static_cast<std::size_t>(part + 1) / kParts;
  const processing::HelixGeometry& geometry = samples.geometry;
  BlockAccumulator block(model, normal, request.normal_matrix);
  Row row;
  // Locals, not the references, so that the loop keeps them in registers.
  double rss = 0.0, low = std::numeric_limits<double>::infinity(), high = -low;
  std::size_t used = 0;
  const double per_phase_cell = request.grid != nullptr ? 1.0 / request.grid->phase_step_deg : 0.0;
  const double per_axial_cell = request.grid != nullptr ? 1.0 / request.grid->y_step_mm : 0.0;
  for (std::size_t run = begin; run < end; ++run) {
    const std::size_t i = request.stride == 1 ? run : RunStart(run, request.stride);
    if (i >= total) continue;
    const auto rho = static_cast<double>(samples.rho_mm[i]);
    if (!std::isfinite(rho)) continue;
    const double y = geometry.AxialAt(i);
    if (y < samples.band_low_mm || y > samples.band_high_mm) continue;
    low = std::min(low, y);
    high = std::max(high, y);
    const double c = processing::PhaseInTurn(geometry.PhaseAt(i));
    if (!model.Evaluate(c, y, rho, row)) continue;
    block.Add(row);
    rss += row.residual * row.residual;
    ++used;
    if (cells == nullptr || cells->axial_cells == 0) continue;
    const Grid& grid = *request.grid;
    auto p = static_cast<std::size_t>(processing::RoundHalfAway(c * per_phase_cell));
    if (p >= grid.n_phase) p -= grid.n_phase;  // c rounds up to the turn's end
    const long a = processing::RoundHalfAway((y - grid.y0_mm) * per_axial_cell) - cells->first_axial;
    if (a < 0 || a >= cells->axial_cells) continue;
    const std::size_t cell = p * static_cast<std::size_t>(cells->axial_cells) + static_cast<std::size_t>(a);
    cells->sum[cell] += row.residual;
    ++cells->count[cell];
  }
  normal.rss += rss;
  normal.samples += used;
  low_y_mm = low;
  high_y_mm = high;
}

// One pass over the samples on every core. With a grid, each part sums the residuals over the
// axial range that `previous` (a pass over the same samples) found its samples in.
template <typename Sample>
PassResult Accumulate(const Samples<Sample>& samples, const Layout& layout, const VectorXd& theta,
                      const PassRequest& request, const PartRanges* previous = nullptr) {
  ARCWHEEL_CHECK(request.grid == nullptr || previous != nullptr) << "a residual map needs the parts' ranges";
  ARCWHEEL_CHECK(samples.cells == nullptr || (request.grid == nullptr && request.stride == 1))
      << "the cells make neither a residual map nor a subsample";
  const int n = layout.size();
  const RowModel model(layout, theta);
  std::vector<NormalEquations> parts(kParts);
  PassResult result;
  if (request.grid != nullptr && !request.grid->empty()) {
    for (int part = 0; part < kParts; ++part) {
      const auto p = static_cast<std::size_t>(part);
      result.cells.push_back(CellSumsFor(*request.grid, previous->low_y_mm[p], previous->high_y_mm[p]));
    }
  }
  const int workers = std::min(WorkerCount(0), kParts);
  RunOnWorkers(workers, [&](int worker) {
    for (int part = worker; part < kParts; part += workers) {
      const auto p = static_cast<std::size_t>(part);
      NormalEquations& normal = parts[p];
      if (request.normal_matrix) normal.jtj = MatrixXd::Zero(n, n);
      normal.jtr = VectorXd::Zero(n);
      if (samples.cells != nullptr) {
        AccumulateCellsPart(samples.cells->parts[p], samples.geometry, model, normal, request.normal_matrix);
        continue;
      }
      AccumulatePart(samples, model, request, part, normal, result.cells.empty() ? nullptr : &result.cells[p],
                     result.ranges.low_y_mm[p], result.ranges.high_y_mm[p]);
    }
  });
  if (samples.cells != nullptr) result.ranges = samples.cells->ranges;
  result.normal = std::move(parts[0]);
  for (std::size_t part = 1; part < parts.size(); ++part) result.normal.Add(parts[part]);
  result.normal.Symmetrise();
  return result;
}

// Mean residual per cell of the map's grid (um), NaN where no sample fell.
std::vector<double> ResidualMap(const Grid& grid, const std::vector<CellSums>& parts) {
  if (grid.empty()) return {};
  std::vector<double> sum(grid.size(), 0.0);
  std::vector<std::uint32_t> count(grid.size(),
                                   0);  // as CellSums::count: a cell holds fewer than 2^32 samples
  for (const CellSums& part : parts) {
    for (std::size_t p = 0; p < grid.n_phase; ++p) {
      for (long a = 0; a < part.axial_cells; ++a) {
        const std::size_t from = p * static_cast<std::size_t>(part.axial_cells) + static_cast<std::size_t>(a);
        const std::size_t to = p * grid.n_y + static_cast<std::size_t>(part.first_axial + a);
        sum[to] += part.sum[from];
        count[to] += part.count[from];
      }
    }
  }
  for (std::size_t cell = 0; cell < sum.size(); ++cell) {
    sum[cell] = count[cell] > 0 ? sum[cell] / static_cast<double>(count[cell]) * 1e3 : kNaN;
  }
  return sum;
}

// The model along the samples first..last of a helix cell (at most 1/64 turn): the cubic through
// its values at four Chebyshev points of the span (at the samples themselves when there are no
// more than four), whose error, of the model's fourth derivative along the cell, is some 1e-5 um
// on a lobed wheel. Valid is false where a point lies beyond the arc.
struct SpanModel {
  std::array<double, 4> x{}, c{};  // the points (sample indices) and Newton's coefficients
  std::size_t points = 0;
  bool valid = true;
  SpanModel(const RowModel& model, const processing::HelixGeometry& geometry, std::size_t first,
            std::size_t last) {
    points = std::min<std::size_t>(last - first + 1, 4);
    const double mid = 0.5 * static_cast<double>(first + last),
                 half = 0.5 * static_cast<double>(last - first);
    Row row;
    for (std::size_t k = 0; k < points; ++k) {
      x[k] = points < 4 || last - first < 4
                 ? static_cast<double>(first + k)
                 : mid + half * std::cos((2.0 * static_cast<double>(k) + 1.0) * std::numbers::pi / 8.0);
      const double phase = processing::PhaseInTurn(geometry.PhaseAtIndex(x[k]));
      valid = valid && model.Evaluate(phase, geometry.AxialAtIndex(x[k]), 0.0, row);
      c[k] = -row.residual;
    }
    for (std::size_t j = 1; j < points; ++j) {  // divided differences
      for (std::size_t k = points - 1; k >= j; --k) c[k] = (c[k] - c[k - 1]) / (x[k] - x[k - j]);
    }
  }
  [[nodiscard]] double At(double index) const {
    double value = c[points - 1];
    for (std::size_t k = points - 1; k-- > 0;) value = c[k] + (index - x[k]) * value;
    return value;
  }
};

// One part's residuals per cell of the map's grid. Within a helix cell (its samples run to the
// next cell's first) the phase and the axial position are monotonic in the index, so its samples
// fall into the map's cells in runs: each run's end is predicted from the rates and checked with
// the per-sample rule (found by bisection where the guess was off), and its residuals are summed
// against the model along the cell (SpanModel).
template <typename Sample>
void CellResidualsPart(const Samples<Sample>& samples, const std::vector<HelixCell>& cells,
                       const RowModel& model, const Grid& grid, int part, CellSums& sums) {
  if (sums.axial_cells == 0 || cells.empty()) return;
  const std::size_t total = samples.rho_mm.size();
  const std::size_t end = BandRun(samples, total * static_cast<std::size_t>(part) / kParts,
                                  total * static_cast<std::size_t>(part + 1) / kParts)
                              .second;
  const processing::HelixGeometry& geometry = samples.geometry;
  const double per_phase_cell = 1.0 / grid.phase_step_deg, per_axial_cell = 1.0 / grid.y_step_mm;
  // Map cells per sample along the phase and the axis.
  const double phase_rate = (geometry.PhaseAtIndex(1.0) - geometry.PhaseAtIndex(0.0)) * per_phase_cell;
  const double axial_rate = (geometry.AxialAtIndex(1.0) - geometry.AxialAtIndex(0.0)) * per_axial_cell;
  // Where the rates put the next map cell's first sample after `from`: a guess, checked below.
  const auto predicted_end = [&](std::size_t from) {
    const double at[2] = {processing::PhaseInTurn(geometry.PhaseAt(from)) * per_phase_cell,
                          (geometry.AxialAt(from) - grid.y0_mm) * per_axial_cell};
    const double rate[2] = {phase_rate, axial_rate};
    double steps = static_cast<double>(kMaxCellSpan);
    for (int k = 0; k < 2; ++k) {
      if (rate[k] > 0.0) steps = std::min(steps, (std::floor(at[k] + 0.5) + 0.5 - at[k]) / rate[k]);
      if (rate[k] < 0.0) steps = std::min(steps, (at[k] - std::ceil(at[k] - 0.5) + 0.5) / -rate[k]);
    }
    return from + std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(steps)));
  };
  // The map's cell of sample i as the pass over every sample finds it: (phase, axial - first_axial).
  const auto map_cell = [&](std::size_t i) {
    const double c = processing::PhaseInTurn(geometry.PhaseAt(i));
    auto p = static_cast<std::size_t>(processing::RoundHalfAway(c * per_phase_cell));
    if (p >= grid.n_phase) p -= grid.n_phase;  // c rounds up to the turn's end
    const long a =
        processing::RoundHalfAway((geometry.AxialAt(i) - grid.y0_mm) * per_axial_cell) - sums.first_axial;
    return std::pair<std::size_t, long>{p, a};
  };
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const HelixCell& cell = cells[k];
    const std::size_t to = k + 1 < cells.size() ? cells[k + 1].first : end;
    const SpanModel span(model, geometry, cell.first, to - 1);
    for (std::size_t from = cell.first; from < to;) {
      const std::pair<std::size_t, long> key = map_cell(from);
      // The run ends at the first index of another map cell: where predicted, if the rule agrees
      // there and one sample before; else found by bisection.
      const std::size_t guess = std::min(predicted_end(from), to);
      const bool guessed =
          (guess == to || map_cell(guess) != key) && (guess - 1 == from || map_cell(guess - 1) == key);
      std::size_t low = guessed ? guess : from + 1, high = to;
      while (!guessed && low < high) {
        const std::size_t mid = low + (high - low) / 2;
        if (map_cell(mid) != key) {
          high = mid;
        } else {
          low = mid + 1;
        }
      }
      if (span.valid && key.second >= 0 && key.second < sums.axial_cells) {
        double sum = 0.0;
        std::uint32_t count = 0;
        for (std::size_t i = from; i < low; ++i) {
          const auto rho = static_cast<double>(samples.rho_mm[i]);
          if (!std::isfinite(rho)) continue;
          sum += rho - span.At(static_cast<double>(i));
          ++count;
        }
        const std::size_t index =
            key.first * static_cast<std::size_t>(sums.axial_cells) + static_cast<std::size_t>(key.second);
        sums.sum[index] += sum;
        sums.count[index] += count;
      }
      from = low;
    }
  }
}

// The residual map of the binned fit at theta: one more pass over the samples, each residual
// against the model along its cell. Releases the cells before the map is summed.
template <typename Sample>
std::vector<double> CellResidualMap(const Samples<Sample>& samples, HelixCells& cells, const Grid& grid,
                                    const Layout& layout, const VectorXd& theta) {
  if (grid.empty()) return {};
  const RowModel model(layout, theta);
  std::vector<CellSums> sums;
  for (std::size_t part = 0; part < kParts; ++part) {
    sums.push_back(CellSumsFor(grid, cells.ranges.low_y_mm[part], cells.ranges.high_y_mm[part]));
  }
  const int workers = std::min(WorkerCount(0), kParts);
  RunOnWorkers(workers, [&](int worker) {
    for (int part = worker; part < kParts; part += workers) {
      const auto p = static_cast<std::size_t>(part);
      CellResidualsPart(samples, cells.parts[p], model, grid, part, sums[p]);
    }
  });
  for (std::vector<HelixCell>& part : cells.parts) std::vector<HelixCell>().swap(part);
  return ResidualMap(grid, sums);
}

// The constraints on p: its integrals against 1, u and u^2 over the band vanish. Returns an
// orthonormal basis of the coefficient vectors that meet them (size x (size - 3)).
MatrixXd ProfileNullSpace(const ProfileBasis& basis, double half_width_mm) {
  MatrixXd constraints = MatrixXd::Zero(3, basis.size());
  // Composite 4-point Gauss-Legendre: exact for the piecewise-cubic integrands times u^2 on each
  // subinterval that no knot crosses, and 1e-12 close where one does.
  constexpr double kNodes[4] = {-0.8611363115940526, -0.3399810435848563, 0.3399810435848563,
                                0.8611363115940526};
  constexpr double kWeights[4] = {0.3478548451374538, 0.6521451548625461, 0.6521451548625461,
                                  0.3478548451374538};
  const int pieces = 2048;
  const double h = 2.0 * half_width_mm / pieces;
  for (int piece = 0; piece < pieces; ++piece) {
    const double mid = -half_width_mm + (piece + 0.5) * h;
    for (int q = 0; q < 4; ++q) {
      const double u = mid + 0.5 * h * kNodes[q];
      double w[4], slope[4];
      const int first = basis.At(u, w, slope);
      for (int k = 0; k < 4; ++k) {
        const double m = 0.5 * h * kWeights[q] * w[k];
        constraints(0, first + k) += m;
        constraints(1, first + k) += m * u;
        constraints(2, first + k) += m * u * u;
      }
    }
  }
  Eigen::JacobiSVD<MatrixXd> svd(constraints, Eigen::ComputeFullV);
  return svd.matrixV().rightCols(basis.size() - 3);
}

// The matrix that writes a periodic spline of `coarse` knots in the basis of `fine` knots (exact:
// the coarse knots are a subset of the fine ones).
MatrixXd Refinement(int fine, int coarse) {
  // The choice of knots asks for the same few matrices again and again.
  thread_local std::map<std::pair<int, int>, MatrixXd> known;
  if (const auto it = known.find({fine, coarse}); it != known.end()) return it->second;
  std::vector<double> phases;
  for (int i = 0; i < 8 * fine; ++i) phases.push_back((i + 0.37) * 360.0 / (8.0 * fine));
  const MatrixXd fine_basis = PeriodicBasis{fine}.Matrix(phases);
  const MatrixXd coarse_basis = PeriodicBasis{coarse}.Matrix(phases);
  // The exact matrix is banded (a coarse function spans few fine ones), its entries 1 / ratio^3
  // (2.4e-4 for 4 knots in 64) or more; the solve leaves up to 1e-15 elsewhere, which would fill
  // the whole block for Project's products.
  MatrixXd refinement = fine_basis.colPivHouseholderQr().solve(coarse_basis);
  refinement = refinement.unaryExpr([](double v) { return std::abs(v) < 1e-12 ? 0.0 : v; });
  return known[{fine, coarse}] = refinement;
}

// Maps reduced parameters [Ra, a, b (coarse knots), p in the constraints' null space] to the full
// parameters of `fine`.
MatrixXd Reduction(const Layout& fine, const Knots& coarse, const MatrixXd& null_space) {
  const MatrixXd radius = Refinement(fine.radius.knots, coarse.radius);
  const MatrixXd axial = Refinement(fine.axial.knots, coarse.axial);
  const MatrixXd runout = Refinement(fine.runout.knots, coarse.runout);
  const Eigen::Index a0 = coarse.radius, b0 = a0 + coarse.axial, p0 = b0 + coarse.runout;
  MatrixXd t = MatrixXd::Zero(fine.size(), p0 + null_space.cols());
  t.block(0, 0, radius.rows(), radius.cols()) = radius;
  t.block(fine.a0(), a0, axial.rows(), axial.cols()) = axial;
  t.block(fine.b0(), b0, runout.rows(), runout.cols()) = runout;
  t.block(fine.p0(), p0, null_space.rows(), null_space.cols()) = null_space;
  return t;
}

// T^T H T for a reduction T (mostly zeros: block-diagonal, and sparse within its blocks).
// Each column's non-zero entries are listed once, and the products run over them: H T as sums of
// H's columns (contiguous, vectorised), T^T (H T) as short sums per entry of its lower triangle.
// Eigen's sparse products cost ten times as much on these few-hundred-row matrices.
MatrixXd Project(const MatrixXd& h, const MatrixXd& t) {
  const Eigen::Index n = t.rows(), m = t.cols();
  std::vector<Eigen::Index> start = {0}, row;  // column j's entries: start[j] .. start[j + 1]
  std::vector<double> value;
  for (Eigen::Index j = 0; j < m; ++j) {
    for (Eigen::Index i = 0; i < n; ++i) {
      if (t(i, j) == 0.0) continue;
      row.push_back(i);
      value.push_back(t(i, j));
    }
    start.push_back(static_cast<Eigen::Index>(row.size()));
  }
  const auto entries = [&](Eigen::Index j) {
    return std::pair<std::size_t, std::size_t>(start[static_cast<std::size_t>(j)],
                                               start[static_cast<std::size_t>(j) + 1]);
  };
  MatrixXd ht = MatrixXd::Zero(n, m);
  for (Eigen::Index j = 0; j < m; ++j) {
    const auto [from, to] = entries(j);
    for (std::size_t e = from; e < to; ++e) ht.col(j).noalias() += value[e] * h.col(row[e]);
  }
  MatrixXd result(m, m);
  for (Eigen::Index i = 0; i < m; ++i) {
    const auto [from, to] = entries(i);
    for (Eigen::Index j = 0; j <= i; ++j) {
      double sum = 0.0;
      for (std::size_t e = from; e < to; ++e) sum += value[e] * ht(row[e], j);
      result(i, j) = sum;
      result(j, i) = sum;
    }
  }
  return result;
}

// H^-1 b for a normal matrix: by Cholesky, or by LDL^T where rounding leaves H not quite
// positive definite.
VectorXd SolveNormal(const MatrixXd& h, const VectorXd& b) {
  const Eigen::LLT<MatrixXd> llt(h);
  if (llt.info() == Eigen::Success) return llt.solve(b);
  return h.ldlt().solve(b);
}

struct Solution {
  VectorXd theta;               // the solution: `at` plus the last step
  VectorXd at;                  // the coefficients where `normal` was accumulated
  MatrixXd reduction;           // full = reduction * reduced
  MatrixXd reduced_jtj;         // at `at` (or, after a chord step, at the pass before)
  NormalEquations normal;       // at `at`
  std::vector<CellSums> cells;  // the residuals per cell at `at`, when asked for
  PartRanges ranges;            // of the passes' parts
  int iterations = 0;
  bool converged = false;
};

struct ConvergeRequest {
  std::size_t stride = 1;  // as PassRequest
  int max_iterations = 40;
  // When not empty: the reduced J^T J of a pass at coefficients so close to the start that J
  // differs only in its last digits; the first iteration then accumulates only J^T r and r^T r
  // (a chord step: the fixed point, J^T r = 0, is the same).
  MatrixXd reduced_jtj{};
  const Grid* grid = nullptr;          // sum the residuals per cell in every pass
  const PartRanges* ranges = nullptr;  // of an earlier pass over the same samples
  bool throw_if_not_converged = true;
};

// Gauss-Newton on the reduced parameters, halving a step that raises the residual. Converged when
// the step would lower the residual sum of squares by a negligible fraction (the linearised
// decrease is step . J^T r), or moves no coefficient by more than 1e-11 mm.
template <typename Sample>
Solution Converge(const Samples<Sample>& samples, const Layout& layout, const MatrixXd& reduction,
                  VectorXd theta, ConvergeRequest request) {
  Solution solution;
  solution.reduction = reduction;
  VectorXd previous = theta;
  double previous_rss = std::numeric_limits<double>::infinity();
  MatrixXd chord_jtj = std::move(request.reduced_jtj);
  for (int iteration = 1; iteration <= request.max_iterations; ++iteration) {
    ThrowIfInterrupted();
    const bool chord = chord_jtj.size() != 0;
    PassResult pass =
        Accumulate(samples, layout, theta,
                   {.stride = request.stride, .normal_matrix = !chord, .grid = request.grid}, request.ranges);
    NormalEquations& normal = pass.normal;
    if (normal.rss > previous_rss * (1.0 + 1e-12) && (theta - previous).cwiseAbs().maxCoeff() > 1e-13) {
      theta = previous + 0.5 * (theta - previous);  // the step overshot: take half of it
      chord_jtj.resize(0, 0);
      continue;
    }
    MatrixXd reduced_jtj = chord ? chord_jtj : Project(normal.jtj, reduction);
    chord_jtj.resize(0, 0);  // a chord step once only
    const VectorXd step = reduction * SolveNormal(reduced_jtj, reduction.transpose() * normal.jtr);
    solution.at = theta;
    solution.theta = theta;
    solution.reduced_jtj = std::move(reduced_jtj);
    solution.normal = std::move(normal);
    solution.cells = std::move(pass.cells);
    solution.ranges = pass.ranges;
    solution.iterations = iteration;
    if (!step.allFinite()) break;
    previous = theta;
    previous_rss = solution.normal.rss;
    theta += step;
    const double decrease = step.dot(solution.normal.jtr);
    if (decrease <= 1e-10 * solution.normal.rss || step.cwiseAbs().maxCoeff() < 1e-11) {
      solution.theta = theta;
      solution.converged = true;
      return solution;
    }
  }
  if (request.throw_if_not_converged) {
    throw Error(ErrorCode::kFitFailed, kStage,
                fmt::format("the wheel model did not converge in {} Gauss-Newton iterations",
                            request.max_iterations));
  }
  return solution;
}

// One Gauss-Newton step over every sample from theta, without the test for convergence: the fine
// fit whose normal equations choose the knots, at a start close enough for its linearisation.
template <typename Sample>
Solution OneStep(const Samples<Sample>& samples, const Layout& layout, const MatrixXd& reduction,
                 const VectorXd& theta) {
  PassResult pass = Accumulate(samples, layout, theta, {});
  Solution solution;
  solution.reduction = reduction;
  solution.at = theta;
  solution.reduced_jtj = Project(pass.normal.jtj, reduction);
  solution.theta =
      theta + reduction * SolveNormal(solution.reduced_jtj, reduction.transpose() * pass.normal.jtr);
  solution.normal = std::move(pass.normal);
  solution.ranges = pass.ranges;
  solution.iterations = 1;
  return solution;
}

// The fine fit's normal equations linearised where they were accumulated, restricted to coarser
// knots (theta = T x): the x minimising RSS = |r - J (T x - at)|^2, that RSS, and T^T J^T J T.
// The minimum is sought as a correction to x0, T's least-squares approximation of `at`: the sums
// of squares then stay near the RSS, instead of some 1e10 times it (|J at|^2), where rounding
// would leave the RSS uncertain by more than the information criterion's penalties at 1e7 samples.
struct LinearisedFit {
  VectorXd x;
  double rss = 0.0;
  MatrixXd reduced_jtj{};
};

LinearisedFit Linearise(const Solution& fine, const MatrixXd& reduction) {
  const MatrixXd& jtj = fine.normal.jtj;
  const Eigen::SparseMatrix<double> t = reduction.sparseView();
  const Eigen::SparseMatrix<double> tt = t.transpose() * t;  // block-diagonal
  const VectorXd x0 = Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>>(tt).solve(t.transpose() * fine.at);
  const VectorXd g = fine.at - reduction * x0;
  const VectorXd jtj_g = jtj * g;
  const VectorXd jtz = fine.normal.jtr + jtj_g;
  const double ztz = fine.normal.rss + 2.0 * g.dot(fine.normal.jtr) + g.dot(jtj_g);
  const VectorXd rhs = reduction.transpose() * jtz;
  LinearisedFit fit;
  fit.reduced_jtj = Project(jtj, reduction);
  const VectorXd correction = SolveNormal(fit.reduced_jtj, rhs);
  fit.x = x0 + correction;
  fit.rss = std::max(ztz - rhs.dot(correction), 0.0);
  return fit;
}

// The knot counts to choose from: the one given, else kKnotChoices, and for Ra and a also a
// single knot (a constant function), so that a wheel without variation is modelled as such.
std::vector<int> KnotCandidates(int fixed, bool constant_allowed) {
  if (fixed > 0) return {fixed};
  std::vector<int> choices(std::begin(kKnotChoices), std::end(kKnotChoices));
  if (constant_allowed) choices.insert(choices.begin(), 1);
  return choices;
}

// Value and 1-sigma of w^T theta.
std::pair<double, double> Linear(const VectorXd& w, const VectorXd& theta, const MatrixXd& covariance) {
  return {w.dot(theta), std::sqrt(std::max(w.dot(covariance * w), 0.0))};
}

// The Wald test of "Ra(c) is constant": chi-square of the coefficients' deviations from their mean
// against their covariance, with knots - 1 degrees of freedom.
struct Variation {
  double chi2 = 0, p_value = 1;
  int dof = 0;
};

Variation WaldTestOfConstancy(const VectorXd& r, const MatrixXd& c) {
  const Eigen::Index k = r.size();
  const MatrixXd centre = MatrixXd::Identity(k, k) - MatrixXd::Constant(k, k, 1.0 / static_cast<double>(k));
  const VectorXd deviation = centre * r;
  Eigen::SelfAdjointEigenSolver<MatrixXd> eigen(centre * c * centre);
  Variation v;
  for (Eigen::Index i = 1; i < k; ++i) {  // eigenvalue 0 (the constant direction) comes first
    const double projection = eigen.eigenvectors().col(i).dot(deviation);
    const double variance = eigen.eigenvalues()[i];
    // Noise-free data leave no variance: any deviation is then infinitely significant.
    v.chi2 += variance > 0.0 ? projection * projection / variance
                             : (projection != 0.0 ? std::numeric_limits<double>::infinity() : 0.0);
  }
  v.dof = static_cast<int>(k - 1);
  v.p_value = std::isfinite(v.chi2)
                  ? boost::math::cdf(boost::math::complement(boost::math::chi_squared(v.dof), v.chi2))
                  : 0.0;
  return v;
}

// The test at the chosen knots of Ra, or at 4 when the information criterion chose a constant
// (a test needs an alternative), from the fine fit's linearised normal equations.
Variation VariationAtFineFit(const Solution& fine, const Layout& fine_layout, Knots knots,
                             const MatrixXd& null_space) {
  knots.radius = std::max(knots.radius, 4);
  const MatrixXd t = Reduction(fine_layout, knots, null_space);
  const double n = static_cast<double>(fine.normal.samples);
  const LinearisedFit linear = Linearise(fine, t);
  const double sigma2 = linear.rss / (n - static_cast<double>(t.cols()));
  const MatrixXd covariance = sigma2 * linear.reduced_jtj.inverse();
  return WaldTestOfConstancy(linear.x.head(knots.radius),
                             covariance.topLeftCorner(knots.radius, knots.radius));
}

struct Fitted {
  Layout layout;
  Variation variation;
  Solution solution;
  std::vector<double> residual_um;  // the residual map (WheelModel::residual_um)
  MatrixXd covariance;              // of the full parameters
  double sigma2 = 0;
};

void SampleFunctions(const Fitted& f, std::span<const double> phases_deg, WheelModel& model) {
  const Layout& l = f.layout;
  const MatrixXd radius = l.radius.Matrix(phases_deg);
  const MatrixXd axial = l.axial.Matrix(phases_deg);
  const MatrixXd runout = l.runout.Matrix(phases_deg);
  for (Eigen::Index r = 0; r < radius.rows(); ++r) {
    VectorXd w = VectorXd::Zero(l.size());
    w.head(l.radius.knots) = radius.row(r).transpose();
    auto [ra, ra_sigma] = Linear(w, f.solution.theta, f.covariance);
    w.setZero();
    w.segment(l.a0(), l.axial.knots) = axial.row(r).transpose();
    auto [a, a_sigma] = Linear(w, f.solution.theta, f.covariance);
    w.setZero();
    w.segment(l.b0(), l.runout.knots) = runout.row(r).transpose();
    auto [b, b_sigma] = Linear(w, f.solution.theta, f.covariance);
    model.arc_radius_mm.push_back(ra);
    model.arc_radius_sigma_mm.push_back(ra_sigma);
    model.center_axial_mm.push_back(a);
    model.center_axial_sigma_mm.push_back(a_sigma);
    model.center_radial_mm.push_back(b);
    model.center_radial_sigma_mm.push_back(b_sigma);
  }
}

void SummariseRadius(const Fitted& f, std::span<const double> phases_deg, WheelModel& model) {
  const Layout& l = f.layout;
  const Eigen::Index k = l.radius.knots;
  const VectorXd r = f.solution.theta.head(k);
  const MatrixXd c = f.covariance.topLeftCorner(k, k);
  // Every periodic basis function has the same integral, so the mean over a turn is the mean
  // coefficient.
  const VectorXd mean = VectorXd::Constant(k, 1.0 / static_cast<double>(k));
  model.mean_arc_radius_mm = mean.dot(r);
  model.mean_arc_radius_sigma_mm = std::sqrt(mean.dot(c * mean));
  const MatrixXd at = l.radius.Matrix(phases_deg);
  const VectorXd values = at * r;
  Eigen::Index high = 0, low = 0;
  values.maxCoeff(&high);
  values.minCoeff(&low);
  if (k == 1) return;  // a constant radius: no range
  const VectorXd range = (at.row(high) - at.row(low)).transpose();
  model.arc_radius_range_mm = range.dot(r);
  model.arc_radius_range_sigma_mm = std::sqrt(std::max(range.dot(c * range), 0.0));
}

void RadiusHarmonics(const Fitted& f, int harmonics, WheelModel& model) {
  const Layout& l = f.layout;
  const Eigen::Index k = l.radius.knots;
  const int points = 64 * l.radius.knots;
  std::vector<double> phases(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) phases[static_cast<std::size_t>(i)] = i * 360.0 / points;
  const MatrixXd at = l.radius.Matrix(phases);
  const VectorXd r = f.solution.theta.head(k);
  const MatrixXd c = f.covariance.topLeftCorner(k, k);
  const int orders = l.radius.knots < 4 ? 0 : std::min(harmonics, std::max(1, l.radius.knots / 2 - 1));
  for (int order = 1; order <= orders; ++order) {
    // Ra's Fourier coefficients: A cos(order c) + B sin(order c), linear in the coefficients.
    VectorXd cos_w = VectorXd::Zero(k), sin_w = VectorXd::Zero(k);
    for (int i = 0; i < points; ++i) {
      const double angle = order * phases[static_cast<std::size_t>(i)] * std::numbers::pi / 180.0;
      cos_w += 2.0 / points * std::cos(angle) * at.row(i).transpose();
      sin_w += 2.0 / points * std::sin(angle) * at.row(i).transpose();
    }
    const double a = cos_w.dot(r), b = sin_w.dot(r);
    const double va = cos_w.dot(c * cos_w), vb = sin_w.dot(c * sin_w), cab = cos_w.dot(c * sin_w);
    const double amplitude = std::hypot(a, b);
    RadiusHarmonic h;
    h.order = order;
    h.amplitude_um = amplitude * 1e3;
    // amplitude cos(order c + phase) = A cos + B sin with A = amp cos(phase), B = -amp sin(phase).
    h.phase_deg = std::atan2(-b, a) * 180.0 / std::numbers::pi;
    if (amplitude > 0) {
      h.amplitude_sigma_um =
          std::sqrt(std::max(a * a * va + b * b * vb + 2 * a * b * cab, 0.0)) / amplitude * 1e3;
      h.phase_sigma_deg = std::sqrt(std::max(b * b * va + a * a * vb - 2 * a * b * cab, 0.0)) /
                          (amplitude * amplitude) * 180.0 / std::numbers::pi;
    }
    model.radius_harmonics.push_back(h);
  }
}

void SampleProfile(const Fitted& f, double half_width_mm, WheelModel& model) {
  const Layout& l = f.layout;
  const int steps = static_cast<int>(std::ceil(2.0 * half_width_mm / 0.1));
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (int i = 0; i <= steps; ++i) {
    const double u = -half_width_mm + 2.0 * half_width_mm * i / steps;
    double w[4], slope[4];
    const int first = l.profile.At(u, w, slope);
    VectorXd row = VectorXd::Zero(l.size());
    for (int k = 0; k < 4; ++k) row[l.p0() + first + k] = w[k];
    const auto [p, sigma] = Linear(row, f.solution.theta, f.covariance);
    model.profile_u_mm.push_back(u);
    model.profile_error_um.push_back(p * 1e3);
    model.profile_error_sigma_um.push_back(sigma * 1e3);
    low = std::min(low, p);
    high = std::max(high, p);
  }
  model.profile_pv_um = (high - low) * 1e3;
}

Layout MakeLayout(const Knots& knots, double half_width_mm, double knot_step_mm) {
  // p spans the band and a margin for the wobble of a(c) about its mean (u beyond it is clamped):
  // a wider margin would leave the outer coefficients without data.
  const double margin = 0.02;
  const int intervals =
      std::max(1, static_cast<int>(std::ceil(2.0 * (half_width_mm + margin) / knot_step_mm)));
  const double step = 2.0 * (half_width_mm + margin) / intervals;
  return {PeriodicBasis{knots.radius}, PeriodicBasis{knots.axial}, PeriodicBasis{knots.runout},
          ProfileBasis{-(half_width_mm + margin), step, intervals}};
}

VectorXd StartingPoint(const Layout& layout, const WheelFit& fit) {
  VectorXd theta = VectorXd::Zero(layout.size());
  theta.head(layout.radius.knots).setConstant(fit.mean_arc_radius_mm);
  theta.segment(layout.a0(), layout.axial.knots).setConstant(fit.mean_center_axial_mm);
  theta.segment(layout.b0(), layout.runout.knots).setConstant(fit.mean_center_radial_mm);
  return theta;
}

// The BIC of coarser knots, from the fine fit's normal equations linearised at its solution.
double Bic(const Solution& fine, const Layout& fine_layout, const Knots& knots, const MatrixXd& null_space) {
  const MatrixXd t = Reduction(fine_layout, knots, null_space);
  const double n = static_cast<double>(fine.normal.samples);
  return n * std::log(Linearise(fine, t).rss / n) + static_cast<double>(t.cols()) * std::log(n);
}

// Each function's knots in turn (Ra, then a, then b, twice over), the one with the least BIC
// while the others stay: a few dozen small dense solves instead of every combination. Ra comes
// first, while b is still at its finest: Ra and b are nearly interchangeable on a short arc, and a
// b chosen first too coarse would leave its misfit for Ra to take up.
Knots ChooseKnots(const Solution& fine, const Layout& fine_layout, const std::vector<int> choices[3],
                  const MatrixXd& null_space) {
  Knots best = fine_layout.knots();
  int Knots::*const members[3] = {&Knots::radius, &Knots::axial, &Knots::runout};
  // The second round meets some trials of the first again (and each round its best so far): the
  // criterion is a function of the knots, so it is computed once for each.
  std::map<std::array<int, 3>, double> known;
  for (int round = 0; round < 2; ++round) {
    for (int f = 0; f < 3; ++f) {
      double least = std::numeric_limits<double>::infinity();
      int chosen = best.*members[f];
      for (const int k : choices[f]) {
        Knots trial = best;
        trial.*members[f] = k;
        const auto [entry, added] = known.try_emplace({trial.radius, trial.axial, trial.runout}, 0.0);
        if (added) entry->second = Bic(fine, fine_layout, trial, null_space);
        const double bic = entry->second;
        if (bic < least) {
          least = bic;
          chosen = k;
        }
      }
      best.*members[f] = chosen;
    }
  }
  return best;
}

}  // namespace

std::vector<std::string> WheelModelOptions::Problems() const {
  std::vector<std::string> problems;
  const auto knots = [&](const char* name, int value) {
    if (value != 0 && value != 1 && (value < 4 || value > 360)) {
      problems.push_back(fmt::format("{} = {} violates 0 (chosen from the data), 1 or 4..360", name, value));
    }
  };
  knots("model-knots", radius_knots);
  knots("model-axial-knots", axial_knots);
  knots("model-runout-knots", runout_knots);
  if (!(profile_knot_step_mm >= 0.05 && profile_knot_step_mm <= 10.0)) {
    problems.push_back(fmt::format("model-profile-step-mm = {} violates 0.05..10", profile_knot_step_mm));
  }
  if (max_iterations < 1)
    problems.push_back(fmt::format("model max_iterations = {} violates >= 1", max_iterations));
  if (!(significance_level > 0.0 && significance_level < 0.5)) {
    problems.push_back(
        fmt::format("model significance_level = {} violates 0 < level < 0.5", significance_level));
  }
  if (harmonics < 1) problems.push_back(fmt::format("model harmonics = {} violates >= 1", harmonics));
  return problems;
}

namespace {

// The warm-up's stride: one sample from each run of this many (1: no warm-up).
std::size_t WarmUpStride(std::size_t total, std::size_t warm_start_samples) {
  if (warm_start_samples == 0 || total < 4 * warm_start_samples) return 1;
  return total / warm_start_samples;
}

// Fits at the finest knots asked for, then, where the knots are to be chosen, picks them by the
// BIC from the fine fit's linearised normal equations and refits there, and maps the residuals.
//
// With a warm-up, the fine fit converges on a subsample; two Gauss-Newton steps over every sample
// from there give the fine fit's normal equations where the fit over every sample has them (the
// model is so nearly linear that one step from the subsample's optimum lands on the full one to
// many digits). They choose the knots, and their linearised solution at the chosen knots is so
// close to the optimum there that one more pass (J^T r and r^T r only, J^T J taken from the fine
// pass, the residual map beside) meets the convergence rule; else full iterations follow. Without
// the warm-up, every Gauss-Newton iteration passes over every sample, and the residual map takes
// a pass of its own.
template <typename Sample>
Fitted FitAndChoose(const Samples<Sample>& samples_in, const Grid& grid, const WheelFit& fit,
                    const WheelModelOptions& options, double half_width_mm, WheelModel& model) {
  const std::vector<int> choices[3] = {KnotCandidates(options.radius_knots, true),
                                       KnotCandidates(options.axial_knots, true),
                                       KnotCandidates(options.runout_knots, false)};
  const Layout fine = MakeLayout({choices[0].back(), choices[1].back(), choices[2].back()}, half_width_mm,
                                 options.profile_knot_step_mm);
  const MatrixXd null_space = ProfileNullSpace(fine.profile, half_width_mm);
  const MatrixXd fine_reduction = Reduction(fine, fine.knots(), null_space);
  VectorXd start = StartingPoint(fine, fit);
  // Binned: every pass but the residual map's runs on the cells, so no warm-up is needed.
  HelixCells cells;
  const bool binned =
      samples_in.rho_mm.size() > options.binned_above_samples && samples_in.geometry.from_settings();
  if (binned) cells = BinSamples(samples_in, fine);
  Samples<Sample> samples = samples_in;
  if (binned) samples.cells = &cells;
  const std::size_t stride = binned ? 1 : WarmUpStride(samples.rho_mm.size(), options.warm_start_samples);
  const bool warm = stride > 1;
  if (warm) {
    const Solution subsample = Converge(
        samples, fine, fine_reduction, start,
        {.stride = stride, .max_iterations = options.max_iterations, .throw_if_not_converged = false});
    // A subsample that cannot support the fine knots leaves the start as it was.
    if (subsample.converged && subsample.theta.allFinite()) start = subsample.theta;
  }
  Solution best =
      warm ? OneStep(samples, fine, fine_reduction, start)
           : Converge(samples, fine, fine_reduction, start, {.max_iterations = options.max_iterations});
  if (warm) {
    // J at the subsample's optimum is off J at the full data's in its fourth digit (through p'(u)
    // above all), and the knots, the test of Ra's constancy and the covariance depend on J^T J:
    // one more step puts it where the fit over every sample has it.
    const int first = best.iterations;
    best = OneStep(samples, fine, fine_reduction, best.theta);
    best.iterations += first;
  }
  model.knots_chosen = choices[0].size() > 1 || choices[1].size() > 1 || choices[2].size() > 1;
  const Knots knots = model.knots_chosen ? ChooseKnots(best, fine, choices, null_space) : fine.knots();
  Fitted fitted;
  fitted.layout = MakeLayout(knots, half_width_mm, options.profile_knot_step_mm);
  fitted.variation = VariationAtFineFit(best, fine, knots, null_space);
  const PartRanges ranges = best.ranges;
  const int iterations = best.iterations;
  ConvergeRequest request{
      .max_iterations = options.max_iterations, .grid = warm ? &grid : nullptr, .ranges = &ranges};
  if (!(knots == fine.knots())) {
    const LinearisedFit linear = Linearise(best, Reduction(fine, knots, null_space));
    const MatrixXd reduction = Reduction(fitted.layout, knots, null_space);
    if (warm) request.reduced_jtj = linear.reduced_jtj;
    best = Converge(samples, fitted.layout, reduction, reduction * linear.x, std::move(request));
    best.iterations += iterations;
  } else if (warm) {
    request.reduced_jtj = best.reduced_jtj;
    const VectorXd from = best.theta;
    best = Converge(samples, fine, fine_reduction, from, std::move(request));
    best.iterations += iterations;
  }
  if (warm) {
    fitted.residual_um = ResidualMap(grid, best.cells);
  } else if (binned) {
    fitted.residual_um = CellResidualMap(samples_in, cells, grid, fitted.layout, best.theta);
  } else {
    // As the fit was defined: the residuals at the solution, one more pass.
    const PassResult pass =
        Accumulate(samples, fitted.layout, best.theta, {.normal_matrix = false, .grid = &grid}, &best.ranges);
    fitted.residual_um = ResidualMap(grid, pass.cells);
  }
  fitted.solution = std::move(best);
  return fitted;
}

template <typename Sample>
WheelModel Fit(std::span<const Sample> rho_mm, const processing::HelixGeometry& geometry,
               const processing::WheelMap& map, const WheelFit& fit, const WheelModelOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kStage, options.Problems());
  WheelModel model;
  model.band_low_mm = fit.band_low_mm;
  model.band_high_mm = fit.band_high_mm;
  model.center_axial_reference_mm = fit.mean_center_axial_mm;
  const double half_width_mm =
      std::max(fit.mean_center_axial_mm - fit.band_low_mm, fit.band_high_mm - fit.mean_center_axial_mm);
  const Samples<Sample> samples{rho_mm, geometry, fit.band_low_mm, fit.band_high_mm};
  const Grid grid = GridOf(map);

  Fitted f = FitAndChoose(samples, grid, fit, options, half_width_mm, model);
  const Solution& s = f.solution;
  const auto parameters = static_cast<std::size_t>(s.reduction.cols());
  if (s.normal.samples < 4 * parameters) {
    throw Error(ErrorCode::kFitFailed, kStage,
                fmt::format("the band holds {} samples, too few for the wheel model's {} parameters",
                            s.normal.samples, parameters));
  }
  f.sigma2 = s.normal.rss / static_cast<double>(s.normal.samples - parameters);
  f.covariance = s.reduction * (f.sigma2 * s.reduced_jtj.inverse()) * s.reduction.transpose();

  model.fitted = true;
  model.radius_knots = f.layout.radius.knots;
  model.axial_knots = f.layout.axial.knots;
  model.runout_knots = f.layout.runout.knots;
  model.variation_chi2 = f.variation.chi2;
  model.variation_dof = f.variation.dof;
  model.variation_p_value = f.variation.p_value;
  model.profile_coefficients = f.layout.profile.size();
  model.samples = s.normal.samples;
  model.parameters = static_cast<int>(parameters);
  model.iterations = s.iterations;
  model.residual_rms_um = std::sqrt(s.normal.rss / static_cast<double>(s.normal.samples)) * 1e3;
  model.noise_sigma_um = map.noise_sigma_mm * 1e3;
  model.phase_deg = map.phase_deg;
  SampleFunctions(f, map.phase_deg, model);
  SummariseRadius(f, map.phase_deg, model);
  model.significance_level = options.significance_level;
  model.variation_significant = model.variation_p_value < options.significance_level;
  RadiusHarmonics(f, options.harmonics, model);
  SampleProfile(f, half_width_mm, model);
  model.residual_um = std::move(f.residual_um);
  model.coefficients.assign(s.theta.data(), s.theta.data() + s.theta.size());
  model.covariance.assign(f.covariance.data(), f.covariance.data() + f.covariance.size());
  return model;
}

}  // namespace

WheelModel FitWheelModel(std::span<const double> rho_mm, const processing::HelixGeometry& geometry,
                         const processing::WheelMap& map, const WheelFit& fit,
                         const WheelModelOptions& options) {
  return Fit(rho_mm, geometry, map, fit, options);
}

WheelModel FitWheelModel(std::span<const float> rho_mm, const processing::HelixGeometry& geometry,
                         const processing::WheelMap& map, const WheelFit& fit,
                         const WheelModelOptions& options) {
  return Fit(rho_mm, geometry, map, fit, options);
}

}  // namespace arcwheel::fitting
