#include "polishing/dwell.h"

#include <fmt/core.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>
#include <utility>

#include "core/check.h"
#include "core/error.h"
#include "polishing/removal_fft.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kDwellStage = "polishing.dwell";
// How far the least-dwell removal may exceed the target before the speeds count as unreachable.
constexpr double kOvershootToleranceUm = 1e-3;

[[noreturn]] void Invalid(const std::string& what) {
  throw Error(ErrorCode::kInvalidOption, kDwellStage, what);
}

void CheckOptions(const RemovalFunction& removal, const DwellOptions& o, std::size_t points) {
  removal.Check();
  ThrowIfProblems(ErrorCode::kInvalidOption, kDwellStage, o.Problems());
  if (!o.least_dwell_s.empty() && o.least_dwell_s.size() != points) {
    Invalid(fmt::format("least_dwell_s has {} values for {} path points", o.least_dwell_s.size(), points));
  }
  for (std::size_t k = 0; k < o.least_dwell_s.size(); ++k) {
    if (!(o.least_dwell_s[k] >= 0.0) || !std::isfinite(o.least_dwell_s[k]) ||
        (k == 0 && o.least_dwell_s[k] > 0.0)) {
      Invalid(fmt::format("least_dwell_s[{}] = {} violates {}", k, o.least_dwell_s[k],
                          k == 0 ? "== 0 (the first point is the approach)" : ">= 0"));
    }
  }
}

// The aperture nodes with data, as rows of the removal matrix.
struct Rows {
  std::vector<int> node;         // row -> index into the map
  std::vector<int> row_of_node;  // map index -> row, or -1
  Eigen::VectorXd target;
};

Rows ApertureRows(const ErrorMap& target, const surfaces::Aperture& aperture) {
  Rows rows;
  rows.row_of_node.assign(target.error_um.size(), -1);
  rows.node.reserve(target.error_um.size());
  for (int j = 0; j < target.grid.ny; ++j) {
    for (int i = 0; i < target.grid.nx; ++i) {
      const int index = j * target.grid.nx + i;
      if (!std::isfinite(target.error_um[index]) || !aperture.Contains(target.grid.X(i), target.grid.Y(j)))
        continue;
      rows.row_of_node[index] = static_cast<int>(rows.node.size());
      rows.node.push_back(index);
    }
  }
  if (rows.node.empty()) {
    throw Error(ErrorCode::kBadInput, kDwellStage,
                fmt::format("empty aperture: no target node lies inside {}", aperture.Describe()));
  }
  rows.target.resize(static_cast<Eigen::Index>(rows.node.size()));
  for (std::size_t r = 0; r < rows.node.size(); ++r)
    rows.target[static_cast<Eigen::Index>(r)] = target.error_um[rows.node[r]];
  return rows;
}

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

// Templated on the concrete removal model so that the rate is an inlined call in the inner loop.
template <class Model>
SparseMatrix RemovalMatrix(const ErrorMap& map, const Rows& rows, std::span<const Eigen::Vector2d> path,
                           const Model& removal, const FootprintBox& box) {
  SparseMatrix a(static_cast<Eigen::Index>(rows.node.size()), static_cast<Eigen::Index>(path.size()));
  const int per_column = static_cast<int>(std::ceil((box.max_x_mm - box.min_x_mm) / map.grid.dx_mm + 1) *
                                          std::ceil((box.max_y_mm - box.min_y_mm) / map.grid.dy_mm + 1));
  a.reserve(Eigen::VectorXi::Constant(static_cast<Eigen::Index>(path.size()), per_column));
  for (std::size_t k = 0; k < path.size(); ++k) {
    const Eigen::Vector2d& p = path[k];
    const int i0 =
        std::max(0, static_cast<int>(std::ceil((p.x() + box.min_x_mm - map.grid.x0_mm) / map.grid.dx_mm)));
    const int i1 =
        std::min(map.grid.nx - 1,
                 static_cast<int>(std::floor((p.x() + box.max_x_mm - map.grid.x0_mm) / map.grid.dx_mm)));
    const int j0 =
        std::max(0, static_cast<int>(std::ceil((p.y() + box.min_y_mm - map.grid.y0_mm) / map.grid.dy_mm)));
    const int j1 =
        std::min(map.grid.ny - 1,
                 static_cast<int>(std::floor((p.y() + box.max_y_mm - map.grid.y0_mm) / map.grid.dy_mm)));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const int row = rows.row_of_node[j * map.grid.nx + i];
        if (row < 0) continue;
        const double rate = removal.RateUmPerS(map.grid.X(i) - p.x(), map.grid.Y(j) - p.y());
        if (rate > 0.0) a.insert(row, static_cast<Eigen::Index>(k)) = rate;
      }
    }
  }
  a.makeCompressed();
  return a;
}

