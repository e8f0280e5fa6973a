// arcwheel.Scan and arcwheel.read_scan: a raw scan (acquisition/scan.h) with its arrays as numpy
// views of the C++ samples (no copy).

#include "acquisition/scan.h"

#include <filesystem>
#include <optional>
#include <string>
#include <utility>

#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"
#include "python/src/bindings.h"

namespace arcwheel::python {
namespace {

py::object OrNone(const std::optional<double>& value) { return value ? py::cast(*value) : py::none(); }

// The metadata under formats.md's key names (acquisition/scan_metadata_keys.h); absent values are
// None.
py::dict MetadataDict(const acquisition::ScanMetadata& m) {
  py::dict d;
  d["spindle_rpm"] = OrNone(m.spindle_rpm);
  d["feed_mm_per_min"] = OrNone(m.feed_mm_per_min);
  d["sample_period_s"] = OrNone(m.sample_period_s);
  d["radius_sign"] = m.radius_sign;
  d["start_y_mm"] = m.start_y_mm;
  d["start_phase_deg"] = m.start_phase_deg;
  d["invalid_value"] = OrNone(m.invalid_value);
  d["range_min_mm"] = OrNone(m.range_min_mm);
  d["range_max_mm"] = OrNone(m.range_max_mm);
  d["wheel_diameter_mm"] = OrNone(m.wheel_diameter_mm);
  d["wheel_width_mm"] = OrNone(m.wheel_width_mm);
  d["wheel_id"] = m.wheel_id;
  d["sensor"] = m.sensor;
  d["operator"] = m.operator_name;
  d["timestamp"] = m.timestamp;
  d["notes"] = m.notes;
  return d;
}

// A read-only numpy view of `values`, kept alive by the Python Scan `owner`; None when empty.
template <typename Values>
py::object View(const Values& values, const py::object& owner) {
  using T = std::remove_cvref_t<decltype(*values.data())>;
  if (values.empty()) return py::none();
  py::array_t<T> array({static_cast<py::ssize_t>(values.size())}, {static_cast<py::ssize_t>(sizeof(T))},
                       values.data(), owner);
  py::detail::array_proxy(array.ptr())->flags &= ~py::detail::npy_api::NPY_ARRAY_WRITEABLE_;
  return array;
}

}  // namespace

void BindScan(py::module_& module) {
  py::class_<acquisition::Scan>(module, "Scan",
                                "A raw helical scan (formats.md section 2): metadata and sample arrays. "
                                "The arrays are read-only views of the scan's memory.")
      .def_readonly("path", &acquisition::Scan::path,
                    "the file it was read from ('simulated' for a scan simulated and not written)")
      .def_property_readonly(
          "metadata", [](const acquisition::Scan& scan) { return MetadataDict(scan.metadata); },
          "settings and provenance under formats.md's key names; None where the file gives none")
      .def_property_readonly(
          "z_mm",
          [](const py::object& self) {
            const auto& scan = self.cast<const acquisition::Scan&>();
            return scan.holds_float() ? View(scan.z_float_mm, self) : View(scan.z_mm, self);
          },
          "the readings (mm), float32 when the file stores float32, else float64; NaN = invalid")
      .def_property_readonly(
          "time_s",
          [](const py::object& self) { return View(self.cast<const acquisition::Scan&>().t_s, self); },
          "sample times (s), float64; None when the file has no time column")
      .def_property_readonly(
          "angle_deg",
          [](const py::object& self) { return View(self.cast<const acquisition::Scan&>().angle_deg, self); },
          "encoder angle (deg), float64; None without an encoder")
      .def_property_readonly(
          "y_mm",
          [](const py::object& self) { return View(self.cast<const acquisition::Scan&>().y_mm, self); },
          "axial position (mm), float64; None without an axial column")
      .def_property_readonly("has_encoder", &acquisition::Scan::has_encoder)
      .def("valid_count", &acquisition::Scan::CountValid, "number of samples with a finite reading")
      .def("__len__", &acquisition::Scan::size)
      .def("__repr__", [](const acquisition::Scan& scan) {
        return "<arcwheel.Scan '" + scan.path + "': " + std::to_string(scan.size()) + " samples>";
      });

  module.def(
      "read_scan",
      [](const std::filesystem::path& path, bool keep_float32, const std::string& format,
         const std::string& columns, const std::string& scan_settings) {
        return RunReleased([&] {
          std::optional<acquisition::ScanSettingsFile> settings;
          if (!scan_settings.empty()) settings = acquisition::ReadScanSettings(scan_settings);
          acquisition::ReadOptions options;
          options.keep_float32 = keep_float32;
          options.settings = settings ? &*settings : nullptr;
          options.format = format;
          options.columns = columns;
          return acquisition::ReadScan(path, options);
        });
      },
      py::arg("path"), py::arg("keep_float32") = true, py::arg("format") = "", py::arg("columns") = "",
      py::arg("scan_settings") = "",
      "Reads a raw scan (.h5/.hdf5 or .csv/.txt, formats.md sections 2 and 2.4): the contract's layouts "
      "or a sensor's own file (format: sensortool, keyence-lk, columns; default: sniffed), with the "
      "column map `columns` ('z=NAME:UNIT,...') and the settings file `scan_settings` that supplies what "
      "the file lacks. float32 readings stay float32 unless keep_float32=False. Raises BadInputError, "
      "InvalidOptionError or IoError naming the file.");
}

}  // namespace arcwheel::python
