#include "fitting/circle_fit.h"

#include <ceres/ceres.h>
#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/dense.h"
#include "core/error.h"

namespace arcwheel::fitting {
namespace {

// All n residuals in one block: r_i = w_i (|p_i - c| - r), analytic Jacobian.
class CircleResiduals final : public ceres::CostFunction {
 public:
  CircleResiduals(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& w)
      : x_(x), y_(y), w_(w) {
    set_num_residuals(static_cast<int>(x.size()));
    mutable_parameter_block_sizes()->push_back(3);
  }

  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    const double a = parameters[0][0];
    const double b = parameters[0][1];
    const double r = parameters[0][2];
    for (std::size_t i = 0; i < x_.size(); ++i) {
      const double dx = x_[i] - a;
      const double dy = y_[i] - b;
      const double d = std::hypot(dx, dy);
      residuals[i] = w_[i] * (d - r);
      if (jacobians != nullptr && jacobians[0] != nullptr) {
        double* row = jacobians[0] + 3 * i;
        const double inv = d > 0 ? 1.0 / d : 0.0;
        row[0] = -w_[i] * dx * inv;
        row[1] = -w_[i] * dy * inv;
        row[2] = -w_[i];
      }
    }
    return true;
  }

 private:
  const std::vector<double>& x_;
  const std::vector<double>& y_;
  const std::vector<double>& w_;
};

// Kasa 1976 algebraic fit: only the initial guess for Ceres.
bool AlgebraicCircle(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& w,
                     double guess[3]) {
  const auto n = static_cast<Eigen::Index>(x.size());
  Eigen::MatrixXd design(n, 3);
  Eigen::VectorXd rhs(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    const auto k = static_cast<std::size_t>(i);
    design(i, 0) = w[k] * x[k];
    design(i, 1) = w[k] * y[k];
    design(i, 2) = w[k];
    rhs(i) = -w[k] * (x[k] * x[k] + y[k] * y[k]);
  }
  Eigen::Index rank = 0;
  const Eigen::Vector3d p = dense::ColPivQrSolve(design, rhs, &rank);
  if (rank < 3) return false;
  guess[0] = -p(0) / 2.0;
  guess[1] = -p(1) / 2.0;
  const double r2 = guess[0] * guess[0] + guess[1] * guess[1] - p(2);
  if (!(r2 > 0)) return false;
  guess[2] = std::sqrt(r2);
  return true;
}

double WeightedCost(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& w,
                    const double p[3]) {
  double cost = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = w[i] * (std::hypot(x[i] - p[0], y[i] - p[1]) - p[2]);
    cost += r * r;
  }
  return cost;
}

// Levenberg-Marquardt's damping makes its last steps short along the flat direction of a short
// arc, and where it stops depends on cost differences below the cost's rounding: |p_i - c| - r
// cancels about five digits when the centre is far from the arc, so near the minimum the cost
// cannot tell apart points about 1e-5 sigma apart. Undamped Gauss-Newton steps from its answer
// converge instead to the fixed point of the iteration, which rounding moves only by about 1e-10
// sigma: the same answer whichever way the damped steps came. A step is taken unless it raises the
// cost beyond that rounding, and the iteration stops when the steps stop shrinking.
void PolishByGaussNewton(const std::vector<double>& x, const std::vector<double>& y,
                         const std::vector<double>& w, double p[3]) {
  constexpr int kMaxIterations = 10;
  // Relative: ten times the cost's rounding on a wheel phase (600 points, 0.3 um noise).
  constexpr double kCostRounding = 1e-10;
  const auto n = static_cast<Eigen::Index>(x.size());
  double cost = WeightedCost(x, y, w, p);
  Eigen::Matrix<double, Eigen::Dynamic, 3> jacobian(n, 3);
  Eigen::VectorXd residual(n);
  double last_step = std::numeric_limits<double>::infinity();
  for (int iteration = 0; iteration < kMaxIterations; ++iteration) {
    for (Eigen::Index i = 0; i < n; ++i) {
      const auto k = static_cast<std::size_t>(i);
      const double dx = x[k] - p[0];
      const double dy = y[k] - p[1];
      const double d = std::hypot(dx, dy);
      residual(i) = w[k] * (d - p[2]);
      jacobian(i, 0) = -w[k] * dx / d;
      jacobian(i, 1) = -w[k] * dy / d;
      jacobian(i, 2) = -w[k];
    }
    const Eigen::Vector3d step = jacobian.colPivHouseholderQr().solve(-residual);
    const double trial[3] = {p[0] + step(0), p[1] + step(1), p[2] + step(2)};
    const double trial_cost = WeightedCost(x, y, w, trial);
    if (!(trial_cost <= cost * (1.0 + kCostRounding))) break;
    std::copy(trial, trial + 3, p);
    cost = trial_cost;
    const double size = step.norm();
    if (!(size < 0.5 * last_step)) break;  // rounding, no longer convergence
    last_step = size;
  }
}