SparseMatrix RemovalMatrix(const ErrorMap& map, const Rows& rows, std::span<const Eigen::Vector2d> path,
                           const RemovalFunction& removal) {
  const FootprintBox box = removal.Footprint();
  return std::visit([&](const auto& model) { return RemovalMatrix(map, rows, path, model, box); },
                    removal.model());
}

// The removal matrix A as its two products: the sparse matrix (the reference), or FFT convolutions
// when the dwell points lie on the map's grid (removal_fft.h).
class Removal {
 public:
  Removal(const ErrorMap& map, const Rows& rows, std::span<const Eigen::Vector2d> path,
          const RemovalFunction& removal, bool fft)
      : points_(static_cast<Eigen::Index>(path.size())) {
    if (fft) fft_ = internal::FftRemoval::Make(map, rows.node, path, removal);
    if (!fft_) sparse_ = RemovalMatrix(map, rows, path, removal);
  }
  [[nodiscard]] Eigen::VectorXd operator*(const Eigen::VectorXd& dwell_s) const {
    return fft_ ? fft_->Apply(dwell_s) : Eigen::VectorXd(sparse_ * dwell_s);
  }
  [[nodiscard]] Eigen::VectorXd Transposed(const Eigen::VectorXd& rows) const {
    return fft_ ? fft_->ApplyTranspose(rows) : Eigen::VectorXd(sparse_.transpose() * rows);
  }
  // A t into a vector the caller keeps.
  void Multiply(const Eigen::VectorXd& dwell_s, Eigen::VectorXd& rows) const {
    if (fft_) {
      fft_->Apply(dwell_s, rows);
    } else {
      rows.noalias() = sparse_ * dwell_s;
    }
  }
  // A^T residual for the residual the last Residual call wrote (the FFT products keep it placed),
  // into a vector the caller keeps: no allocation per iteration.
  void Gradient(const Eigen::VectorXd& residual, Eigen::VectorXd& gradient) const {
    if (fft_) {
      fft_->GradientOfResidual(residual, gradient);
    } else {
      gradient.noalias() = sparse_.transpose() * residual;
    }
  }
  // residual = A t - target; returns its norm.
  double Residual(const Eigen::VectorXd& dwell_s, const Eigen::VectorXd& target,
                  Eigen::VectorXd& residual) const {
    if (fft_) return fft_->Residual(dwell_s, target, residual);
    residual.noalias() = sparse_ * dwell_s;
    residual -= target;
    return residual.norm();
  }
  [[nodiscard]] Eigen::Index cols() const { return points_; }
  [[nodiscard]] long Nonzeros() const { return fft_ ? fft_->Nonzeros() : sparse_.nonZeros(); }
  [[nodiscard]] bool UsesFft() const { return fft_.has_value(); }
  [[nodiscard]] const internal::FftRemoval* Fft() const { return fft_ ? &*fft_ : nullptr; }
  // The FFT products' workers, for the solve's passes; nullptr with the sparse matrix.
  [[nodiscard]] WorkerPool* Pool() const { return fft_ ? fft_->Pool() : nullptr; }

 private:
  Eigen::Index points_;
  std::optional<internal::FftRemoval> fft_;
  SparseMatrix sparse_;
};

// Largest eigenvalue of A^T A: the Lipschitz constant of the gradient. With FFT products the
// kernel's spectrum bounds it; otherwise power iteration.
double GradientLipschitz(const Removal& a, bool spectral_bound) {
  if (spectral_bound && a.Fft() != nullptr) return a.Fft()->NormSquaredBound();
  Eigen::VectorXd v = Eigen::VectorXd::Ones(a.cols()).normalized();
  double lambda = 0.0;
  for (int k = 0; k < 50; ++k) {
    const Eigen::VectorXd w = a.Transposed(a * v);
    lambda = w.norm();
    if (!(lambda > 0.0)) return 1.0;
    v = w / lambda;
  }
  return 1.05 * lambda;  // power iteration approaches from below
}

struct Bounds {
  Eigen::VectorXd lower, upper, chord_mm;
};

// The chords come from the caller's geometry: a wrong one is our bug, not the user's input.
void CheckChords(std::span<const double> chord_mm, std::size_t points) {
  ARCWHEEL_CHECK(chord_mm.size() == points) << chord_mm.size() << " chords for " << points << " points";
  for (std::size_t k = 0; k < chord_mm.size(); ++k) {
    ARCWHEEL_CHECK(std::isfinite(chord_mm[k]) && chord_mm[k] >= 0.0 && (k > 0 || chord_mm[k] == 0.0))
        << "chord_mm[" << k << "] = " << chord_mm[k];
  }
}

