#pragma once
// Best-fit transforms between two frames from N >= 3 corresponding points (formats.md section 5):
// 3D rigid, 3D similarity (7-parameter Helmert), 2D rigid and 2D affine, each in closed form.
//
//   rigid3d, similarity3d, rigid2d: Umeyama (1991), "Least-squares estimation of transformation
//     parameters between two point patterns", IEEE PAMI 13(4): SVD of the cross-covariance of the
//     centred point sets with the reflection fix, which gives the global least-squares optimum.
//   affine2d: linear least squares (QR) on the six matrix and translation entries.
//
// The least-squares objective is sum_i |t_i - (scale * R * s_i + translation)|^2 over the pairs
// used. Parameter covariance is sigma^2 (J^T J)^-1 with J the Jacobian of the fitted targets at the
// solution and sigma^2 = RSS / (d * n - p) (d = 2 or 3 coordinates per pair, p parameters);
// it assumes independent, equal-variance errors in the target coordinates only.

#include <Eigen/Core>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "frames/transform.h"

namespace arcwheel::frames {

struct PointPair {
  Eigen::Vector3d source_mm = Eigen::Vector3d::Zero();  // z ignored by the planar models
  Eigen::Vector3d target_mm = Eigen::Vector3d::Zero();
};

struct TransformFitOptions {
  // A pair is flagged as an outlier when its leave-one-out residual norm exceeds this many times
  // sigma * sqrt(d), sigma being the per-coordinate residual sigma of the fit without that pair.
  // > 0; scoring needs one spare pair beyond what the model needs without it.
  double outlier_threshold = 3.0;
  // Remove flagged pairs one at a time (worst first), refitting each time, until none is left.
  bool drop_outliers = false;
  // The geometry is refused as degenerate when the smallest singular value that the model needs
  // of the centred source points (or of the source-target cross-covariance) is below this
  // fraction of the largest. In (0, 1).
  double degenerate_ratio = 1e-9;
  // Empty when valid, else one line per violation with its value, named by the flag of `arcwheel
  // transform fit` / `headcenter calibrate` ("--outlier-threshold = 0 violates > 0") or, without
  // one, by its field ("degenerate_ratio").
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct TransformFit {
  Transform transform;
  // Reported parameters, in this order:
  //   rigid3d:      tx_mm ty_mm tz_mm rx_rad ry_rad rz_rad   (position-vector angles, R = Rz Ry Rx)
  //   similarity3d: the same and scale
  //   rigid2d:      tx_mm ty_mm theta_rad                   (counter-clockwise, x toward y)
  //   affine2d:     a11 a12 a21 a22 tx_mm ty_mm             (row-major 2x2 matrix)
  std::vector<std::string> parameter_names;
  Eigen::VectorXd parameters;
  // Covariance of `parameters`; empty when there are no degrees of freedom left.
  std::optional<Eigen::MatrixXd> covariance;
  // Per pair, in input order, including dropped ones: target - fitted target (z = 0 in 2D).
  std::vector<Eigen::Vector3d> residuals_mm;
  // Leave-one-out outlier score per pair (see TransformFitOptions); NaN where it cannot be scored.
  std::vector<double> outlier_score;
  std::vector<bool> is_outlier;
  std::vector<bool> used;  // false for the pairs dropped as outliers
  int pairs_used = 0;
  int degrees_of_freedom = 0;      // d * pairs_used - p
  double rms_residual_mm = 0.0;    // sqrt(mean |r_i|^2) over the pairs used
  double max_residual_mm = 0.0;    // largest |r_i| over the pairs used
  std::optional<double> sigma_mm;  // sqrt(RSS / dof): per-coordinate residual sigma
  double geometry_ratio = 0.0;     // the singular-value ratio tested against degenerate_ratio
};

// Throws Error{kBadInput, "frames.transform_fit"} for fewer than 3 pairs, non-finite coordinates
// or degenerate geometry (coincident points; collinear points for the 3D models and affine2d);
// Error{kInvalidOption} for invalid options.
[[nodiscard]] TransformFit FitTransform(std::span<const PointPair> pairs, TransformModel model,
                                        const TransformFitOptions& options = {});

// The closed-form fit alone over the given pairs, no statistics. Same errors as FitTransform.
[[nodiscard]] Transform FitTransformExact(std::span<const PointPair> pairs, TransformModel model,
                                          double degenerate_ratio = 1e-9);

}  // namespace arcwheel::frames