// The points centred on their centroid and scaled to unit rms spread, so that the fit works on
// O(1) numbers.
struct ScaledPoints {
  std::vector<double> x, y, w;
  double cx = 0.0, cy = 0.0, scale = 0.0;
};

ScaledPoints ScalePoints(std::span<const double> x_in, std::span<const double> y_in,
                         std::span<const double> weights) {
  const std::size_t n = x_in.size();
  ScaledPoints out;
  for (std::size_t i = 0; i < n; ++i) {
    out.cx += x_in[i];
    out.cy += y_in[i];
  }
  out.cx /= static_cast<double>(n);
  out.cy /= static_cast<double>(n);
  double spread = 0;
  for (std::size_t i = 0; i < n; ++i)
    spread += (x_in[i] - out.cx) * (x_in[i] - out.cx) + (y_in[i] - out.cy) * (y_in[i] - out.cy);
  out.scale = std::sqrt(spread / static_cast<double>(n));
  if (!(out.scale > 0)) return out;
  out.x.resize(n);
  out.y.resize(n);
  out.w.assign(n, 1.0);
  for (std::size_t i = 0; i < n; ++i) {
    out.x[i] = (x_in[i] - out.cx) / out.scale;
    out.y[i] = (y_in[i] - out.cy) / out.scale;
    if (!weights.empty()) out.w[i] = weights[i];
  }
  return out;
}

ceres::Solver::Summary SolveWithCeres(ceres::Problem& problem, int max_iterations) {
  ceres::Solver::Options solver_options;
  solver_options.linear_solver_type = ceres::DENSE_QR;
  solver_options.max_num_iterations = max_iterations;
  // Levenberg-Marquardt only has to bring the circle near the minimum (a cost within 1e-8 of it is
  // within 1e-4 sqrt(n) sigma); PolishByGaussNewton goes the rest of the way.
  solver_options.function_tolerance = 1e-8;
  solver_options.gradient_tolerance = 1e-8;
  solver_options.parameter_tolerance = 1e-8;
  solver_options.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(solver_options, &problem, &summary);
  return summary;
}

// Sets the circle, the residual statistics and the sensitivity to y from the solution p of the
// scaled problem.
void SetSolution(const ScaledPoints& s, const double p[3], CircleFit& fit) {
  const std::size_t n = s.x.size();
  const auto& x = s.x;
  const auto& y = s.y;
  const auto& w = s.w;
  // Jacobian at the solution (unscaled units follow from the chain rule: a, b, r scale with `scale`).
  Eigen::MatrixXd jacobian(static_cast<Eigen::Index>(n), 3);
  double rss_weighted = 0.0, rss = 0.0, low = 0.0, high = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = x[i] - p[0];
    const double dy = y[i] - p[1];
    const double d = std::hypot(dx, dy);
    const double residual_mm = (d - p[2]) * s.scale;
    const auto row = static_cast<Eigen::Index>(i);
    jacobian(row, 0) = -w[i] * dx / d;
    jacobian(row, 1) = -w[i] * dy / d;
    jacobian(row, 2) = -w[i];
    rss_weighted += w[i] * w[i] * residual_mm * residual_mm;
    rss += residual_mm * residual_mm;
    low = i == 0 ? residual_mm : std::min(low, residual_mm);
    high = i == 0 ? residual_mm : std::max(high, residual_mm);
  }
  // How the solution moves when the points move along y (the sensor's direction), to first order:
  // dp = -(J^T J)^-1 J^T diag(w_i dy_i / d_i) dy, where w_i dy_i / d_i is -J(i, 1) (to the bit).
  const Eigen::Matrix3d normal = jacobian.transpose() * jacobian;
  const Eigen::VectorXd along_y = -jacobian.col(1);
  fit.sensitivity_to_y =
      -dense::LdltSolve(normal, Eigen::Matrix3Xd(jacobian.transpose() * along_y.asDiagonal()));
  fit.center_mm = {s.cx + p[0] * s.scale, s.cy + p[1] * s.scale};
  fit.radius_mm = p[2] * s.scale;
  fit.rms_residual_mm = std::sqrt(rss / static_cast<double>(n));
  fit.pv_residual_mm = high - low;
  fit.chi2 = rss_weighted;
}

