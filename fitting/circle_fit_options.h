#pragma once
// The circle fit's options and outcome (fitting/circle_fit.h), apart from the fit and its Eigen
// types, for the headers that only carry the options.

#include <string>
#include <vector>

namespace arcwheel::fitting {

enum class FitStatus { kNotRun, kConverged, kNoConvergence, kDegenerate };

struct CircleFitOptions {
  int max_iterations = 100;  // Levenberg-Marquardt iterations, >= 1
  // Covariance scale: if true, the weights are 1/sigma_i and the covariance is (J^T W J)^-1
  // (known noise); if false it is scaled by the residual variance RSS/(n-3) (unknown noise).
  bool weights_are_inverse_sigmas = false;
  // Empty when valid, else one line per violation with its value: "max_iterations = 0 violates >= 1".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

}  // namespace arcwheel::fitting
