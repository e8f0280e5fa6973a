#include "polishing/dwell.h"

#include <fmt/core.h>

#include <Eigen/SparseCore>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/check.h"
#include "core/error.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kStage = "polishing.dwell";
// How far the least-dwell removal may exceed the target before the speeds count as unreachable.
constexpr double kOvershootToleranceUm = 1e-3;

[[noreturn]] void Invalid(const std::string& what) {
  throw Error(ErrorCode::kInvalidOption, kStage, what);
}

void CheckOptions(const GaussianRemovalFunction& removal, const DwellOptions& o) {
  if (!(removal.peak_rate_um_per_s > 0.0) || !std::isfinite(removal.peak_rate_um_per_s)) {
    Invalid(fmt::format("peak_rate_um_per_s = {} violates > 0", removal.peak_rate_um_per_s));
  }
  if (!(removal.fwhm_mm > 0.0) || !std::isfinite(removal.fwhm_mm)) {
    Invalid(fmt::format("fwhm_mm = {} violates > 0", removal.fwhm_mm));
  }
  if (!(o.max_speed_mm_s > 0.0) || !std::isfinite(o.max_speed_mm_s)) {
    Invalid(fmt::format("max_speed_mm_s = {} violates > 0", o.max_speed_mm_s));
  }
  if (!(o.min_speed_mm_s >= 0.0 && o.min_speed_mm_s <= o.max_speed_mm_s)) {
    Invalid(fmt::format("unreachable speeds: min_speed_mm_s = {} must lie in [0, max_speed_mm_s = {}]",
                        o.min_speed_mm_s, o.max_speed_mm_s));
  }
  if (!(o.min_dwell_s >= 0.0) || !std::isfinite(o.min_dwell_s)) {
    Invalid(fmt::format("min_dwell_s = {} violates >= 0", o.min_dwell_s));
  }
  if (!(o.max_acceleration_mm_s2 >= 0.0)) {
    Invalid(fmt::format("max_acceleration_mm_s2 = {} violates >= 0", o.max_acceleration_mm_s2));
  }
  if (o.min_speed_mm_s > 0.0 && o.min_dwell_s > 0.0) {
    Invalid("unreachable speeds: give min_speed_mm_s or min_dwell_s, not both (a short segment "
            "cannot satisfy both)");
  }
  if (o.max_iterations < 1) Invalid(fmt::format("max_iterations = {} violates >= 1", o.max_iterations));
  if (o.stall_iterations < 0) Invalid(fmt::format("stall_iterations = {} violates >= 0", o.stall_iterations));
  if (!(o.stall_improvement > 0.0)) {
    Invalid(fmt::format("stall_improvement = {} violates > 0", o.stall_improvement));
  }
  if (!(o.relative_tolerance > 0.0)) {
    Invalid(fmt::format("relative_tolerance = {} violates > 0", o.relative_tolerance));
  }
}

// The aperture nodes with data, as rows of the removal matrix.
struct Rows {
  std::vector<int> node;              // row -> index into the map
  std::vector<int> row_of_node;       // map index -> row, or -1
  Eigen::VectorXd target;
};

Rows ApertureRows(const ErrorMap& target, const grinding::Aperture& aperture) {
  Rows rows;
  rows.row_of_node.assign(target.error_um.size(), -1);
  std::vector<double> values;
  for (int j = 0; j < target.ny; ++j) {
    for (int i = 0; i < target.nx; ++i) {
      const int index = j * target.nx + i;
      if (!std::isfinite(target.error_um[index]) || !aperture.Contains(target.X(i), target.Y(j))) continue;
      rows.row_of_node[index] = static_cast<int>(rows.node.size());
      rows.node.push_back(index);
      values.push_back(target.error_um[index]);
    }
  }
  if (rows.node.empty()) {
    throw Error(ErrorCode::kBadInput, kStage,
                fmt::format("empty aperture: no target node lies inside {}", aperture.Describe()));
  }
  rows.target = Eigen::Map<const Eigen::VectorXd>(values.data(), static_cast<Eigen::Index>(values.size()));
  return rows;
}

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