// A point's dwell is the time of the TCP chord into it: chord / max_speed <= t <= chord / min_speed.
Bounds DwellBounds(std::span<const double> chord_mm, const DwellOptions& o) {
  const auto n = static_cast<Eigen::Index>(chord_mm.size());
  Bounds b{Eigen::VectorXd::Zero(n), Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity()),
           Eigen::Map<const Eigen::VectorXd>(chord_mm.data(), n)};
  b.upper[0] = 0.0;  // the first point is the approach: no dwell
  for (Eigen::Index k = 1; k < n; ++k) {
    b.lower[k] = std::max(b.chord_mm[k] / o.max_speed_mm_s, o.min_dwell_s);
    if (o.min_speed_mm_s > 0.0) b.upper[k] = b.chord_mm[k] / o.min_speed_mm_s;
  }
  return b;
}

// `excess`: a vector to work in.
void CheckReachable(const Removal& a, const Rows& rows, const ErrorMap& map, const Bounds& b,
                    const DwellOptions& o, Eigen::VectorXd& excess) {
  a.Residual(b.lower, rows.target, excess);
  Eigen::Index worst = 0;
  const double most = excess.maxCoeff(&worst);
  if (most <= kOvershootToleranceUm) return;
  const int node = rows.node[static_cast<std::size_t>(worst)];
  throw Error(ErrorCode::kBadInput, kDwellStage,
              fmt::format("unreachable speeds: at max_speed_mm_s = {} the path already removes {:.4f} um "
                          "at ({:.3f}, {:.3f}) mm where the target is {:.4f} um; add a uniform layer of "
                          "at least {:.4f} um (removal_target.uniform_layer_um) or raise the maximum speed",
                          o.max_speed_mm_s, most + rows.target[worst], map.grid.X(node % map.grid.nx),
                          map.grid.Y(node / map.grid.nx), rows.target[worst], most));
}

// The caller's per-point least dwell, kept even where it removes more than the target.
void AddLeastDwell(Bounds& b, std::span<const Eigen::Vector2d> path, const DwellOptions& o) {
  for (std::size_t k = 1; k < o.least_dwell_s.size(); ++k) {
    const auto i = static_cast<Eigen::Index>(k);
    if (o.least_dwell_s[k] > b.upper[i]) {
      Invalid(fmt::format(
          "unreachable speeds: least_dwell_s[{}] = {} s at ({:.3f}, {:.3f}) mm is above the longest "
          "dwell {} s that min_speed_mm_s = {} allows",
          k, o.least_dwell_s[k], path[k].x(), path[k].y(), b.upper[i], o.min_speed_mm_s));
    }
    b.lower[i] = std::max(b.lower[i], o.least_dwell_s[k]);
  }
}

[[noreturn]] void NotSettled(std::span<const Eigen::Vector2d> path, Eigen::Index worst, double added_um,
                             const DwellOptions& o) {
  const auto k = static_cast<std::size_t>(worst);
  throw Error(
      ErrorCode::kBadInput, kDwellStage,
      fmt::format(
          "unreachable speeds: after {} shaping rounds the speeds still exceed max_acceleration_mm_s2 "
          "= {}: slowing down into path point {} ({:.3f}, {:.3f}) mm adds {:.3g} um of removal "
          "(more than shaping_tolerance_um = {}); raise the acceleration limit, use a wider "
          "removal function or a larger uniform layer",
          o.max_shaping_rounds, o.max_acceleration_mm_s2, k, path[k].x(), path[k].y(), added_um,
          o.shaping_tolerance_um));
}

// True when the best residual norm so far has improved on the best one stall_iterations ago by
// less than stall_improvement times `reference`, the first residual norm of the whole solve.
// `history` keeps the running best of every iteration.
bool Stalled(double residual_norm, int iteration, double reference, const DwellOptions& o,
             std::vector<double>& history) {
  history.push_back(history.empty() ? residual_norm : std::min(history.back(), residual_norm));
  if (o.stall_iterations <= 0 || iteration <= o.stall_iterations) return false;
  const double earlier = history[history.size() - 1 - static_cast<std::size_t>(o.stall_iterations)];
  return earlier - history.back() <= o.stall_improvement * reference;
}

