#pragma once
// What the wheel model's sources (fitting/wheel_model*.cc) share: the model's rows of the
// Jacobian and their accumulation into the normal equations (inline: they run once per sample),
// the samples and the passes over them, the binned fit's cells, the Gauss-Newton solution, and
// the functions each source defines for the others. Not installed.

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "fitting/wheel_model.h"
#include "fitting/wheel_model_basis.h"
#include "processing/helix_geometry.h"

namespace arcwheel::fitting::internal {

inline constexpr const char* kStage = "fitting.model";

// Where a sample's cells lie: the map's (phase, axial) grid, for the residual map.
struct Grid {
  std::size_t n_phase = 0, n_y = 0;
  double phase_step_deg = 0, y0_mm = 0, y_step_mm = 0;
  [[nodiscard]] bool empty() const { return n_phase == 0 || n_y < 2; }
  [[nodiscard]] std::size_t size() const { return n_phase * n_y; }
};

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

// The Wald test of "Ra(c) is constant": chi-square of the coefficients' deviations from their mean
// against their covariance, with knots - 1 degrees of freedom.
struct Variation {
  double chi2 = 0, p_value = 1;
  int dof = 0;
};

struct Fitted {
  Layout layout;
  Variation variation;
  Solution solution;
  std::vector<double> residual_um;  // the residual map (WheelModel::residual_um)
  MatrixXd covariance;              // of the full parameters
  double sigma2 = 0;
};

// Defined in wheel_model_accumulation.cc: the passes over every sample (or a subsample).
CellSums CellSumsFor(const Grid& grid, double low_y_mm, double high_y_mm);
template <typename Sample>
PassResult Accumulate(const Samples<Sample>& samples, const Layout& layout, const VectorXd& theta,
                      const PassRequest& request, const PartRanges* previous = nullptr);
std::vector<double> ResidualMap(const Grid& grid, const std::vector<CellSums>& parts);

// Defined in wheel_model_binned.cc: the binned fit's cells, their passes and residual map.
template <typename Sample>
HelixCells BinSamples(const Samples<Sample>& samples, const Layout& fine);
void AccumulateCellsPart(const std::vector<HelixCell>& cells, const processing::HelixGeometry& geometry,
                         const RowModel& model, NormalEquations& normal, bool normal_matrix);
template <typename Sample>
std::vector<double> CellResidualMap(const Samples<Sample>& samples, HelixCells& cells, const Grid& grid,
                                    const Layout& layout, const VectorXd& theta);

// Defined in wheel_model_solve.cc: Gauss-Newton and the linearised fits at coarser knots.
template <typename Sample>
Solution Converge(const Samples<Sample>& samples, const Layout& layout, const MatrixXd& reduction,
                  VectorXd theta, ConvergeRequest request);
template <typename Sample>
Solution OneStep(const Samples<Sample>& samples, const Layout& layout, const MatrixXd& reduction,
                 const VectorXd& theta);
LinearisedFit Linearise(const Solution& fine, const MatrixXd& reduction);

// Defined in wheel_model_knots.cc: the knots to choose from, the choice and the test of Ra's
// constancy.
std::vector<int> KnotCandidates(int fixed, bool constant_allowed);
Variation VariationAtFineFit(const Solution& fine, const Layout& fine_layout, Knots knots,
                             const MatrixXd& null_space);
Knots ChooseKnots(const Solution& fine, const Layout& fine_layout, const std::vector<int> choices[3],
                  const MatrixXd& null_space);

// Defined in wheel_model_summary.cc: the fitted functions and their 1-sigma, as WheelModel reports
// them.
void SampleFunctions(const Fitted& f, std::span<const double> phases_deg, WheelModel& model);
void SummariseRadius(const Fitted& f, std::span<const double> phases_deg, WheelModel& model);
void RadiusHarmonics(const Fitted& f, int harmonics, WheelModel& model);
void SampleProfile(const Fitted& f, double half_width_mm, WheelModel& model);

}  // namespace arcwheel::fitting::internal