SparseMatrix RemovalMatrix(const ErrorMap& map, const Rows& rows,
                           std::span<const Eigen::Vector2d> path, const GaussianRemovalFunction& removal) {
  const double radius = removal.SupportRadiusMm();
  SparseMatrix a(static_cast<Eigen::Index>(rows.node.size()), static_cast<Eigen::Index>(path.size()));
  const int per_column = static_cast<int>(std::ceil(2 * radius / map.dx_mm + 1) * std::ceil(2 * radius / map.dy_mm + 1));
  a.reserve(Eigen::VectorXi::Constant(static_cast<Eigen::Index>(path.size()), per_column));
  for (std::size_t k = 0; k < path.size(); ++k) {
    const Eigen::Vector2d& p = path[k];
    const int i0 = std::max(0, static_cast<int>(std::ceil((p.x() - radius - map.x0_mm) / map.dx_mm)));
    const int i1 = std::min(map.nx - 1, static_cast<int>(std::floor((p.x() + radius - map.x0_mm) / map.dx_mm)));
    const int j0 = std::max(0, static_cast<int>(std::ceil((p.y() - radius - map.y0_mm) / map.dy_mm)));
    const int j1 = std::min(map.ny - 1, static_cast<int>(std::floor((p.y() + radius - map.y0_mm) / map.dy_mm)));
    for (int j = j0; j <= j1; ++j) {
      for (int i = i0; i <= i1; ++i) {
        const int row = rows.row_of_node[j * map.nx + i];
        if (row < 0) continue;
        const double rate = removal.RateUmPerS(map.X(i) - p.x(), map.Y(j) - p.y());
        if (rate > 0.0) a.insert(row, static_cast<Eigen::Index>(k)) = rate;
      }
    }
  }
  a.makeCompressed();
  return a;
}

// Largest eigenvalue of A^T A by power iteration: the Lipschitz constant of the gradient.
double GradientLipschitz(const SparseMatrix& a) {
  Eigen::VectorXd v = Eigen::VectorXd::Ones(a.cols()).normalized();
  double lambda = 0.0;
  for (int k = 0; k < 50; ++k) {
    const Eigen::VectorXd w = a.transpose() * (a * v);
    lambda = w.norm();
    if (!(lambda > 0.0)) return 1.0;
    v = w / lambda;
  }
  return 1.05 * lambda;  // power iteration approaches from below
}

struct Bounds {
  Eigen::VectorXd lower, upper, segment_mm;
};

Bounds DwellBounds(std::span<const Eigen::Vector2d> path, const DwellOptions& o) {
  const auto n = static_cast<Eigen::Index>(path.size());
  Bounds b{Eigen::VectorXd::Zero(n), Eigen::VectorXd::Constant(n, std::numeric_limits<double>::infinity()),
           Eigen::VectorXd::Zero(n)};
  b.upper[0] = 0.0;  // the first point is the approach: no dwell
  for (Eigen::Index k = 1; k < n; ++k) {
    b.segment_mm[k] = (path[k] - path[k - 1]).norm();
    b.lower[k] = std::max(b.segment_mm[k] / o.max_speed_mm_s, o.min_dwell_s);
    if (o.min_speed_mm_s > 0.0) b.upper[k] = b.segment_mm[k] / o.min_speed_mm_s;
  }
  return b;
}

void CheckReachable(const SparseMatrix& a, const Rows& rows, const ErrorMap& map, const Bounds& b,
                    const DwellOptions& o) {
  const Eigen::VectorXd excess = a * b.lower - rows.target;
  Eigen::Index worst = 0;
  const double most = excess.maxCoeff(&worst);
  if (most <= kOvershootToleranceUm) return;
  const int node = rows.node[static_cast<std::size_t>(worst)];
  throw Error(ErrorCode::kBadInput, kStage,
              fmt::format("unreachable speeds: at max_speed_mm_s = {} the path already removes {:.4f} um "
                          "at ({:.3f}, {:.3f}) mm where the target is {:.4f} um; add a uniform layer of "
                          "at least {:.4f} um (removal_target.uniform_layer_um) or raise the maximum speed",
                          o.max_speed_mm_s, most + rows.target[worst], map.X(node % map.nx),
                          map.Y(node / map.nx), rows.target[worst], most));
}