// Largest acceleration the speeds need: |v_k^2 - v_(k-1)^2| / (2 chord_k) over k >= 2 (the
// first point is the approach, reached at whatever speed the robot brings).
double MaxAcceleration(const std::vector<double>& speed, const Eigen::VectorXd& chord_mm) {
  double most = 0.0;
  for (std::size_t k = 2; k < speed.size(); ++k) {
    const double length = chord_mm[static_cast<Eigen::Index>(k)];
    if (!(length > 0.0)) continue;
    most = std::max(most, std::abs(speed[k] * speed[k] - speed[k - 1] * speed[k - 1]) / (2.0 * length));
  }
  return most;
}

std::vector<double> Speeds(const Eigen::VectorXd& t, const Eigen::VectorXd& chord_mm, const DwellOptions& o) {
  std::vector<double> speed(static_cast<std::size_t>(t.size()));
  for (Eigen::Index k = 0; k < t.size(); ++k) {
    speed[static_cast<std::size_t>(k)] =
        k == 0 || !(t[k] > 0.0) ? o.max_speed_mm_s : std::min(o.max_speed_mm_s, chord_mm[k] / t[k]);
  }
  return speed;
}

// The forward and backward passes of a motion planner: each speed capped by what its neighbour
// allows over the TCP chord between them. Only lowers speeds; afterwards every pair satisfies the limit.
std::vector<double> ShapedSpeeds(std::vector<double> v, const Eigen::VectorXd& chord_mm, double a_mm_s2) {
  const std::size_t n = v.size();
  for (std::size_t k = 2; k < n; ++k) {
    const double length = chord_mm[static_cast<Eigen::Index>(k)];
    if (length > 0.0) v[k] = std::min(v[k], std::sqrt(v[k - 1] * v[k - 1] + 2.0 * a_mm_s2 * length));
  }
  for (std::size_t k = n - 1; k >= 2; --k) {
    const double length = chord_mm[static_cast<Eigen::Index>(k)];
    if (length > 0.0) v[k - 1] = std::min(v[k - 1], std::sqrt(v[k] * v[k] + 2.0 * a_mm_s2 * length));
  }
  return v;
}

// The dwell that runs the shaped speeds: longer where a speed was lowered, unchanged elsewhere.
Eigen::VectorXd ShapedDwell(const Eigen::VectorXd& t, const Eigen::VectorXd& chord_mm,
                            const DwellOptions& o) {
  const std::vector<double> speed = Speeds(t, chord_mm, o);
  const std::vector<double> shaped = ShapedSpeeds(speed, chord_mm, o.max_acceleration_mm_s2);
  Eigen::VectorXd out = t;
  for (Eigen::Index k = 1; k < t.size(); ++k) {
    const auto i = static_cast<std::size_t>(k);
    if (shaped[i] < speed[i]) out[k] = std::max(t[k], chord_mm[k] / shaped[i]);
  }
  return out;
}

// The solve's work vectors, kept from the reachability check through the filter steps, the
// gradient iterations and the shaping rounds to the final product: on a million points each is
// 8 MB, too much to allocate and fault in afresh (~20 ms each on this virtual machine) for every
// stage.
struct WorkVectors {
  Eigen::VectorXd previous, y, residual, gradient;
};

struct Fit {
  Eigen::VectorXd dwell_s;
  int iterations = 0;
  bool converged = false;
  double first_residual_norm = 0.0;  // the stall test's reference
};

// Accelerated projected gradient from `start`. From a warm start near a solution one plain gradient
// step is short although the accelerated iteration still has far to go, so there the dwell-change
// test only counts after kWarmStartIterations. A warm start (a shaping round) passes the first
// solve's first residual norm as the stall test's reference: measured against its own, already
// small, first residual, a round would polish far below where the first solve stopped.
constexpr int kWarmStartIterations = 100;

// Of one projected gradient step: ||t - previous||^2, ||t||^2 and (y - t).(t - previous).
struct StepSums {
  double change = 0.0, dwell = 0.0, uphill = 0.0;
};

// t = clamp(y - step gradient) and its sums in one pass over the vectors, on every core (on a
// million points each pass is memory-bound and costs a fair part of what a transform does). Each
// block's sums are taken while the block is still in cache.
StepSums ProjectedStep(const Eigen::VectorXd& y, const Eigen::VectorXd& gradient, double step,
                       const Bounds& bounds, const Eigen::VectorXd& previous, Eigen::VectorXd& t,
                       WorkerPool* pool) {
  std::array<StepSums, internal::kPassBlocks> blocks{};
  internal::ForEachBlock(
      static_cast<std::size_t>(t.size()),
      [&](std::size_t begin, std::size_t end, int block) {
        const auto b = static_cast<Eigen::Index>(begin), n = static_cast<Eigen::Index>(end - begin);
        auto ts = t.segment(b, n);
        ts = (y.segment(b, n) - step * gradient.segment(b, n))
                 .cwiseMax(bounds.lower.segment(b, n))
                 .cwiseMin(bounds.upper.segment(b, n));
        StepSums& sums = blocks[static_cast<std::size_t>(block)];
        sums.change = (ts - previous.segment(b, n)).squaredNorm();
        sums.dwell = ts.squaredNorm();
        sums.uphill = (y.segment(b, n) - ts).dot(ts - previous.segment(b, n));
      },
      pool);
  StepSums total;
  for (const StepSums& sums : blocks) {
    total.change += sums.change;
    total.dwell += sums.dwell;
    total.uphill += sums.uphill;
  }
  return total;
}

