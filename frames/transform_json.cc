#include "frames/transform_json.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>

#include "core/error.h"

namespace arcwheel::frames {
namespace {

constexpr const char* kTransformJsonStage = "frames.transform_json";
constexpr double kDegPerRad = 180.0 / std::numbers::pi;

nlohmann::json Vector(const Eigen::VectorXd& v) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index i = 0; i < v.size(); ++i) out.push_back(v(i));
  return out;
}

nlohmann::json Matrix(const Eigen::MatrixXd& m) {
  nlohmann::json out = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) out.push_back(Vector(m.row(r).transpose()));
  return out;
}

nlohmann::json TransformKeys(const Transform& t) {
  nlohmann::json out;
  out["model"] = std::string(ModelName(t.model));
  const int d = ModelDimension(t.model);
  if (t.model == TransformModel::kAffine2d) {
    out["matrix"] = Matrix(t.linear.topLeftCorner(2, 2));
  } else {
    out["rotation_matrix"] = Matrix(t.linear.topLeftCorner(d, d));
    out["scale"] = t.scale;
  }
  out["translation"] = Vector(t.translation_mm.head(d));
  out["convention"] = kConvention;
  out["units"] = {{"translation", "mm"}, {"angles", "deg"}};
  if (d == 3) {
    const Eigen::Vector3d position_vector = AnglesFromRotation(t.linear) * kDegPerRad;
    const Eigen::Vector3d coordinate_frame = CoordinateFrameAngles(t.linear) * kDegPerRad;
    out["rotation_angles"] = {
        {"order", "R = Rz(rz) * Ry(ry) * Rx(rx), fixed axes, counter-clockwise positive"},
        {"position_vector_deg", Vector(position_vector)},
        {"coordinate_frame_deg", Vector(coordinate_frame)},
        {"coordinate_frame_note",
         "angles of R^T: the frame rotation; for small angles the negated position-vector angles"},
    };
  } else if (t.model == TransformModel::kRigid2d) {
    out["rotation_deg"] = std::atan2(t.linear(1, 0), t.linear(0, 0)) * kDegPerRad;
  }
  if (t.model == TransformModel::kSimilarity3d) out["scale_ppm"] = (t.scale - 1.0) * 1e6;
  return out;
}

[[noreturn]] void Malformed(const std::string& source, const std::string& key, const std::string& detail) {
  throw Error(ErrorCode::kBadInput, kTransformJsonStage,
              fmt::format("'{}': key '{}' {}", source, key, detail));
}

double Number(const nlohmann::json& value, const std::string& source, const std::string& key) {
  if (!value.is_number() || !std::isfinite(value.get<double>()))
    Malformed(source, key, "must hold finite numbers");
  return value.get<double>();
}

Eigen::MatrixXd ReadMatrix(const nlohmann::json& json, const std::string& key, int size,
                           const std::string& source) {
  if (!json.contains(key)) Malformed(source, key, "is missing");
  const nlohmann::json& rows = json.at(key);
  if (!rows.is_array() || static_cast<int>(rows.size()) != size)
    Malformed(source, key, fmt::format("must be {} rows", size));
  Eigen::MatrixXd m(size, size);
  for (int r = 0; r < size; ++r) {
    if (!rows[r].is_array() || static_cast<int>(rows[r].size()) != size) {
      Malformed(source, key, fmt::format("must be {} x {}", size, size));
    }
    for (int c = 0; c < size; ++c) m(r, c) = Number(rows[r][c], source, key);
  }
  return m;
}

}  // namespace

nlohmann::json TransformToJson(const Transform& transform) {
  nlohmann::json out = TransformKeys(transform);
  out["inverse"] = TransformKeys(transform.Inverse());
  return out;
}

