#include "frames/transform_fit.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <random>
#include <vector>

#include "core/error.h"

namespace arcwheel::frames {
namespace {

// The models written out independently of the library, in the reported parametrisation.
Eigen::Matrix3d RotX(double a) {
  Eigen::Matrix3d r;
  r << 1, 0, 0, 0, std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a);
  return r;
}
Eigen::Matrix3d RotY(double a) {
  Eigen::Matrix3d r;
  r << std::cos(a), 0, std::sin(a), 0, 1, 0, -std::sin(a), 0, std::cos(a);
  return r;
}
Eigen::Matrix3d RotZ(double a) {
  Eigen::Matrix3d r;
  r << std::cos(a), -std::sin(a), 0, std::sin(a), std::cos(a), 0, 0, 0, 1;
  return r;
}

// Target coordinates (d per point) predicted by the model with parameters `theta`.
Eigen::VectorXd Predict(TransformModel model, const Eigen::VectorXd& theta,
                        const std::vector<Eigen::Vector3d>& source) {
  const int d = ModelDimension(model);
  Eigen::VectorXd out(d * static_cast<Eigen::Index>(source.size()));
  for (size_t i = 0; i < source.size(); ++i) {
    const Eigen::Vector3d& s = source[i];
    Eigen::Vector3d t = Eigen::Vector3d::Zero();
    switch (model) {
      case TransformModel::kRigid3d:
        t = RotZ(theta(5)) * RotY(theta(4)) * RotX(theta(3)) * s + theta.head<3>();
        break;
      case TransformModel::kSimilarity3d:
        t = theta(6) * RotZ(theta(5)) * RotY(theta(4)) * RotX(theta(3)) * s + theta.head<3>();
        break;
      case TransformModel::kRigid2d:
        t.x() = std::cos(theta(2)) * s.x() - std::sin(theta(2)) * s.y() + theta(0);
        t.y() = std::sin(theta(2)) * s.x() + std::cos(theta(2)) * s.y() + theta(1);
        break;
      case TransformModel::kAffine2d:
        t.x() = theta(0) * s.x() + theta(1) * s.y() + theta(4);
        t.y() = theta(2) * s.x() + theta(3) * s.y() + theta(5);
        break;
    }
    out.segment(d * static_cast<Eigen::Index>(i), d) = t.head(d);
  }
  return out;
}

Eigen::MatrixXd NumericJacobian(TransformModel model, const Eigen::VectorXd& theta,
                                const std::vector<Eigen::Vector3d>& source) {
  const Eigen::VectorXd f0 = Predict(model, theta, source);
  Eigen::MatrixXd jacobian(f0.size(), theta.size());
  for (Eigen::Index k = 0; k < theta.size(); ++k) {
    const double h = 1e-6 * std::max(1.0, std::abs(theta(k)));
    Eigen::VectorXd plus = theta, minus = theta;
    plus(k) += h;
    minus(k) -= h;
    jacobian.col(k) = (Predict(model, plus, source) - Predict(model, minus, source)) / (2 * h);
  }
  return jacobian;
}

Eigen::VectorXd TrueParameters(TransformModel model) {
  switch (model) {
    case TransformModel::kRigid3d:
      return (Eigen::VectorXd(6) << 812.5, -230.25, 45.0, 0.03, -0.2, 1.1).finished();
    case TransformModel::kSimilarity3d:
      return (Eigen::VectorXd(7) << 812.5, -230.25, 45.0, 0.03, -0.2, 1.1, 1.000025).finished();
    case TransformModel::kRigid2d:
      return (Eigen::VectorXd(3) << -35.5, 120.0, -0.7).finished();
    case TransformModel::kAffine2d:
      return (Eigen::VectorXd(6) << 0.98, 0.05, -0.03, 1.02, 15.0, -7.5).finished();
  }
  return {};
}

std::vector<Eigen::Vector3d> RandomSource(int count, int dimension, std::mt19937& rng) {
  std::uniform_real_distribution<double> coordinate(-400.0, 400.0);
  std::vector<Eigen::Vector3d> points(count);
  for (auto& p : points) p = {coordinate(rng), coordinate(rng), dimension == 3 ? coordinate(rng) : 0.0};
  return points;
}

std::vector<PointPair> MakePairs(TransformModel model, const std::vector<Eigen::Vector3d>& source,
                                 const Eigen::VectorXd& targets) {
  const int d = ModelDimension(model);
  std::vector<PointPair> pairs(source.size());
  for (size_t i = 0; i < source.size(); ++i) {
    pairs[i].source_mm = source[i];
    pairs[i].target_mm.head(d) = targets.segment(d * static_cast<Eigen::Index>(i), d);
  }
  return pairs;
}

// Relative agreement: lengths against the 400 mm extent of the points, angles against 1 rad,
// dimensionless entries against 1.
void ExpectParametersNear(const TransformFit& fit, const Eigen::VectorXd& expected, double relative) {
  ASSERT_EQ(fit.parameters.size(), expected.size());
  for (Eigen::Index k = 0; k < expected.size(); ++k) {
    const bool length = fit.parameter_names[k].ends_with("_mm");
    const double reference = std::max(std::abs(expected(k)), length ? 400.0 : 1.0);
    EXPECT_NEAR(fit.parameters(k), expected(k), relative * reference) << fit.parameter_names[k];
  }
}

constexpr TransformModel kModels[] = {TransformModel::kRigid3d, TransformModel::kSimilarity3d,
                                      TransformModel::kRigid2d, TransformModel::kAffine2d};

TEST(FitTransform, RecoversEveryModelExactlyFromExactData) {
  std::mt19937 rng(7001);
  for (const TransformModel model : kModels) {
    const auto source = RandomSource(8, ModelDimension(model), rng);
    const Eigen::VectorXd theta = TrueParameters(model);
    const TransformFit fit = FitTransform(MakePairs(model, source, Predict(model, theta, source)), model);
    SCOPED_TRACE(std::string(ModelName(model)));
    ExpectParametersNear(fit, theta, 1e-9);
    EXPECT_LT(fit.rms_residual_mm, 1e-9);
    EXPECT_EQ(fit.pairs_used, 8);
  }
}

TEST(FitTransform, ReturnsTheKnownLeastSquaresSolutionOfAReferenceSet) {
  // Targets = model(theta) + e projected onto the orthogonal complement of the Jacobian's columns
  // at theta: theta is then the least-squares solution and the projected e its residual vector.
  std::mt19937 rng(7002);
  std::normal_distribution<double> noise(0.0, 0.02);
  for (const TransformModel model : kModels) {
    SCOPED_TRACE(std::string(ModelName(model)));
    const int d = ModelDimension(model);
    const auto source = RandomSource(12, d, rng);
    const Eigen::VectorXd theta = TrueParameters(model);
    const Eigen::MatrixXd jacobian = NumericJacobian(model, theta, source);
    Eigen::VectorXd e(jacobian.rows());
    for (auto& v : e) v = noise(rng);
    const Eigen::VectorXd residual = e - jacobian * jacobian.colPivHouseholderQr().solve(e);
    const TransformFit fit =
        FitTransform(MakePairs(model, source, Predict(model, theta, source) + residual), model);
    ExpectParametersNear(fit, theta, 1e-9);
    for (size_t i = 0; i < source.size(); ++i) {
      for (int c = 0; c < d; ++c) EXPECT_NEAR(fit.residuals_mm[i](c), residual(d * i + c), 1e-9);
    }
    EXPECT_NEAR(fit.rms_residual_mm, residual.norm() / std::sqrt(12.0), 1e-12);
    const int dof = d * 12 - ModelParameterCount(model);
    EXPECT_EQ(fit.degrees_of_freedom, dof);
    EXPECT_NEAR(*fit.sigma_mm, residual.norm() / std::sqrt(dof), 1e-12);
    // The covariance is sigma^2 (J^T J)^-1 with J from the independent model.
    const Eigen::MatrixXd expected =
        (*fit.sigma_mm) * (*fit.sigma_mm) * (jacobian.transpose() * jacobian).inverse();
    for (Eigen::Index k = 0; k < expected.rows(); ++k) {
      EXPECT_NEAR(std::sqrt((*fit.covariance)(k, k)), std::sqrt(expected(k, k)),
                  1e-5 * std::sqrt(expected(k, k)));
    }
  }
}

TEST(FitTransform, NoisyDataGiveTheNoiseSigmaAndTheParameterSpreadTheCovariancePredicts) {
  std::mt19937 rng(7003);
  constexpr double kSigmaMm = 0.01;
  constexpr int kTrials = 400;
  std::normal_distribution<double> noise(0.0, kSigmaMm);
  for (const TransformModel model : kModels) {
    SCOPED_TRACE(std::string(ModelName(model)));
    const int d = ModelDimension(model);
    const auto source = RandomSource(10, d, rng);
    const Eigen::VectorXd theta = TrueParameters(model);
    const Eigen::VectorXd exact = Predict(model, theta, source);
    const Eigen::Index p = theta.size();
    Eigen::VectorXd sum_squares = Eigen::VectorXd::Zero(p);
    Eigen::VectorXd predicted_variance = Eigen::VectorXd::Zero(p);
    double sum_sigma_squared = 0.0;
    for (int trial = 0; trial < kTrials; ++trial) {
      Eigen::VectorXd targets = exact;
      for (auto& v : targets) v += noise(rng);
      const TransformFit fit = FitTransform(MakePairs(model, source, targets), model);
      sum_squares += (fit.parameters - theta).array().square().matrix();
      predicted_variance += fit.covariance->diagonal();
      sum_sigma_squared += *fit.sigma_mm * *fit.sigma_mm;
    }
    // E[sigma_hat^2] = sigma^2; the mean of 400 draws of a chi-square/dof (dof >= 24) has a
    // relative sd below 1.5 %; 5 % is over 3 sd.
    EXPECT_NEAR(sum_sigma_squared / kTrials, kSigmaMm * kSigmaMm, 0.05 * kSigmaMm * kSigmaMm);
    // The empirical variance of each parameter over 400 trials has a relative sd of ~7 %.
    for (Eigen::Index k = 0; k < p; ++k) {
      EXPECT_NEAR(sum_squares(k) / predicted_variance(k), 1.0, 0.25) << k;
    }
  }
}

TEST(FitTransform, FlagsAndDropsAGrossOutlier) {
  std::mt19937 rng(7004);
  std::normal_distribution<double> noise(0.0, 0.005);
  const TransformModel model = TransformModel::kRigid3d;
  const auto source = RandomSource(10, 3, rng);
  const Eigen::VectorXd theta = TrueParameters(model);
  Eigen::VectorXd targets = Predict(model, theta, source);
  for (auto& v : targets) v += noise(rng);
  targets(3 * 6 + 1) += 2.0;  // pair 7, 2 mm off in y
  const auto pairs = MakePairs(model, source, targets);

  const TransformFit flagged = FitTransform(pairs, model, {.outlier_threshold = 3.0});
  EXPECT_EQ(flagged.pairs_used, 10);
  for (int i = 0; i < 10; ++i) EXPECT_EQ(flagged.is_outlier[i], i == 6) << i;

  const TransformFit dropped = FitTransform(pairs, model, {.outlier_threshold = 3.0, .drop_outliers = true});
  EXPECT_EQ(dropped.pairs_used, 9);
  EXPECT_FALSE(dropped.used[6]);
  EXPECT_NEAR(dropped.residuals_mm[6].y(), 2.0, 0.05);
  EXPECT_LT(*dropped.sigma_mm, 0.01);
  for (Eigen::Index k = 0; k < 3; ++k) EXPECT_NEAR(dropped.parameters(k), theta(k), 0.05);
}

TEST(FitTransform, NearlyCollinearExactDataStillGiveTheExactTransform) {
  // Points within 4 um of a 600 mm line: the roll about the line is still determined.
  std::vector<Eigen::Vector3d> source;
  for (int i = 0; i < 6; ++i)
    source.emplace_back(-300.0 + 120.0 * i, 0.004 * ((i * 7) % 3 - 1), 0.004 * ((i * 5) % 4 - 1.5));
  const TransformModel model = TransformModel::kRigid3d;
  const Eigen::VectorXd theta = TrueParameters(model);
  const TransformFit fit = FitTransform(MakePairs(model, source, Predict(model, theta, source)), model);
  ExpectParametersNear(fit, theta, 1e-7);
  EXPECT_LT(fit.geometry_ratio, 1e-4);
}

TEST(FitTransform, ReflectedTargetsStillGiveAProperRotation) {
  std::mt19937 rng(7005);
  auto source = RandomSource(6, 3, rng);
  std::vector<PointPair> pairs(source.size());
  for (size_t i = 0; i < source.size(); ++i)
    pairs[i] = {source[i], Eigen::Vector3d(source[i].x(), source[i].y(), -source[i].z())};
  const TransformFit fit = FitTransform(pairs, TransformModel::kRigid3d);
  EXPECT_NEAR(fit.transform.linear.determinant(), 1.0, 1e-12);
  EXPECT_GT(fit.rms_residual_mm, 1.0);
}

TEST(FitTransform, RefusesTooFewPairsDegenerateGeometryAndNonFiniteInput) {
  const auto expect_bad = [](const std::vector<PointPair>& pairs, TransformModel model,
                             const std::string& words) {
    try {
      (void)FitTransform(pairs, model);
      ADD_FAILURE() << "accepted " << words;
    } catch (const Error& error) {
      EXPECT_EQ(error.code(), ErrorCode::kBadInput);
      EXPECT_NE(std::string(error.what()).find(words), std::string::npos) << error.what();
    }
  };
  const PointPair a{{0, 0, 0}, {1, 1, 1}}, b{{10, 0, 0}, {11, 1, 1}}, c{{20, 0, 0}, {21, 1, 1}},
      d{{0, 10, 0}, {1, 11, 1}};
  expect_bad({a, b}, TransformModel::kRigid3d, "at least 3");
  expect_bad({a, b, c}, TransformModel::kRigid3d, "collinear");
  expect_bad({a, b, c}, TransformModel::kSimilarity3d, "collinear");
  expect_bad({a, b, c}, TransformModel::kAffine2d, "collinear");
  expect_bad({a, a, a}, TransformModel::kRigid2d, "coincident");
  PointPair nan_pair = d;
  nan_pair.target_mm.y() = std::nan("");
  expect_bad({a, b, nan_pair}, TransformModel::kRigid2d, "non-finite");
  EXPECT_NO_THROW((void)FitTransform(std::vector<PointPair>{a, b, c}, TransformModel::kRigid2d));
  EXPECT_THROW((void)ParseModel("helmert"), Error);
  EXPECT_THROW((void)FitTransform(std::vector<PointPair>{a, b, d}, TransformModel::kRigid3d,
                                  {.outlier_threshold = -1.0}),
               Error);
}

TEST(Transform, InverseUndoesTheTransformAndAnglesRoundTrip) {
  std::mt19937 rng(7006);
  std::uniform_real_distribution<double> angle(-1.5, 1.5);
  for (int trial = 0; trial < 50; ++trial) {
    const Eigen::Vector3d angles(angle(rng), angle(rng), angle(rng));
    const Eigen::Matrix3d r = RotZ(angles.z()) * RotY(angles.y()) * RotX(angles.x());
    EXPECT_TRUE(RotationFromAngles(angles).isApprox(r, 1e-14));
    EXPECT_TRUE(AnglesFromRotation(r).isApprox(angles, 1e-12));
    // Coordinate-frame angles describe R^T; for small angles they are the negated ones.
    EXPECT_TRUE(RotationFromAngles(CoordinateFrameAngles(r)).transpose().isApprox(r, 1e-12));
    const Transform t{TransformModel::kSimilarity3d, r, 1.3, Eigen::Vector3d(5, -2, 9)};
    const Eigen::Vector3d p(3, 4, -8);
    EXPECT_TRUE(t.Inverse().ApplyToPoint(t.ApplyToPoint(p)).isApprox(p, 1e-13));
  }
  const Eigen::Vector3d small(1e-5, -2e-5, 3e-5);
  EXPECT_TRUE(CoordinateFrameAngles(RotationFromAngles(small)).isApprox(-small, 1e-4));
}

}  // namespace
}  // namespace arcwheel::frames