Fit ProjectedGradient(const Removal& a, const Eigen::VectorXd& target, const Bounds& bounds, double step,
                      Eigen::VectorXd start, std::optional<double> stall_reference, bool warm,
                      const DwellOptions& options, WorkVectors& work) {
  Fit fit;
  Eigen::VectorXd t = std::move(start);  // the start's vector becomes t
  t = t.cwiseMax(bounds.lower).cwiseMin(bounds.upper);
  Eigen::VectorXd &previous = work.previous, &y = work.y, &residual = work.residual,
                  &gradient = work.gradient;
  previous = t;
  y = t;
  double momentum = 1.0;
  std::vector<double> history;
  for (fit.iterations = 1; fit.iterations <= options.max_iterations; ++fit.iterations) {
    const double residual_norm = a.Residual(y, target, residual);
    if (fit.iterations == 1) fit.first_residual_norm = stall_reference.value_or(residual_norm);
    if (Stalled(residual_norm, fit.iterations, fit.first_residual_norm, options, history)) {
      fit.converged = true;
      break;
    }
    a.Gradient(residual, gradient);
    previous.swap(t);
    const StepSums sums = ProjectedStep(y, gradient, step, bounds, previous, t, a.Pool());
    if (std::sqrt(sums.change) <= options.relative_tolerance * std::sqrt(sums.dwell) &&
        (!warm || fit.iterations > kWarmStartIterations)) {
      fit.converged = true;
      break;
    }
    // O'Donoghue & Candes (2015): restart the momentum when it points uphill.
    if (sums.uphill > 0.0) momentum = 1.0;
    const double next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * momentum * momentum));
    const double push = (momentum - 1.0) / next;
    internal::ForEachBlock(
        static_cast<std::size_t>(t.size()),
        [&](std::size_t begin, std::size_t end, int) {
          const auto b = static_cast<Eigen::Index>(begin), n = static_cast<Eigen::Index>(end - begin);
          y.segment(b, n) = t.segment(b, n) + push * (t.segment(b, n) - previous.segment(b, n));
        },
        a.Pool());
    momentum = next;
  }
  fit.iterations = std::min(fit.iterations, options.max_iterations);
  fit.dwell_s = std::move(t);
  return fit;
}

// RIFTA-style iterative inverse filtering (Wang et al. 2020, "Robust iterative Fourier transform
// algorithm"): from the inverse filter of the target, t <- clamp(t - F(A t - b)), F the
// damped inverse filter of the residual (removal_fft.h). Where the bounds are not active this is a
// Newton-like step on every frequency the footprint passes, so a handful of steps do what hundreds
// of gradient steps do; the bounds are kept by clamping. The filter of a residual that lives on
// the aperture only is not the exact inverse of A, and on some maps (steep edges) the lightly
// damped step overshoots and grows: a step that does not lower the residual is undone and the
// damping tripled (0.01, 0.03, ... up to 0.81), which takes shorter steps at the frequencies the
// footprint passes least.
// Stops when the best residual norm has improved by less than stall_improvement x `reference`
// over kFilterStallSteps steps, or after kMaxFilterSteps; returns the best dwell
// (first_residual_norm: its residual norm; iterations: the steps, each one product and one filter).
constexpr double kFilterStartDamping = 0.03;
constexpr double kFilterStepDamping = 0.01;
constexpr double kMaxFilterStepDamping = 1.0;
constexpr int kFilterStallSteps = 5;
constexpr int kMaxFilterSteps = 60;

