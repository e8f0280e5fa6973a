#include "frames/transform_fit.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/dense.h"
#include "core/error.h"

namespace arcwheel::frames {
namespace {

constexpr const char* kTransformFitStage = "frames.transform_fit";
constexpr int kMinimumPairs = 3;

Eigen::MatrixXd Coordinates(std::span<const PointPair> pairs, int dimension, bool source) {
  Eigen::MatrixXd points(dimension, static_cast<Eigen::Index>(pairs.size()));
  for (size_t i = 0; i < pairs.size(); ++i) {
    const Eigen::Vector3d& p = source ? pairs[i].source_mm : pairs[i].target_mm;
    points.col(static_cast<Eigen::Index>(i)) = p.head(dimension);
  }
  return points;
}

void CheckInputs(std::span<const PointPair> pairs, TransformModel model) {
  if (pairs.size() < kMinimumPairs) {
    throw Error(
        ErrorCode::kBadInput, kTransformFitStage,
        fmt::format("{} point pairs; {} needs at least {}", pairs.size(), ModelName(model), kMinimumPairs));
  }
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!pairs[i].source_mm.allFinite() || !pairs[i].target_mm.allFinite()) {
      throw Error(ErrorCode::kBadInput, kTransformFitStage,
                  fmt::format("pair {} has a non-finite coordinate", i + 1));
    }
  }
}

// Singular values of the centred point set, largest first.
Eigen::VectorXd SpreadSingularValues(const Eigen::MatrixXd& centred) {
  return dense::JacobiSvd(centred).singular_values;
}

// How many independent directions the model needs the source points to span.
int RequiredRank(TransformModel model) { return model == TransformModel::kRigid2d ? 1 : 2; }

// Ratio of the last needed singular value to the largest; coincident points give 0.
double GeometryRatio(const Eigen::VectorXd& singular_values, int rank, double coordinate_scale) {
  const double largest = singular_values(0);
  if (!(largest > 1e-12 * coordinate_scale)) return 0.0;
  return singular_values(rank - 1) / largest;
}

void RefuseDegenerate(double ratio, double limit, TransformModel model, const char* what) {
  if (ratio > limit) return;
  const char* shape = RequiredRank(model) == 1 ? "coincident" : "coincident or collinear";
  throw Error(ErrorCode::kBadInput, kTransformFitStage,
              fmt::format("the {} are {} (singular-value ratio {:.3g} <= {:.3g}): {} is not determined", what,
                          shape, ratio, limit, ModelName(model)));
}

struct Centred {
  Eigen::VectorXd mean_source, mean_target;
  Eigen::MatrixXd source, target;
};

Centred Centre(std::span<const PointPair> pairs, int dimension) {
  Centred c;
  c.source = Coordinates(pairs, dimension, true);
  c.target = Coordinates(pairs, dimension, false);
  c.mean_source = c.source.rowwise().mean();
  c.mean_target = c.target.rowwise().mean();
  c.source.colwise() -= c.mean_source;
  c.target.colwise() -= c.mean_target;
  return c;
}

double CoordinateScale(std::span<const PointPair> pairs) {
  double scale = 1.0;
  for (const PointPair& p : pairs)
    scale = std::max({scale, p.source_mm.cwiseAbs().maxCoeff(), p.target_mm.cwiseAbs().maxCoeff()});
  return scale;
}

Transform Embed(TransformModel model, const Eigen::MatrixXd& linear, double scale,
                const Eigen::VectorXd& translation) {
  Transform t;
  t.model = model;
  t.scale = scale;
  const auto d = linear.rows();
  t.linear.topLeftCorner(d, d) = linear;
  t.translation_mm.head(d) = translation;
  return t;
}

Transform FitUmeyama(const Centred& c, TransformModel model, double degenerate_ratio,
                     double coordinate_scale) {
  const auto n = static_cast<double>(c.source.cols());
  const auto d = c.source.rows();
  const Eigen::MatrixXd cross = c.target * c.source.transpose() / n;
  const dense::Svd svd = dense::JacobiSvd(cross, Eigen::ComputeFullU | Eigen::ComputeFullV);
  // The cross-covariance is quadratic in lengths: its square-rooted ratio compares with the spread ratio.
  RefuseDegenerate(
      std::sqrt(GeometryRatio(svd.singular_values, RequiredRank(model), coordinate_scale * coordinate_scale)),
      degenerate_ratio, model, "target points (against the source points)");
  Eigen::VectorXd signs = Eigen::VectorXd::Ones(d);
  if (svd.u.determinant() * svd.v.determinant() < 0.0) signs(d - 1) = -1.0;
  const Eigen::MatrixXd rotation = svd.u * signs.asDiagonal() * svd.v.transpose();
  double scale = 1.0;
  if (model == TransformModel::kSimilarity3d) {
    const double source_variance = c.source.squaredNorm() / n;
    scale = svd.singular_values.dot(signs) / source_variance;
    if (!(scale > 0.0)) {
      throw Error(ErrorCode::kFitFailed, kTransformFitStage,
                  fmt::format("the fitted scale {:.6g} is not positive", scale));
    }
  }
  const Eigen::VectorXd translation = c.mean_target - scale * rotation * c.mean_source;
  return Embed(model, rotation, scale, translation);
}

