// arcwheel.frame, fit_transform and headcenter: the library calls of the `frame`, `transform fit`
// and `headcenter solve` commands (frames/three_point_frame.h, frames/transform_fit.h,
// workflows/headcenter.h), with their results as dicts and numpy arrays.

#include <Eigen/Core>
#include <optional>
#include <string>
#include <vector>

#include "frames/three_point_frame.h"
#include "frames/transform_fit.h"
#include "frames/transform_json.h"
#include "python/src/bindings.h"
#include "workflows/headcenter.h"

namespace arcwheel::python {
namespace {

// An (N, 3) array of points, mm; (N, 2) gets z = 0.
std::vector<Eigen::Vector3d> Points(
    const py::array_t<double, py::array::c_style | py::array::forcecast>& array, const char* stage,
    const char* name) {
  if (array.ndim() != 2 || (array.shape(1) != 2 && array.shape(1) != 3)) {
    throw Error(ErrorCode::kInvalidOption, stage,
                std::string(name) + " must be an (N, 2) or (N, 3) array of points");
  }
  std::vector<Eigen::Vector3d> points;
  const auto view = array.unchecked<2>();
  for (py::ssize_t i = 0; i < view.shape(0); ++i) {
    points.emplace_back(view(i, 0), view(i, 1), view.shape(1) == 3 ? view(i, 2) : 0.0);
  }
  return points;
}

Eigen::Vector3d Point(const std::vector<double>& p, const char* name) {
  if (p.size() != 3)
    throw Error(ErrorCode::kInvalidOption, "frames.three_point", std::string(name) + " needs x, y, z");
  return {p[0], p[1], p[2]};
}

// The 4 x 4 homogeneous matrix of scale * linear * p + translation.
py::array_t<double> Matrix(const frames::Transform& t) {
  std::vector<double> m(16, 0.0);
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[static_cast<size_t>(4 * r + c)] = t.scale * t.linear(r, c);
    m[static_cast<size_t>(4 * r + 3)] = t.translation_mm[r];
  }
  m[15] = 1.0;
  return ToNumpy(std::move(m), {4, 4});
}

py::array_t<double> Vector(const Eigen::VectorXd& v) {
  return ToNumpy(std::vector<double>(v.data(), v.data() + v.size()));
}

py::dict Frame(const std::vector<double>& p1, const std::vector<double>& p2, const std::vector<double>& p3,
               double min_separation_mm, double min_angle_deg) {
  const frames::ThreePointFrameOptions options{.min_separation_mm = min_separation_mm,
                                               .min_angle_deg = min_angle_deg};
  ThrowIfProblems(ErrorCode::kInvalidOption, "frame", options.Problems());
  const frames::WorkpieceFrame frame =
      frames::ThreePointFrame(Point(p1, "p1"), Point(p2, "p2"), Point(p3, "p3"), options);
  py::dict d;
  d["origin_mm"] = Vector(frame.origin_mm);
  std::vector<double> axes;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) axes.push_back(frame.axes(r, c));
  d["axes"] = ToNumpy(std::move(axes), {3, 3});
  d["angle_p2_p3_deg"] = frame.angle_p2_p3_deg;
  d["machine_from_workpiece"] = Matrix(frame.MachineFromWorkpiece());
  d["workpiece_from_machine"] = Matrix(frame.WorkpieceFromMachine());
  d["transform"] = ParseJson(frames::TransformToJson(frame.MachineFromWorkpiece()).dump());
  return d;
}