// Sets fit.covariance to (J^T J)^-1 from the Jacobian at the solution by the computation of
// Ceres' DENSE_SVD covariance (ceres::Covariance with null_space_rank 0), without its problem
// set-up: the SVD of J (Eigen's BDCSVD, which runs a JacobiSVD with a column-pivoting QR for three
// columns), V diag(1 / s_i^2) V^T. Returns false, as Ceres does, if (s_i / s_max)^2 is below
// min_reciprocal_condition_number = 1e-14 for some singular value s_i.
// The Jacobian is the one Ceres evaluated (CircleResiduals at p), so the result is Ceres' to the bit.
bool SetCovariance(const CircleResiduals& residuals, const double p[3], const CircleFitOptions& options,
                   CircleFit& fit) {
  constexpr double kMinReciprocalConditionNumber = 1e-14;
  using RowMajorMatrix = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;
  RowMajorMatrix jacobian(fit.n, 3);
  Eigen::VectorXd values(fit.n);
  const double* parameters[] = {p};
  double* jacobians[] = {jacobian.data()};
  residuals.Evaluate(parameters, values.data(), jacobians);
  const Eigen::JacobiSVD<RowMajorMatrix, Eigen::ColPivHouseholderQRPreconditioner> svd(jacobian,
                                                                                       Eigen::ComputeThinV);
  const Eigen::VectorXd singular_values = svd.singularValues();
  const double max_singular_value = singular_values[0];
  const double min_singular_value_ratio = std::sqrt(kMinReciprocalConditionNumber);
  Eigen::Vector3d inverse_squared_singular_values;
  for (int i = 0; i < 3; ++i) {
    if (singular_values[i] / max_singular_value < min_singular_value_ratio) return false;
    inverse_squared_singular_values[i] = 1.0 / (singular_values[i] * singular_values[i]);
  }
  // Scaling by `scale` leaves the Jacobian unchanged (d(r/scale)/d(p/scale) = dr/dp), so
  // (J^T J)^-1 is already the covariance in mm^2 for residuals of unit variance: exact when the
  // weights are 1/sigma, else scaled by the residual variance.
  fit.covariance = svd.matrixV() * inverse_squared_singular_values.asDiagonal() * svd.matrixV().transpose();
  if (!options.weights_are_inverse_sigmas) {
    const auto n = static_cast<std::size_t>(fit.n);
    fit.covariance *= n > 3 ? fit.chi2 / static_cast<double>(n - 3) : 0.0;
  }
  return true;
}

CircleFit Degenerate(CircleFit fit, const std::string& message) {
  fit.status = FitStatus::kDegenerate;
  fit.message = message;
  return fit;
}

}  // namespace

std::vector<std::string> CircleFitOptions::Problems() const {
  if (max_iterations >= 1) return {};
  return {fmt::format("max_iterations = {} violates >= 1", max_iterations)};
}

CircleFit FitCircle(std::span<const double> x_in, std::span<const double> y_in,
                    std::span<const double> weights, const CircleFitOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "fitting.circle", options.Problems());
  CircleFit fit;
  const std::size_t n = x_in.size();
  fit.n = static_cast<int>(n);
  if (n < 3 || y_in.size() != n || (!weights.empty() && weights.size() != n)) {
    return Degenerate(fit, "a circle needs at least 3 points (and as many weights)");
  }
  const ScaledPoints points = ScalePoints(x_in, y_in, weights);
  if (!(points.scale > 0)) return Degenerate(fit, "all points coincide");
  double p[3];
  if (!AlgebraicCircle(points.x, points.y, points.w, p)) {
    return Degenerate(fit, "the points are collinear: no circle is determined");
  }

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  problem.AddResidualBlock(new CircleResiduals(points.x, points.y, points.w), nullptr, p);
  const ceres::Solver::Summary summary = SolveWithCeres(problem, options.max_iterations);
  fit.iterations = static_cast<int>(summary.iterations.size());
  PolishByGaussNewton(points.x, points.y, points.w, p);
  SetSolution(points, p, fit);
  if (!SetCovariance(CircleResiduals(points.x, points.y, points.w), p, options, fit)) {
    return Degenerate(fit, "the points do not determine the circle (ill-conditioned)");
  }
  if (summary.termination_type == ceres::CONVERGENCE || summary.termination_type == ceres::USER_SUCCESS) {
    fit.status = FitStatus::kConverged;
    fit.message = "converged";
  } else {
    fit.status = FitStatus::kNoConvergence;
    fit.message = "did not converge: " + summary.message;
  }
  return fit;
}

}  // namespace arcwheel::fitting
