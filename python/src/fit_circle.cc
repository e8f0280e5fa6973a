// arcwheel.fit_circle: the geometric circle fit of fitting/circle_fit.h on an (N, 2) array.

#include <Eigen/Core>
#include <cmath>
#include <optional>
#include <string>
#include <vector>

#include "fitting/circle_fit.h"
#include "python/src/bindings.h"

namespace arcwheel::python {
namespace {

const char* StatusName(fitting::FitStatus status) {
  switch (status) {
    case fitting::FitStatus::kConverged:
      return "converged";
    case fitting::FitStatus::kNoConvergence:
      return "no_convergence";
    case fitting::FitStatus::kDegenerate:
      return "degenerate";
    case fitting::FitStatus::kNotRun:
      break;
  }
  return "not_run";
}

py::dict FitCircle(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& points,
    const std::optional<py::array_t<double, py::array::c_style | py::array::forcecast>>& weights,
    int max_iterations, bool weights_are_inverse_sigmas) {
  if (points.ndim() != 2 || points.shape(1) != 2) {
    throw Error(
        ErrorCode::kInvalidOption, "fitting.circle",
        "points must be an (N, 2) array, got shape " + std::string(py::str(py::tuple(points.attr("shape")))));
  }
  const auto n = static_cast<std::size_t>(points.shape(0));
  std::vector<double> x(n), y(n), w;
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = points.at(static_cast<py::ssize_t>(i), 0);
    y[i] = points.at(static_cast<py::ssize_t>(i), 1);
  }
  if (weights) {
    if (weights->ndim() != 1 || static_cast<std::size_t>(weights->shape(0)) != n) {
      throw Error(ErrorCode::kInvalidOption, "fitting.circle",
                  "weights must be an (N,) array, one per point");
    }
    w.assign(weights->data(), weights->data() + n);
  }
  const fitting::CircleFitOptions options{.max_iterations = max_iterations,
                                          .weights_are_inverse_sigmas = weights_are_inverse_sigmas};
  const fitting::CircleFit fit = RunReleased([&] { return fitting::FitCircle(x, y, w, options); });
  py::dict d;
  d["center_mm"] = ToNumpy(std::vector<double>{fit.center_mm.x(), fit.center_mm.y()});
  d["radius_mm"] = fit.radius_mm;
  d["center_sigma_mm"] =
      ToNumpy(std::vector<double>{std::sqrt(fit.covariance(0, 0)), std::sqrt(fit.covariance(1, 1))});
  d["radius_sigma_mm"] = fit.radius_sigma_mm();
  d["covariance"] = ToNumpy(std::vector<double>(fit.covariance.data(), fit.covariance.data() + 9), {3, 3});
  d["rms_residual_mm"] = fit.rms_residual_mm;
  d["pv_residual_mm"] = fit.pv_residual_mm;
  d["chi2"] = fit.chi2;
  d["n"] = fit.n;
  d["iterations"] = fit.iterations;
  d["status"] = StatusName(fit.status);
  d["message"] = fit.message;
  return d;
}

}  // namespace

void BindFitCircle(py::module_& module) {
  module.def("_fit_circle", &FitCircle, py::arg("points"), py::arg("weights") = py::none(),
             py::arg("max_iterations") = 100, py::arg("weights_are_inverse_sigmas") = false);
}

}  // namespace arcwheel::python