py::dict FitTransform(const py::array_t<double, py::array::c_style | py::array::forcecast>& source,
                      const py::array_t<double, py::array::c_style | py::array::forcecast>& target,
                      const std::string& model, double outlier_threshold, bool drop_outliers) {
  const std::vector<Eigen::Vector3d> from = Points(source, "frames.transform_fit", "source");
  const std::vector<Eigen::Vector3d> to = Points(target, "frames.transform_fit", "target");
  if (from.size() != to.size()) {
    throw Error(ErrorCode::kInvalidOption, "frames.transform_fit",
                "source and target differ in their number of points");
  }
  std::vector<frames::PointPair> pairs;
  for (size_t i = 0; i < from.size(); ++i) pairs.push_back({from[i], to[i]});
  frames::TransformFitOptions options;
  options.outlier_threshold = outlier_threshold;
  options.drop_outliers = drop_outliers;
  ThrowIfProblems(ErrorCode::kInvalidOption, "frames.transform_fit", options.Problems());
  const frames::TransformFit fit =
      RunReleased([&] { return frames::FitTransform(pairs, frames::ParseModel(model), options); });
  py::dict d;
  d["fit"] = ParseJson(frames::TransformFitToJson(fit).dump());
  d["matrix"] = Matrix(fit.transform);
  d["parameters"] = Vector(fit.parameters);
  std::vector<double> residuals;
  for (const Eigen::Vector3d& r : fit.residuals_mm) residuals.insert(residuals.end(), {r.x(), r.y(), r.z()});
  d["residuals_mm"] = ToNumpy(std::move(residuals), {static_cast<py::ssize_t>(fit.residuals_mm.size()), 3});
  d["rms_residual_mm"] = fit.rms_residual_mm;
  return d;
}

py::dict Headcenter(const std::string& record, const std::string& calibration,
                    const std::optional<std::vector<double>>& commanded_mm,
                    const std::optional<double>& z0_mm, const std::string& tare, double min_force_fraction,
                    double min_force_N) {
  workflows::RecordSolveOptions options;
  options.z0_mm = z0_mm;
  options.tare = tare;
  options.min_force_fraction = min_force_fraction;
  options.min_force_N = min_force_N;
  std::optional<Eigen::Vector2d> commanded;
  if (commanded_mm) {
    if (commanded_mm->size() != 2)
      throw Error(ErrorCode::kInvalidOption, "headcenter", "commanded_mm needs x, y");
    commanded = Eigen::Vector2d((*commanded_mm)[0], (*commanded_mm)[1]);
  }
  const workflows::HeadcenterSolve solve =
      RunReleased([&] { return workflows::SolveHeadcenterRecord(record, calibration, commanded, options); });
  py::dict d;
  d["result"] = ParseJson(solve.json.dump());
  d["centre_mm"] = Vector(solve.centre.centre_mm);
  d["centre_sigma_mm"] = Vector(solve.centre.SigmaMm());
  d["centre_machine_mm"] =
      solve.centre_machine_mm ? py::object(Vector(*solve.centre_machine_mm)) : py::none();
  d["offset_mm"] = solve.offset_mm ? py::object(Vector(*solve.offset_mm)) : py::none();
  return d;
}

}  // namespace

void BindFrames(py::module_& module) {
  const frames::ThreePointFrameOptions frame_defaults;
  module.def("_frame", &Frame, py::arg("p1"), py::arg("p2"), py::arg("p3"),
             py::arg("min_separation_mm") = frame_defaults.min_separation_mm,
             py::arg("min_angle_deg") = frame_defaults.min_angle_deg);
  const frames::TransformFitOptions fit_defaults;
  module.def("_fit_transform", &FitTransform, py::arg("source"), py::arg("target"),
             py::arg("model") = "rigid3d", py::arg("outlier_threshold") = fit_defaults.outlier_threshold,
             py::arg("drop_outliers") = fit_defaults.drop_outliers);
  const workflows::RecordSolveOptions solve_defaults;
  module.def("_headcenter", &Headcenter, py::arg("record"), py::arg("calibration") = "",
             py::arg("commanded_mm") = py::none(), py::arg("z0_mm") = py::none(), py::arg("tare") = "",
             py::arg("min_force_fraction") = solve_defaults.min_force_fraction,
             py::arg("min_force_N") = solve_defaults.min_force_N);
}

}  // namespace arcwheel::python