Transform FitAffine2d(std::span<const PointPair> pairs) {
  // Each target coordinate is an independent linear regression on (x, y, 1).
  const auto n = static_cast<Eigen::Index>(pairs.size());
  Eigen::MatrixXd design(n, 3);
  Eigen::MatrixXd targets(n, 2);
  for (Eigen::Index i = 0; i < n; ++i) {
    design.row(i) << pairs[i].source_mm.x(), pairs[i].source_mm.y(), 1.0;
    targets.row(i) = pairs[i].target_mm.head<2>().transpose();
  }
  const Eigen::MatrixXd solution = dense::ColPivQrSolve(design, targets);  // 3 x 2
  const Eigen::Matrix2d matrix = solution.topRows<2>().transpose();
  return Embed(TransformModel::kAffine2d, matrix, 1.0, solution.row(2).transpose());
}

// d(fitted target)/d(parameters) at the solution, in the internal parametrisation:
// 3D: translation, left rotation increment w (R -> exp([w]x) R), [scale]; 2D rigid: tx, ty, theta;
// affine2d: a11 a12 a21 a22 tx ty.
Eigen::MatrixXd Jacobian(std::span<const PointPair> pairs, const Transform& t) {
  const int d = ModelDimension(t.model);
  const int p = ModelParameterCount(t.model);
  Eigen::MatrixXd jacobian = Eigen::MatrixXd::Zero(d * static_cast<Eigen::Index>(pairs.size()), p);
  for (size_t i = 0; i < pairs.size(); ++i) {
    const auto row = static_cast<Eigen::Index>(d * i);
    const Eigen::Vector3d& s = pairs[i].source_mm;
    const Eigen::Vector3d rotated = t.linear * s;
    jacobian.block(row, 0, d, d).setIdentity();
    switch (t.model) {
      case TransformModel::kRigid3d:
      case TransformModel::kSimilarity3d: {
        const Eigen::Vector3d v = t.scale * rotated;
        Eigen::Matrix3d minus_hat;
        minus_hat << 0, v.z(), -v.y(), -v.z(), 0, v.x(), v.y(), -v.x(), 0;
        jacobian.block<3, 3>(row, 3) = minus_hat;
        if (t.model == TransformModel::kSimilarity3d) jacobian.block<3, 1>(row, 6) = rotated;
        break;
      }
      case TransformModel::kRigid2d:
        jacobian(row, 2) = -rotated.y();
        jacobian(row + 1, 2) = rotated.x();
        break;
      case TransformModel::kAffine2d:
        jacobian.block(row, 0, 2, 6).setZero();
        jacobian.block(row, 0, 1, 2) << s.x(), s.y();
        jacobian.block(row + 1, 2, 1, 2) << s.x(), s.y();
        jacobian(row, 4) = 1.0;
        jacobian(row + 1, 5) = 1.0;
        break;
    }
  }
  return jacobian;
}

std::vector<std::string> ParameterNames(TransformModel model) {
  switch (model) {
    case TransformModel::kRigid3d:
      return {"tx_mm", "ty_mm", "tz_mm", "rx_rad", "ry_rad", "rz_rad"};
    case TransformModel::kSimilarity3d:
      return {"tx_mm", "ty_mm", "tz_mm", "rx_rad", "ry_rad", "rz_rad", "scale"};
    case TransformModel::kRigid2d:
      return {"tx_mm", "ty_mm", "theta_rad"};
    case TransformModel::kAffine2d:
      return {"a11", "a12", "a21", "a22", "tx_mm", "ty_mm"};
  }
  return {};
}

