#pragma once
// JSON form of transforms and fits (formats.md section 5; the full key list is in docs/frames.md).
//
// A transform object holds at least
//   {"model", "rotation_matrix" (row-major 3x3; affine2d: "matrix", 2x2), "scale", "translation",
//    "convention": "target = scale * R * source + translation"}
// and every JSON file that arcwheel writes for a frame or a fit has these keys at the top level,
// so that any of them can be given to `arcwheel transform apply`.

#include <nlohmann/json_fwd.hpp>
#include <span>
#include <string>

#include "frames/transform.h"
#include "frames/transform_fit.h"

namespace arcwheel::frames {

inline constexpr const char* kConvention = "target = scale * R * source + translation";

// The transform keys above, plus "inverse" (the same keys for target -> source) and, for the 3D
// models, "rotation_angles" (order and both Helmert sign conventions, in degrees).
[[nodiscard]] nlohmann::json TransformToJson(const Transform& transform);

// TransformToJson plus the fit: parameters with sigmas and covariance, per-pair residuals
// ("residuals_mm": residual norms; "residual_vectors_mm"), outlier scores and flags, counts.
[[nodiscard]] nlohmann::json TransformFitToJson(const TransformFit& fit);

// Reads the transform keys from the top level of `json` (or from its "transform" object).
// Throws Error{kBadInput, "frames.transform_json"} naming `source` and the key for a missing or
// malformed key, a rotation that is not orthonormal with det +1 (within 1e-6), or a non-positive scale.
[[nodiscard]] Transform TransformFromJson(const nlohmann::json& json, const std::string& source);

}  // namespace arcwheel::frames