// True when the best residual norm so far has improved on the best one stall_iterations ago by
// less than stall_improvement times the first residual norm. `history` keeps the running best of every iteration.
bool Stalled(double residual_norm, int iteration, const DwellOptions& o, std::vector<double>& history) {
  history.push_back(history.empty() ? residual_norm : std::min(history.back(), residual_norm));
  if (o.stall_iterations <= 0 || iteration <= o.stall_iterations) return false;
  const double earlier = history[history.size() - 1 - static_cast<std::size_t>(o.stall_iterations)];
  return earlier - history.back() <= o.stall_improvement * history.front();
}

void CheckAcceleration(DwellSolution& s, std::span<const Eigen::Vector2d> path, const DwellOptions& o) {
  std::size_t worst = 0;
  for (std::size_t k = 2; k < path.size(); ++k) {
    if (!(s.segment_mm[k] > 0.0)) continue;
    const double a = std::abs(s.speed_mm_s[k] * s.speed_mm_s[k] - s.speed_mm_s[k - 1] * s.speed_mm_s[k - 1]) /
                     (2.0 * s.segment_mm[k]);
    if (a > s.max_acceleration_mm_s2) s.max_acceleration_mm_s2 = a, worst = k;
  }
  if (o.max_acceleration_mm_s2 > 0.0 && s.max_acceleration_mm_s2 > o.max_acceleration_mm_s2) {
    throw Error(ErrorCode::kBadInput, kStage,
                fmt::format("unreachable speeds: from {:.4f} to {:.4f} mm/s over the {:.4f} mm segment into "
                            "path point {} ({:.3f}, {:.3f}) mm needs {:.1f} mm/s^2, above "
                            "max_acceleration_mm_s2 = {}; use a wider removal function or a larger "
                            "uniform layer",
                            s.speed_mm_s[worst - 1], s.speed_mm_s[worst], s.segment_mm[worst], worst,
                            path[worst].x(), path[worst].y(), s.max_acceleration_mm_s2, o.max_acceleration_mm_s2));
  }
}

ErrorMap Scatter(const ErrorMap& like, const Rows& rows, const Eigen::VectorXd& values) {
  ErrorMap out = like;
  std::fill(out.error_um.begin(), out.error_um.end(), std::numeric_limits<double>::quiet_NaN());
  for (std::size_t r = 0; r < rows.node.size(); ++r) out.error_um[rows.node[r]] = values[static_cast<Eigen::Index>(r)];
  return out;
}

}  // namespace

double GaussianRemovalFunction::SigmaMm() const {
  return fwhm_mm / (2.0 * std::sqrt(2.0 * std::numbers::ln2));
}

double GaussianRemovalFunction::SupportRadiusMm() const { return 3.5 * SigmaMm(); }

double GaussianRemovalFunction::RateUmPerS(double dx_mm, double dy_mm) const {
  const double r2 = dx_mm * dx_mm + dy_mm * dy_mm;
  const double support = SupportRadiusMm();
  if (r2 > support * support) return 0.0;
  const double sigma = SigmaMm();
  return peak_rate_um_per_s * std::exp(-r2 / (2.0 * sigma * sigma));
}