Eigen::VectorXd ReportedParameters(const Transform& t) {
  Eigen::VectorXd p(ModelParameterCount(t.model));
  switch (t.model) {
    case TransformModel::kRigid3d:
    case TransformModel::kSimilarity3d:
      p.head<3>() = t.translation_mm;
      p.segment<3>(3) = AnglesFromRotation(t.linear);
      if (t.model == TransformModel::kSimilarity3d) p(6) = t.scale;
      break;
    case TransformModel::kRigid2d:
      p << t.translation_mm.x(), t.translation_mm.y(), std::atan2(t.linear(1, 0), t.linear(0, 0));
      break;
    case TransformModel::kAffine2d:
      p << t.linear(0, 0), t.linear(0, 1), t.linear(1, 0), t.linear(1, 1), t.translation_mm.x(),
          t.translation_mm.y();
      break;
  }
  return p;
}

// d(reported parameters)/d(internal parameters): identity except for the 3D angles, whose
// derivative with respect to the rotation increment is taken by central differences.
Eigen::MatrixXd ReportingJacobian(const Transform& t) {
  const int p = ModelParameterCount(t.model);
  Eigen::MatrixXd g = Eigen::MatrixXd::Identity(p, p);
  if (ModelDimension(t.model) == 2) return g;
  constexpr double kStep = 1e-6;
  for (int k = 0; k < 3; ++k) {
    const Eigen::Matrix3d plus =
        Eigen::AngleAxisd(kStep, Eigen::Vector3d::Unit(k)).toRotationMatrix() * t.linear;
    const Eigen::Matrix3d minus =
        Eigen::AngleAxisd(-kStep, Eigen::Vector3d::Unit(k)).toRotationMatrix() * t.linear;
    g.block<3, 1>(3, 3 + k) = (AnglesFromRotation(plus) - AnglesFromRotation(minus)) / (2.0 * kStep);
  }
  return g;
}

std::vector<PointPair> Subset(std::span<const PointPair> pairs, const std::vector<bool>& keep) {
  std::vector<PointPair> subset;
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (keep[i]) subset.push_back(pairs[i]);
  }
  return subset;
}

// |r| over the model's coordinates (z ignored by the planar models).
double ResidualNorm(Eigen::Vector3d r, int dimension) {
  if (dimension == 2) r.z() = 0.0;
  return r.norm();
}

double ResidualSumOfSquares(std::span<const PointPair> pairs, const Transform& t) {
  const int d = ModelDimension(t.model);
  double sum = 0.0;
  for (const PointPair& p : pairs) {
    const double r = ResidualNorm(p.target_mm - t.ApplyToPoint(p.source_mm), d);
    sum += r * r;
  }
  return sum;
}

// Leave-one-out score of every kept pair; NaN where the rest cannot determine the model with
// spare degrees of freedom.
std::vector<double> OutlierScores(std::span<const PointPair> pairs, const std::vector<bool>& keep,
                                  TransformModel model, double degenerate_ratio) {
  const int d = ModelDimension(model);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  std::vector<double> scores(pairs.size(), nan);
  for (size_t i = 0; i < pairs.size(); ++i) {
    if (!keep[i]) continue;
    std::vector<bool> others = keep;
    others[i] = false;
    const std::vector<PointPair> rest = Subset(pairs, others);
    const int dof = d * static_cast<int>(rest.size()) - ModelParameterCount(model);
    if (rest.size() < kMinimumPairs || dof <= 0) continue;
    Transform fit;
    try {
      fit = FitTransformExact(rest, model, degenerate_ratio);
    } catch (const Error&) {
      continue;  // the others alone are degenerate: this pair cannot be judged
    }
    const double deleted = ResidualNorm(pairs[i].target_mm - fit.ApplyToPoint(pairs[i].source_mm), d);
    const double sigma = std::sqrt(ResidualSumOfSquares(rest, fit) / dof);
    const double floor = 1e-12 * CoordinateScale(pairs);
    if (sigma > floor) {
      scores[i] = deleted / (sigma * std::sqrt(static_cast<double>(d)));
    } else {
      scores[i] = deleted > 1e3 * floor ? std::numeric_limits<double>::infinity() : 0.0;
    }
  }
  return scores;
}

