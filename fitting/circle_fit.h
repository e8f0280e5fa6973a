#pragma once
// Least-squares circle through 2D points (method.md A.5, eqs. 6-7): minimises
//   sum_i w_i^2 ( sqrt((x_i - a)^2 + (y_i - b)^2) - r )^2
// (geometric, orthogonal-distance fit) with Ceres' Levenberg-Marquardt, started from the
// algebraic (Kasa) circle. The points are centred and scaled first, so short arcs far from the
// origin (a 10 deg arc, coordinates offset by 1e5 mm) lose no digits.

#include <Eigen/Core>
#include <cmath>
#include <span>
#include <string>
#include <vector>

#include "fitting/circle_fit_options.h"

namespace arcwheel::fitting {

struct CircleFit {
  Eigen::Vector2d center_mm = Eigen::Vector2d::Zero();
  double radius_mm = 0.0;
  // Covariance of (a, b, r), mm^2.
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Zero();
  // d(a, b, r) / d(y_i): how the fit follows a shift of point i along y, for propagating
  // correlated noise (3 x n).
  Eigen::Matrix3Xd sensitivity_to_y;
  double rms_residual_mm = 0.0;  // unweighted geometric residuals
  double pv_residual_mm = 0.0;   // max - min of the geometric residuals
  double chi2 = 0.0;             // sum of weighted squared residuals
  int n = 0;
  int iterations = 0;
  FitStatus status = FitStatus::kNotRun;
  std::string message = "FitCircle was not called.";
  [[nodiscard]] bool IsUsable() const { return status == FitStatus::kConverged; }
  [[nodiscard]] double radius_sigma_mm() const { return std::sqrt(covariance(2, 2)); }
};

// `weights` empty means all 1. Needs n >= 3 points not all on one line. Throws
// Error{kInvalidOption, "fitting.circle"} for invalid options.
[[nodiscard]] CircleFit FitCircle(std::span<const double> x, std::span<const double> y,
                                  std::span<const double> weights, const CircleFitOptions& options);

}  // namespace arcwheel::fitting