Fit InverseFilterIterations(const internal::FftRemoval& f, const Removal& a, const Eigen::VectorXd& target,
                            const Bounds& bounds, double reference, const DwellOptions& options,
                            WorkVectors& work) {
  Fit fit;
  Eigen::VectorXd &t = work.y, &residual = work.residual, &best_residual = work.gradient;
  f.InverseFilter(target, kFilterStartDamping, true, t);
  t = t.cwiseMax(bounds.lower).cwiseMin(bounds.upper);
  fit.first_residual_norm = std::numeric_limits<double>::infinity();
  std::vector<double> history;
  double damping = kFilterStepDamping;
  for (fit.iterations = 1; fit.iterations <= kMaxFilterSteps; ++fit.iterations) {
    const double norm = a.Residual(t, target, residual);
    if (norm < fit.first_residual_norm) {
      // Kept by swapping: t and the residual are written afresh before they are read again.
      fit.first_residual_norm = norm;
      fit.dwell_s.swap(t);
      best_residual.swap(residual);
    } else {
      damping *= 3.0;
      if (damping > kMaxFilterStepDamping) break;
    }
    history.push_back(fit.first_residual_norm);
    if (fit.iterations > kFilterStallSteps &&
        history[history.size() - 1 - kFilterStallSteps] - history.back() <=
            options.stall_improvement * reference)
      break;
    f.InverseFilter(best_residual, damping, true, t);
    t = (fit.dwell_s - t).cwiseMax(bounds.lower).cwiseMin(bounds.upper);
  }
  fit.iterations = std::min(fit.iterations, kMaxFilterSteps);
  fit.converged = true;
  return fit;
}

ErrorMap Scatter(const ErrorMap& like, const Rows& rows, const Eigen::VectorXd& values) {
  ErrorMap out{.grid = like.grid};
  out.error_um.assign(like.error_um.size(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t r = 0; r < rows.node.size(); ++r)
    out.error_um[rows.node[r]] = values[static_cast<Eigen::Index>(r)];
  return out;
}

}  // namespace

std::vector<Eigen::Vector2d> SpiralPath(const surfaces::Aperture& aperture, const RasterOptions& o) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kDwellStage, o.Problems());
  const bool circle = aperture.shape == surfaces::Aperture::Shape::kCircle;
  const double radius =
      circle ? aperture.HalfY() + o.extension_mm
             : std::hypot(aperture.HalfX() + o.extension_mm, aperture.HalfY() + o.extension_mm);
  const double b = o.line_spacing_mm / (2.0 * std::numbers::pi);
  // Arc length from the centre to angle theta, in closed form, and its derivative.
  auto arc = [b](double theta) {
    return 0.5 * b * (theta * std::sqrt(1.0 + theta * theta) + std::asinh(theta));
  };
  auto darc = [b](double theta) { return b * std::sqrt(1.0 + theta * theta); };
  const double theta_end = radius / b;
  const double total = arc(theta_end);
  const int steps = std::max(1, static_cast<int>(std::ceil(total / o.point_spacing_mm - 1e-9)));
  std::vector<Eigen::Vector2d> path;
  path.reserve(static_cast<std::size_t>(steps) + 1);
  double theta = 0.0;
  for (int k = 0; k <= steps; ++k) {
    const double wanted = total * k / steps;
    // Newton on the convex, increasing arc length: from the previous angle it lands past the
    // root, then closes in from above.
    for (int it = 0; it < 60 && k > 0; ++it) {
      const double delta = (arc(theta) - wanted) / darc(theta);
      theta -= delta;
      if (std::abs(delta) <= 1e-14 * std::max(1.0, theta)) break;
    }
    if (k == steps) theta = theta_end;
    path.emplace_back(b * theta * std::cos(theta), b * theta * std::sin(theta));
  }
  return path;
}

std::vector<Eigen::Vector2d> RasterPath(const surfaces::Aperture& aperture, const RasterOptions& o) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kDwellStage, o.Problems());
  const bool circle = aperture.shape == surfaces::Aperture::Shape::kCircle;
  const double half_y = aperture.HalfY() + o.extension_mm;
  const int lines = static_cast<int>(std::ceil(2.0 * half_y / o.line_spacing_mm - 1e-9)) + 1;
  std::vector<Eigen::Vector2d> path;
  for (int line = 0; line < lines; ++line) {
    const double y = -half_y + 2.0 * half_y * line / std::max(1, lines - 1);
    const double half_x =
        circle ? std::sqrt(std::max(0.0, half_y * half_y - y * y)) : aperture.HalfX() + o.extension_mm;
    if (!(half_x > 0.0)) {  // a circle's top and bottom lines are single points
      path.emplace_back(0.0, y);
      continue;
    }
    const int steps = std::max(1, static_cast<int>(std::ceil(2.0 * half_x / o.point_spacing_mm - 1e-9)));
    for (int s = 0; s <= steps; ++s) {
      const double u = static_cast<double>(line % 2 == 0 ? s : steps - s) / steps;
      path.emplace_back(-half_x + 2.0 * half_x * u, y);
    }
  }
  return path;
}