void FillStatistics(std::span<const PointPair> pairs, TransformFit& fit) {
  const TransformModel model = fit.transform.model;
  const int d = ModelDimension(model);
  const int p = ModelParameterCount(model);
  const std::vector<PointPair> used = Subset(pairs, fit.used);
  fit.pairs_used = static_cast<int>(used.size());
  fit.degrees_of_freedom = d * fit.pairs_used - p;
  fit.residuals_mm.assign(pairs.size(), Eigen::Vector3d::Zero());
  double sum_squares = 0.0;
  fit.max_residual_mm = 0.0;
  for (size_t i = 0; i < pairs.size(); ++i) {
    Eigen::Vector3d r = pairs[i].target_mm - fit.transform.ApplyToPoint(pairs[i].source_mm);
    if (d == 2) r.z() = 0.0;
    fit.residuals_mm[i] = r;
    if (!fit.used[i]) continue;
    sum_squares += r.squaredNorm();
    fit.max_residual_mm = std::max(fit.max_residual_mm, r.norm());
  }
  fit.rms_residual_mm = std::sqrt(sum_squares / fit.pairs_used);
  fit.parameter_names = ParameterNames(model);
  fit.parameters = ReportedParameters(fit.transform);
  fit.sigma_mm.reset();
  fit.covariance.reset();
  if (fit.degrees_of_freedom <= 0) return;
  const double variance = sum_squares / fit.degrees_of_freedom;
  fit.sigma_mm = std::sqrt(variance);
  const Eigen::MatrixXd jacobian = Jacobian(used, fit.transform);
  const Eigen::MatrixXd information = jacobian.transpose() * jacobian;
  const Eigen::MatrixXd internal =
      variance * dense::LdltSolve(information, Eigen::MatrixXd(Eigen::MatrixXd::Identity(p, p)));
  const Eigen::MatrixXd g = ReportingJacobian(fit.transform);
  fit.covariance = g * internal * g.transpose();
}

}  // namespace

std::vector<std::string> TransformFitOptions::Problems() const {
  std::vector<std::string> problems;
  if (!(outlier_threshold > 0.0))
    problems.push_back(fmt::format("--outlier-threshold = {} violates > 0", outlier_threshold));
  if (!(degenerate_ratio > 0.0 && degenerate_ratio < 1.0))
    problems.push_back(fmt::format("degenerate_ratio = {} violates (0, 1)", degenerate_ratio));
  return problems;
}

Transform FitTransformExact(std::span<const PointPair> pairs, TransformModel model, double degenerate_ratio) {
  CheckInputs(pairs, model);
  const int d = ModelDimension(model);
  const Centred centred = Centre(pairs, d);
  const double coordinate_scale = CoordinateScale(pairs);
  RefuseDegenerate(GeometryRatio(SpreadSingularValues(centred.source), RequiredRank(model), coordinate_scale),
                   degenerate_ratio, model, "source points");
  if (model == TransformModel::kAffine2d) return FitAffine2d(pairs);
  return FitUmeyama(centred, model, degenerate_ratio, coordinate_scale);
}

TransformFit FitTransform(std::span<const PointPair> pairs, TransformModel model,
                          const TransformFitOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kTransformFitStage, options.Problems());
  TransformFit fit;
  fit.used.assign(pairs.size(), true);
  fit.transform = FitTransformExact(pairs, model, options.degenerate_ratio);
  const int d = ModelDimension(model);
  const Centred centred = Centre(pairs, d);
  fit.geometry_ratio =
      GeometryRatio(SpreadSingularValues(centred.source), RequiredRank(model), CoordinateScale(pairs));
  fit.outlier_score = OutlierScores(pairs, fit.used, model, options.degenerate_ratio);
  while (options.drop_outliers) {
    size_t worst = pairs.size();
    for (size_t i = 0; i < pairs.size(); ++i) {
      const double score = fit.outlier_score[i];
      if (fit.used[i] && score > options.outlier_threshold &&
          (worst == pairs.size() || score > fit.outlier_score[worst])) {
        worst = i;
      }
    }
    if (worst == pairs.size()) break;
    std::vector<bool> keep = fit.used;
    keep[worst] = false;
    Transform refit;
    try {
      refit = FitTransformExact(Subset(pairs, keep), model, options.degenerate_ratio);
    } catch (const Error&) {
      break;  // dropping it would leave too little to fit: keep it, flagged
    }
    const double dropped_score = fit.outlier_score[worst];
    fit.used = keep;
    fit.transform = refit;
    fit.outlier_score = OutlierScores(pairs, fit.used, model, options.degenerate_ratio);
    fit.outlier_score[worst] = dropped_score;
  }
  fit.is_outlier.assign(pairs.size(), false);
  for (size_t i = 0; i < pairs.size(); ++i) {
    fit.is_outlier[i] = !fit.used[i] || fit.outlier_score[i] > options.outlier_threshold;
  }
  FillStatistics(pairs, fit);
  return fit;
}

}  // namespace arcwheel::frames
