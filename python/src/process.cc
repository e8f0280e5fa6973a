// arcwheel.process: the `arcwheel process` pipeline (workflows/process_pipeline.h) with its results
// as a dict of numpy arrays, and optionally the files the command writes.

#include <cmath>
#include <filesystem>
#include <string>
#include <type_traits>
#include <utility>
#include <variant>
#include <vector>

#include "core/progress.h"
#include "fitting/outputs.h"
#include "python/src/bindings.h"
#include "reports/report.h"
#include "reports/tolerances.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"
#include "workflows/process_options.h"
#include "workflows/process_pipeline.h"

namespace arcwheel::python {
namespace {

using Options = workflows::ProcessPipelineOptions;
namespace h5 = schema::wheel_map;

// The options of `arcwheel process` that reach the computation (workflows/process_options.h), named
// as its flags in snake_case.
OptionField<Options> FieldOf(const workflows::ProcessOption& row) {
  const std::string flag(row.flag);
  return {workflows::KeywordOf(row.flag),
          [row](const Options& options) {
            return std::visit(
                [](const auto& value) -> py::object {
                  if constexpr (std::is_same_v<std::decay_t<decltype(value)>, workflows::ChoiceRef>) {
                    return py::str(std::string(workflows::NameOf(value)));
                  } else {
                    return py::cast(*value);
                  }
                },
                row.field(const_cast<Options&>(options)));
          },
          [row, flag](Options& options, py::handle given) {
            std::visit(
                [&](const auto& value) {
                  using T = std::decay_t<decltype(value)>;
                  if constexpr (std::is_same_v<T, workflows::ChoiceRef>) {
                    workflows::SetChoice(flag, value, given.cast<std::string>(), options);
                  } else {
                    *value = given.cast<std::remove_pointer_t<T>>();
                  }
                },
                row.field(options));
          }};
}

const std::vector<OptionField<Options>>& ProcessFields() {
  static const std::vector<OptionField<Options>> fields = [] {
    std::vector<OptionField<Options>> made;
    for (const workflows::ProcessOption& row : workflows::ProcessOptionTable()) {
      if (!row.flag.empty()) made.push_back(FieldOf(row));
    }
    return made;
  }();
  return fields;
}

// The name of a dataset inside its group: "/map/rho" -> "rho".
py::str Leaf(std::string_view dataset) { return std::string(dataset.substr(dataset.rfind('/') + 1)); }

py::dict MapArrays(processing::WheelMap& map, std::vector<double>&& form_error_um) {
  const auto n_phase = static_cast<py::ssize_t>(map.n_phase());
  const auto n_y = static_cast<py::ssize_t>(map.n_y());
  py::dict d;
  d[Leaf(h5::kMapPhaseDeg)] = ToNumpy(std::move(map.phase_deg));
  d[Leaf(h5::kMapYMm)] = ToNumpy(std::move(map.y_mm));
  d[Leaf(h5::kMapRhoMm)] = ToNumpy(std::move(map.rho_mm), {n_phase, n_y});
  d[Leaf(h5::kMapFormErrorUm)] = ToNumpy(std::move(form_error_um), {n_phase, n_y});
  d[Leaf(h5::kMapSampleCount)] = ToNumpy(std::move(map.sample_count), {n_phase, n_y});
  d[Leaf(h5::kMapDespikedCount)] = ToNumpy(std::move(map.despiked_count), {n_phase, n_y});
  return d;
}

// wheel_map.h5's /fit: NaN where a phase is not usable, as the file has it; plus the phase nodes,
// chi2_per_dof and the flags that summary.json carries.
py::dict FitArrays(const std::vector<double>& phase_deg, const fitting::WheelFit& fit) {
  const auto column = [&](auto member) {
    std::vector<double> values;
    for (const fitting::PhaseFit& p : fit.phases) values.push_back(p.usable ? p.*member : std::nan(""));
    return ToNumpy(std::move(values));
  };
  py::dict d;
  d["phase_deg"] = ToNumpy(phase_deg);
  d[Leaf(h5::kFitArcRadiusMm)] = column(&fitting::PhaseFit::arc_radius_mm);
  d[Leaf(h5::kFitArcRadiusSigmaMm)] = column(&fitting::PhaseFit::arc_radius_sigma_mm);
  d[Leaf(h5::kFitCenterAxialMm)] = column(&fitting::PhaseFit::center_axial_mm);
  d[Leaf(h5::kFitCenterAxialSigmaMm)] = column(&fitting::PhaseFit::center_axial_sigma_mm);
  d[Leaf(h5::kFitCenterRadialMm)] = column(&fitting::PhaseFit::center_radial_mm);
  d[Leaf(h5::kFitCenterRadialSigmaMm)] = column(&fitting::PhaseFit::center_radial_sigma_mm);
  d[Leaf(h5::kFitArcErrorUm)] = column(&fitting::PhaseFit::arc_error_um);
  d["chi2_per_dof"] = column(&fitting::PhaseFit::chi2_per_dof);
  std::vector<int> points;
  std::vector<std::string> flags;
  py::array_t<bool> usable(static_cast<py::ssize_t>(fit.phases.size()));
  for (std::size_t i = 0; i < fit.phases.size(); ++i) {
    points.push_back(fit.phases[i].points);
    flags.push_back(fit.phases[i].flag);
    usable.mutable_at(static_cast<py::ssize_t>(i)) = fit.phases[i].usable;
  }
  d[Leaf(h5::kFitPointsInBand)] = ToNumpy(std::move(points));
  d[Leaf(h5::kFitUsable)] = usable;
  d["flag"] = flags;
  return d;
}

py::dict AxialArrays(fitting::WheelFit& fit) {
  py::dict d;
  d[Leaf(h5::kAxialYMm)] = ToNumpy(std::move(fit.axial_y_mm));
  d[Leaf(h5::kAxialRunoutUm)] = ToNumpy(std::move(fit.runout_um));
  d[Leaf(h5::kAxialRoundnessUm)] = ToNumpy(std::move(fit.roundness_um));
  return d;
}

// wheel_map.h5's /model arrays, on the map's phase nodes.
py::dict ModelArrays(fitting::WheelModel& m, py::ssize_t n_phase, py::ssize_t n_y) {
  py::dict d;
  d["phase_deg"] = ToNumpy(std::move(m.phase_deg));
  d[Leaf(h5::kModelArcRadiusMm)] = ToNumpy(std::move(m.arc_radius_mm));
  d[Leaf(h5::kModelArcRadiusSigmaMm)] = ToNumpy(std::move(m.arc_radius_sigma_mm));
  d[Leaf(h5::kModelCenterAxialMm)] = ToNumpy(std::move(m.center_axial_mm));
  d[Leaf(h5::kModelCenterAxialSigmaMm)] = ToNumpy(std::move(m.center_axial_sigma_mm));
  d[Leaf(h5::kModelCenterRadialMm)] = ToNumpy(std::move(m.center_radial_mm));
  d[Leaf(h5::kModelCenterRadialSigmaMm)] = ToNumpy(std::move(m.center_radial_sigma_mm));
  d[Leaf(h5::kModelProfileUMm)] = ToNumpy(std::move(m.profile_u_mm));
  d[Leaf(h5::kModelProfileErrorUm)] = ToNumpy(std::move(m.profile_error_um));
  d[Leaf(h5::kModelProfileErrorSigmaUm)] = ToNumpy(std::move(m.profile_error_sigma_um));
  if (m.residual_um.size() == static_cast<std::size_t>(n_phase * n_y)) {
    d[Leaf(h5::kModelResidualUm)] = ToNumpy(std::move(m.residual_um), {n_phase, n_y});
  }
  const auto n = static_cast<py::ssize_t>(m.coefficients.size());
  d[Leaf(h5::kModelCoefficients)] = ToNumpy(std::move(m.coefficients));
  d[Leaf(h5::kModelCovariance)] = ToNumpy(std::move(m.covariance), {n, n});
  return d;
}

// The pieces arcwheel.Result is made of (arcwheel/__init__.py).
py::dict ResultDict(workflows::ProcessPipelineResult& r) {
  const fitting::WheelModel* model = r.model && r.model->fitted ? &*r.model : nullptr;
  py::dict d;
  d["summary"] = ParseJson(fitting::SummaryJson(r.record, r.processed, r.fit, model));
  const auto n_phase = static_cast<py::ssize_t>(r.processed.map.n_phase());
  const auto n_y = static_cast<py::ssize_t>(r.processed.map.n_y());
  d["fits"] = FitArrays(r.processed.map.phase_deg, r.fit);
  d["map"] = MapArrays(r.processed.map, std::move(r.fit.form_error_um));
  d["axial"] = AxialArrays(r.fit);
  d["model"] = model != nullptr ? py::object(ModelArrays(*r.model, n_phase, n_y)) : py::none();
  py::list timings;
  for (const StageClock::Stage& stage : r.clock.stages())
    timings.append(py::make_tuple(stage.name, stage.seconds));
  d["timings"] = timings;
  return d;
}

py::dict Process(const py::object& scan_or_path, const std::optional<std::filesystem::path>& output_dir,
                 bool report, const std::optional<std::filesystem::path>& tolerances,
                 const py::kwargs& kwargs) {
  Options options;
  ApplyOptions(ProcessFields(), kwargs, options, "process");
  if ((report || tolerances) && !output_dir) {
    throw Error(ErrorCode::kInvalidOption, "process", "report and tolerances need output_dir");
  }
  const std::filesystem::path outdir = output_dir.value_or(std::filesystem::path());
  // Read before the scan, as the command line does: summary.json then records the decisions.
  if (tolerances) options.tolerances = reports::ReadTolerances(*tolerances);
  workflows::ProcessPipelineResult result;
  if (py::isinstance<acquisition::Scan>(scan_or_path)) {
    // The pipeline works on the readings in place: it gets a copy, and the caller keeps the scan.
    acquisition::Scan scan = scan_or_path.cast<const acquisition::Scan&>();
    result = RunReleased([&] {
      Progress quiet(false);
      return workflows::RunProcessPipeline(std::move(scan), "", outdir, options, quiet);
    });
  } else {
    const std::string path = py::str(py::module_::import("os").attr("fspath")(scan_or_path));
    result = RunReleased([&] {
      Progress quiet(false);
      return workflows::RunProcessPipeline(path, outdir, options, quiet);
    });
  }
  if (report)
    RunReleased([&] {
      // The inspection report of `arcwheel process --report`, drawn from the files just written.
      (void)reports::WriteReports(outdir, options.tolerances.value_or(reports::Tolerances{}));
      return 0;
    });
  return ResultDict(result);
}

}  // namespace

void BindProcess(py::module_& module) {
  module.def("_process", &Process, py::arg("scan_or_path"), py::kw_only(), py::arg("output_dir") = py::none(),
             py::arg("report") = false, py::arg("tolerances") = py::none());
  module.attr("PROCESS_OPTIONS") = Defaults(ProcessFields());
}

}  // namespace arcwheel::python