nlohmann::json TransformFitToJson(const TransformFit& fit) {
  nlohmann::json out = TransformToJson(fit.transform);
  const int d = ModelDimension(fit.transform.model);
  out["n"] = fit.residuals_mm.size();
  out["pairs_used"] = fit.pairs_used;
  out["degrees_of_freedom"] = fit.degrees_of_freedom;
  out["rms_residual_mm"] = fit.rms_residual_mm;
  out["max_residual_mm"] = fit.max_residual_mm;
  out["sigma_mm"] = fit.sigma_mm ? nlohmann::json(*fit.sigma_mm) : nlohmann::json(nullptr);
  out["geometry_ratio"] = fit.geometry_ratio;
  nlohmann::json norms = nlohmann::json::array(), vectors = nlohmann::json::array();
  nlohmann::json scores = nlohmann::json::array(), flags = nlohmann::json::array(),
                 used = nlohmann::json::array();
  for (size_t i = 0; i < fit.residuals_mm.size(); ++i) {
    norms.push_back(fit.residuals_mm[i].head(d).norm());
    vectors.push_back(Vector(fit.residuals_mm[i].head(d)));
    scores.push_back(std::isfinite(fit.outlier_score[i]) ? nlohmann::json(fit.outlier_score[i])
                                                         : nlohmann::json(nullptr));
    flags.push_back(static_cast<bool>(fit.is_outlier[i]));
    used.push_back(static_cast<bool>(fit.used[i]));
  }
  out["residuals_mm"] = norms;
  out["residual_vectors_mm"] = vectors;
  out["outlier_score"] = scores;
  out["outlier"] = flags;
  out["used"] = used;
  nlohmann::json parameters, sigmas;
  for (size_t k = 0; k < fit.parameter_names.size(); ++k) {
    const auto index = static_cast<Eigen::Index>(k);
    parameters[fit.parameter_names[k]] = fit.parameters(index);
    sigmas[fit.parameter_names[k]] =
        fit.covariance ? nlohmann::json(std::sqrt((*fit.covariance)(index, index))) : nlohmann::json(nullptr);
  }
  out["parameters"] = parameters;
  out["parameter_sigmas"] = sigmas;
  out["parameter_order"] = fit.parameter_names;
  out["covariance"] = fit.covariance ? Matrix(*fit.covariance) : nlohmann::json(nullptr);
  return out;
}

Transform TransformFromJson(const nlohmann::json& json, const std::string& source) {
  if (!json.is_object())
    throw Error(ErrorCode::kBadInput, kTransformJsonStage, fmt::format("'{}' is not a JSON object", source));
  const nlohmann::json& root =
      json.contains("transform") && !json.contains("model") ? json.at("transform") : json;
  if (!root.contains("model") || !root.at("model").is_string()) Malformed(source, "model", "is missing");
  Transform t;
  try {
    t.model = ParseModel(root.at("model").get<std::string>());
  } catch (const Error& error) {
    Malformed(source, "model", error.what());
  }
  const int d = ModelDimension(t.model);
  if (t.model == TransformModel::kAffine2d) {
    t.linear.topLeftCorner(2, 2) = ReadMatrix(root, "matrix", 2, source);
    if (std::abs(t.linear.determinant()) < 1e-12) Malformed(source, "matrix", "is singular");
  } else {
    const Eigen::MatrixXd r = ReadMatrix(root, "rotation_matrix", d, source);
    t.linear.topLeftCorner(r.rows(), r.cols()) = r;
    const double orthogonality =
        (t.linear.transpose() * t.linear - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
    if (orthogonality > 1e-6 || t.linear.determinant() < 0.0) {
      Malformed(source, "rotation_matrix",
                fmt::format("is not a rotation (|R^T R - I| = {:.3g}, det {:.6g})", orthogonality,
                            t.linear.determinant()));
    }
    t.scale = root.contains("scale") ? Number(root.at("scale"), source, "scale") : 1.0;
    if (!(t.scale > 0.0)) Malformed(source, "scale", "must be positive");
  }
  if (!root.contains("translation") || !root.at("translation").is_array())
    Malformed(source, "translation", "is missing");
  const nlohmann::json& translation = root.at("translation");
  if (translation.size() != static_cast<size_t>(d)) {
    Malformed(source, "translation", fmt::format("must hold {} numbers for {}", d, ModelName(t.model)));
  }
  for (int k = 0; k < d; ++k) t.translation_mm(k) = Number(translation[k], source, "translation");
  return t;
}

}  // namespace arcwheel::frames