std::vector<double> PlanarChordsMm(std::span<const Eigen::Vector2d> path_xy_mm) {
  std::vector<double> chord_mm(path_xy_mm.size(), 0.0);
  for (std::size_t k = 1; k < path_xy_mm.size(); ++k)
    chord_mm[k] = (path_xy_mm[k] - path_xy_mm[k - 1]).norm();
  return chord_mm;
}

DwellSolution SolveDwell(const ErrorMap& target, const surfaces::Aperture& aperture,
                         std::span<const Eigen::Vector2d> path, const RemovalFunction& removal,
                         const DwellOptions& options) {
  const std::vector<double> chord_mm = PlanarChordsMm(path);
  return SolveDwell(target, aperture, path, chord_mm, removal, options);
}

DwellSolution SolveDwell(const ErrorMap& target, const surfaces::Aperture& aperture,
                         std::span<const Eigen::Vector2d> path, std::span<const double> chord_mm,
                         const RemovalFunction& removal, const DwellOptions& options) {
  CheckOptions(removal, options, path.size());
  if (path.size() < 2) Invalid(fmt::format("the path has {} point(s); it needs two or more", path.size()));
  CheckChords(chord_mm, path.size());
  const Rows rows = ApertureRows(target, aperture);
  const Removal a(target, rows, path, removal, options.fft_products);
  Bounds bounds = DwellBounds(chord_mm, options);
  WorkVectors work;
  CheckReachable(a, rows, target, bounds, options, work.residual);
  AddLeastDwell(bounds, path, options);

  // Start from the correlation A^T b scaled to fit best: the right shape at low frequencies. Its
  // residual norm is the stall test's reference, whatever the start.
  Eigen::VectorXd start = a.Transposed(rows.target);
  double fit_scale = 0.0, correlation_residual = 0.0;
  {
    Eigen::VectorXd at = a * start;
    fit_scale = at.squaredNorm() > 0.0 ? at.dot(rows.target) / at.squaredNorm() : 0.0;
    at = fit_scale * at - rows.target;
    correlation_residual = at.norm();
  }
  const bool spectral = options.inverse_filter_start && a.Fft() != nullptr;
  const double step = 1.0 / GradientLipschitz(a, spectral);
  Fit fit;
  std::optional<Fit> filtered;
  if (spectral) {
    // Its pages go to the filter's vectors (first touching 8 MB costs ~20 ms on this virtual
    // machine); it is made again in the rare case that the filter does not fit better.
    start = Eigen::VectorXd();
    filtered = InverseFilterIterations(*a.Fft(), a, rows.target, bounds, correlation_residual, options, work);
  }
  if (filtered && filtered->first_residual_norm < correlation_residual) {
    // Then the accelerated projected gradient from there, with the job's stopping rules: it
    // finishes what the filter leaves (the aperture's edge, where bounds are active; on a map
    // with steep edges most of the way). A shorter stall window would save most of its
    // iterations on smooth maps but stops short on such a map (removal_fft_test).
    fit = ProjectedGradient(a, rows.target, bounds, step, std::move(filtered->dwell_s), correlation_residual,
                            true, options, work);
    fit.iterations += filtered->iterations;
    fit.first_residual_norm = correlation_residual;
  } else {
    if (start.size() == 0) start = a.Transposed(rows.target);
    start *= fit_scale;
    fit =
        ProjectedGradient(a, rows.target, bounds, step, std::move(start), std::nullopt, false, options, work);
    fit.iterations += filtered ? filtered->iterations : 0;
  }
  const double stall_reference = fit.first_residual_norm;
  DwellSolution solution;
  solution.iterations = fit.iterations;
  solution.converged = fit.converged;
  Eigen::VectorXd t = std::move(fit.dwell_s);
  if (options.max_acceleration_mm_s2 > 0.0) {
    const double peak = removal.PeakRateUmPerS();
    for (;;) {
      const Eigen::VectorXd shaped = ShapedDwell(t, bounds.chord_mm, options);
      Eigen::Index worst = 0;
      const double added_um = peak * (shaped - t).maxCoeff(&worst);
      // The lengthened dwells become lower bounds; the other points stay free.
      for (Eigen::Index k = 0; k < t.size(); ++k) {
        if (shaped[k] > t[k]) bounds.lower[k] = std::max(bounds.lower[k], shaped[k]);
      }
      t = shaped;
      if (added_um <= options.shaping_tolerance_um) break;
      if (solution.shaping_rounds == options.max_shaping_rounds) NotSettled(path, worst, added_um, options);
      ++solution.shaping_rounds;
      fit =
          ProjectedGradient(a, rows.target, bounds, step, std::move(t), stall_reference, true, options, work);
      solution.iterations += fit.iterations;
      solution.converged = solution.converged && fit.converged;
      t = std::move(fit.dwell_s);
    }
  }

  Eigen::VectorXd& removed = work.residual;
  a.Multiply(t, removed);
  solution.nonzeros = a.Nonzeros();
  solution.fft_products = a.UsesFft();
  solution.dwell_s.assign(t.data(), t.data() + t.size());
  solution.chord_mm.assign(chord_mm.begin(), chord_mm.end());
  solution.speed_mm_s = Speeds(t, bounds.chord_mm, options);
  solution.total_time_s = t.sum();
  solution.max_acceleration_mm_s2 = MaxAcceleration(solution.speed_mm_s, bounds.chord_mm);
  solution.predicted_removal_um = Scatter(target, rows, removed);
  removed = rows.target - removed;  // now the residual
  solution.residual_um = Scatter(target, rows, removed);
  solution.before = StatisticsInAperture(target, aperture);
  solution.after = StatisticsInAperture(solution.residual_um, aperture);
  return solution;
}

