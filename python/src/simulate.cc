// arcwheel.simulate: a synthetic scan with known geometry (acquisition/simulate.h), the options of
// `arcwheel simulate` in snake_case, and its truth as a dict.

#include "acquisition/simulate.h"

#include <cstdio>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/atomic_file.h"
#include "python/src/bindings.h"

namespace arcwheel::python {
namespace {

struct SimulateOptions {
  acquisition::WheelModel wheel;
  acquisition::ScanSettings settings;
  bool true_rpm_given = false;
  bool float64 = false;
  int truth_phases = 360;
};

// A harmonic as `arcwheel simulate` spells it, "ORDER:AMPLITUDE[:PHASE_DEG]", or a tuple
// (order, amplitude[, phase_deg]).
acquisition::Harmonic ParseHarmonic(py::handle item, const char* option) {
  acquisition::Harmonic h;
  bool ok = true;
  if (py::isinstance<py::str>(item)) {
    const std::string spec = py::str(item);
    char extra = 0;
    const int read = std::sscanf(spec.c_str(), "%d:%lf:%lf%c", &h.order, &h.amplitude, &h.phase_deg, &extra);
    ok = read >= 2 && read <= 3;
  } else {
    const auto fields = item.cast<std::vector<double>>();
    ok = fields.size() == 2 || fields.size() == 3;
    if (ok) {
      h.order = static_cast<int>(fields[0]);
      ok = h.order == fields[0];
      h.amplitude = fields[1];
      if (fields.size() == 3) h.phase_deg = fields[2];
    }
  }
  if (!ok || h.order < 1) {
    throw Error(ErrorCode::kInvalidOption, "simulate",
                std::string(option) + " " + std::string(py::repr(item)) +
                    " is not ORDER:AMPLITUDE[:PHASE_DEG] (or a tuple of them) with ORDER >= 1");
  }
  return h;
}

template <typename Access>
OptionField<SimulateOptions> HarmonicsField(const char* name, Access access) {
  return {name,
          [access](const SimulateOptions& o) {
            py::list specs;
            for (const acquisition::Harmonic& h : access(const_cast<SimulateOptions&>(o))) {
              specs.append(py::make_tuple(h.order, h.amplitude, h.phase_deg));
            }
            return py::object(specs);
          },
          [access, name](SimulateOptions& o, py::handle value) {
            auto& harmonics = access(o);
            harmonics.clear();
            for (py::handle item : value) harmonics.push_back(ParseHarmonic(item, name));
          }};
}

using S = SimulateOptions;

const std::vector<OptionField<S>>& SimulateFields() {
  static const std::vector<OptionField<S>> fields = {
      Field<S>(
          "wheel_diameter_mm", [](S & o) -> auto& { return o.wheel.wheel_diameter_mm; }),
      Field<S>(
          "width_mm", [](S & o) -> auto& { return o.wheel.width_mm; }),
      Field<S>(
          "arc_radius_mm", [](S & o) -> auto& { return o.wheel.arc_radius_mm; }),
      Field<S>(
          "center_axial_mm", [](S & o) -> auto& { return o.wheel.center_axial_mm; }),
      HarmonicsField(
          "radius_harmonic", [](S & o) -> auto& { return o.wheel.arc_radius_harmonics_mm; }),
      HarmonicsField(
          "axial_harmonic", [](S & o) -> auto& { return o.wheel.center_axial_harmonics_mm; }),
      HarmonicsField(
          "radial_harmonic", [](S & o) -> auto& { return o.wheel.radial_harmonics_um; }),
      Field<S>(
          "profile_legendre_um", [](S & o) -> auto& { return o.wheel.profile_legendre_um; }),
      Field<S>(
          "grit_um", [](S & o) -> auto& { return o.wheel.grit_sigma_um; }),
      Field<S>(
          "grit_cell_mm", [](S & o) -> auto& { return o.wheel.grit_cell_mm; }),
      Field<S>(
          "rpm", [](S & o) -> auto& { return o.settings.spindle_rpm_nominal; }),
      {"true_rpm", [](const S&) { return py::object(py::none()); },
       [](S& o, py::handle value) {
         o.settings.spindle_rpm_true = value.cast<double>();
         o.true_rpm_given = true;
       }},
      Field<S>(
          "feed_mm_per_min", [](S & o) -> auto& { return o.settings.feed_mm_per_min; }),
      Field<S>(
          "sample_period_s", [](S & o) -> auto& { return o.settings.sample_period_s; }),
      Field<S>(
          "start_y_mm", [](S & o) -> auto& { return o.settings.start_y_mm; }),
      Field<S>(
          "end_y_mm", [](S & o) -> auto& { return o.settings.end_y_mm; }),
      Field<S>(
          "start_phase_deg", [](S & o) -> auto& { return o.settings.start_phase_deg; }),
      // 0 (the default) stands for the wheel radius - 0.5 mm, as on the command line.
      Field<S>(
          "sensor_zero_radius_mm", [](S & o) -> auto& { return o.settings.sensor_zero_radius_mm; }),
      Field<S>(
          "radius_sign", [](S & o) -> auto& { return o.settings.radius_sign; }),
      Field<S>(
          "beam_offset_mm", [](S & o) -> auto& { return o.settings.beam_offset_mm; }),
      Field<S>(
          "noise_um", [](S & o) -> auto& { return o.settings.noise_um; }),
      Field<S>(
          "spike_rate", [](S & o) -> auto& { return o.settings.spike_rate; }),
      Field<S>(
          "spike_um", [](S & o) -> auto& { return o.settings.spike_amplitude_um; }),
      Field<S>(
          "burst_rate", [](S & o) -> auto& { return o.settings.burst_rate; }),
      Field<S>(
          "burst_length_max", [](S & o) -> auto& { return o.settings.burst_length_max; }),
      Field<S>(
          "dropout_rate", [](S & o) -> auto& { return o.settings.dropout_rate; }),
      Field<S>(
          "dropout_length_max", [](S & o) -> auto& { return o.settings.dropout_length_max; }),
      Field<S>(
          "encoder", [](S & o) -> auto& { return o.settings.write_encoder; }),
      Field<S>(
          "time_column", [](S & o) -> auto& { return o.settings.write_time; }),
      Field<S>(
          "axial_column", [](S & o) -> auto& { return o.settings.write_axial; }),
      Field<S>(
          "float64", [](S & o) -> auto& { return o.float64; }),
      Field<S>(
          "seed", [](S & o) -> auto& { return o.settings.seed; }),
      Field<S>(
          "wheel_id", [](S & o) -> auto& { return o.settings.wheel_id; }),
      Field<S>(
          "timestamp", [](S & o) -> auto& { return o.settings.timestamp; }),
      Field<S>(
          "truth_phases", [](S & o) -> auto& { return o.truth_phases; }),
  };
  return fields;
}

// The CLI's defaults that depend on other options.
SimulateOptions Resolved(SimulateOptions o) {
  if (!o.true_rpm_given) o.settings.spindle_rpm_true = o.settings.spindle_rpm_nominal;
  if (o.settings.sensor_zero_radius_mm <= 0)
    o.settings.sensor_zero_radius_mm = o.wheel.wheel_diameter_mm / 2.0 - 0.5;
  o.settings.float32 = !o.float64;
  return o;
}

// The scan as it reads back from the file simulate writes: float32 readings unless float64.
acquisition::Scan AsWritten(acquisition::Scan scan, bool float32) {
  if (!float32 || scan.holds_float()) return scan;
  scan.z_float_mm = std::vector<float>(scan.z_mm.begin(), scan.z_mm.end());
  scan.z_mm.clear();
  scan.z_mm.shrink_to_fit();
  return scan;
}

py::tuple Simulate(const std::optional<std::filesystem::path>& output,
                   const std::optional<std::filesystem::path>& truth, const py::kwargs& kwargs) {
  SimulateOptions given;
  ApplyOptions(SimulateFields(), kwargs, given, "simulate");
  const SimulateOptions o = Resolved(given);
  if (truth && !output) throw Error(ErrorCode::kInvalidOption, "simulate", "truth needs output");
  auto [scan, truth_text] = RunReleased([&] {
    acquisition::SimulatedScan simulated = acquisition::SimulateScan(o.wheel, o.settings);
    std::string text = acquisition::TruthJson(o.wheel, o.settings, simulated.counts, o.truth_phases);
    if (output) {
      acquisition::WriteScan(simulated.scan, o.settings.float32, *output);
      WriteFileAtomically(truth ? *truth : std::filesystem::path(output->string() + ".truth.json"), text);
      simulated.scan.path = output->string();
    }
    return std::make_pair(AsWritten(std::move(simulated.scan), o.settings.float32), std::move(text));
  });
  return py::make_tuple(py::cast(std::move(scan)), ParseJson(truth_text));
}

}  // namespace

void BindSimulate(py::module_& module) {
  module.def("_simulate", &Simulate, py::arg("output") = py::none(), py::kw_only(),
             py::arg("truth") = py::none());
  module.attr("SIMULATE_OPTIONS") = Defaults(SimulateFields());
}

}  // namespace arcwheel::python