std::vector<Eigen::Vector2d> RasterPath(const grinding::Aperture& aperture, const RasterOptions& o) {
  if (!(o.line_spacing_mm > 0.0)) Invalid(fmt::format("line_spacing_mm = {} violates > 0", o.line_spacing_mm));
  if (!(o.point_spacing_mm > 0.0)) Invalid(fmt::format("point_spacing_mm = {} violates > 0", o.point_spacing_mm));
  if (!(o.extension_mm >= 0.0)) Invalid(fmt::format("extension_mm = {} violates >= 0", o.extension_mm));
  const bool circle = aperture.shape == grinding::Aperture::Shape::kCircle;
  const double half_y = aperture.HalfY() + o.extension_mm;
  const int lines = static_cast<int>(std::ceil(2.0 * half_y / o.line_spacing_mm - 1e-9)) + 1;
  std::vector<Eigen::Vector2d> path;
  for (int line = 0; line < lines; ++line) {
    const double y = -half_y + 2.0 * half_y * line / std::max(1, lines - 1);
    const double half_x = circle ? std::sqrt(std::max(0.0, half_y * half_y - y * y))
                                 : aperture.HalfX() + o.extension_mm;
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

DwellSolution SolveDwell(const ErrorMap& target, const grinding::Aperture& aperture,
                         std::span<const Eigen::Vector2d> path, const GaussianRemovalFunction& removal,
                         const DwellOptions& options) {
  CheckOptions(removal, options);
  if (path.size() < 2) Invalid(fmt::format("the path has {} point(s); it needs two or more", path.size()));
  const Rows rows = ApertureRows(target, aperture);
  const SparseMatrix a = RemovalMatrix(target, rows, path, removal);
  const Bounds bounds = DwellBounds(path, options);
  CheckReachable(a, rows, target, bounds, options);

  auto project = [&](const Eigen::VectorXd& t) { return t.cwiseMax(bounds.lower).cwiseMin(bounds.upper).eval(); };
  // Start from the correlation A^T b scaled to fit best: the right shape at low frequencies.
  Eigen::VectorXd t = a.transpose() * rows.target;
  const Eigen::VectorXd at = a * t;
  const double scale = at.squaredNorm() > 0.0 ? at.dot(rows.target) / at.squaredNorm() : 0.0;
  t = project(scale * t);
  const double step = 1.0 / GradientLipschitz(a);
  Eigen::VectorXd previous = t, y = t;
  double momentum = 1.0;
  DwellSolution solution;
  std::vector<double> history;
  for (solution.iterations = 1; solution.iterations <= options.max_iterations; ++solution.iterations) {
    const Eigen::VectorXd residual = a * y - rows.target;
    if (Stalled(residual.norm(), solution.iterations, options, history)) {
      solution.converged = true;
      break;
    }
    const Eigen::VectorXd gradient = a.transpose() * residual;
    previous = t;
    t = project(y - step * gradient);
    const double change = (t - previous).norm();
    if (change <= options.relative_tolerance * t.norm()) {
      solution.converged = true;
      break;
    }
    // O'Donoghue & Candes (2015): restart the momentum when it points uphill.
    if ((y - t).dot(t - previous) > 0.0) momentum = 1.0;
    const double next = 0.5 * (1.0 + std::sqrt(1.0 + 4.0 * momentum * momentum));
    y = t + ((momentum - 1.0) / next) * (t - previous);
    momentum = next;
  }
  solution.iterations = std::min(solution.iterations, options.max_iterations);

  const Eigen::VectorXd removed = a * t;
  solution.nonzeros = static_cast<int>(a.nonZeros());
  solution.dwell_s.assign(t.data(), t.data() + t.size());
  solution.segment_mm.assign(bounds.segment_mm.data(), bounds.segment_mm.data() + bounds.segment_mm.size());
  solution.speed_mm_s.resize(path.size());
  for (std::size_t k = 0; k < path.size(); ++k) {
    solution.speed_mm_s[k] = k == 0 || !(t[static_cast<Eigen::Index>(k)] > 0.0)
                                 ? options.max_speed_mm_s
                                 : std::min(options.max_speed_mm_s, solution.segment_mm[k] / t[static_cast<Eigen::Index>(k)]);
  }
  solution.total_time_s = t.sum();
  CheckAcceleration(solution, path, options);
  solution.predicted_removal_um = Scatter(target, rows, removed);
  solution.residual_um = Scatter(target, rows, rows.target - removed);
  solution.before = StatisticsInAperture(target, aperture);
  solution.after = StatisticsInAperture(solution.residual_um, aperture);
  return solution;
}

}  // namespace arcwheel::polishing