ErrorMap RemovalOfDwell(const ErrorMap& like, const surfaces::Aperture& aperture,
                        std::span<const Eigen::Vector2d> contact_xy_mm, std::span<const double> dwell_s,
                        const RemovalFunction& removal) {
  ARCWHEEL_CHECK(contact_xy_mm.size() == dwell_s.size()) << dwell_s.size() << " dwells";
  removal.Check();
  const Rows rows = ApertureRows(like, aperture);
  const Removal a(like, rows, contact_xy_mm, removal, true);
  const Eigen::Map<const Eigen::VectorXd> t(dwell_s.data(), static_cast<Eigen::Index>(dwell_s.size()));
  return Scatter(like, rows, a * Eigen::VectorXd(t));
}

std::vector<std::string> DwellOptions::Problems() const {
  std::vector<std::string> problems;
  const auto require = [&problems](bool ok, const std::string& text) {
    if (!ok) problems.push_back(text);
  };
  const bool max_ok = max_speed_mm_s > 0.0 && std::isfinite(max_speed_mm_s);
  require(max_ok, fmt::format("machine.max_speed_mm_s = {} violates > 0", max_speed_mm_s));
  // Against a bad maximum only the lower bound says anything about the minimum itself.
  require(min_speed_mm_s >= 0.0 && (min_speed_mm_s <= max_speed_mm_s || !max_ok),
          fmt::format("machine.min_speed_mm_s = {} violates 0 <= min_speed_mm_s <= max_speed_mm_s = {} "
                      "(unreachable)",
                      min_speed_mm_s, max_speed_mm_s));
  require(min_dwell_s >= 0.0 && std::isfinite(min_dwell_s),
          fmt::format("machine.min_dwell_s = {} violates >= 0", min_dwell_s));
  require(!(min_dwell_s > 0.0 && min_speed_mm_s > 0.0),
          fmt::format("machine.min_dwell_s = {} violates min_speed_mm_s = 0 (both are unreachable together: "
                      "give one of them)",
                      min_dwell_s));
  require(max_acceleration_mm_s2 >= 0.0,
          fmt::format("machine.max_acceleration_mm_s2 = {} violates >= 0 (0 = no limit)",
                      max_acceleration_mm_s2));
  require(max_iterations >= 1, fmt::format("solver.max_iterations = {} violates >= 1", max_iterations));
  require(relative_tolerance > 0.0,
          fmt::format("solver.relative_tolerance = {} violates > 0", relative_tolerance));
  require(stall_iterations >= 0, fmt::format("stall_iterations = {} violates >= 0", stall_iterations));
  require(stall_improvement > 0.0, fmt::format("stall_improvement = {} violates > 0", stall_improvement));
  require(max_shaping_rounds >= 1, fmt::format("max_shaping_rounds = {} violates >= 1", max_shaping_rounds));
  require(shaping_tolerance_um > 0.0,
          fmt::format("shaping_tolerance_um = {} violates > 0", shaping_tolerance_um));
  return problems;
}

std::vector<std::string> RasterOptions::Problems() const {
  std::vector<std::string> problems;
  if (!(line_spacing_mm > 0.0)) {
    problems.push_back(fmt::format("path.line_spacing_mm = {} violates > 0", line_spacing_mm));
  }
  if (!(point_spacing_mm > 0.0)) {
    problems.push_back(fmt::format("path.point_spacing_mm = {} violates > 0", point_spacing_mm));
  }
  if (!(extension_mm >= 0.0))
    problems.push_back(fmt::format("path.extension_mm = {} violates >= 0", extension_mm));
  return problems;
}

}  // namespace arcwheel::polishing
