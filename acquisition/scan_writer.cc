// Writers for the raw scan layouts (formats.md section 2) and the simulator's truth file.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "acquisition/scan_format.h"
#include "acquisition/simulate.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"

namespace arcwheel::acquisition {
namespace {

void WriteOptional(hdf5::File& file, const char* name, const std::optional<double>& value) {
  if (value) file.WriteAttribute("/scan", name, *value);
}

nlohmann::json HarmonicsJson(const std::vector<Harmonic>& harmonics) {
  nlohmann::json list = nlohmann::json::array();
  for (const Harmonic& h : harmonics)
    list.push_back({{"order", h.order}, {"amplitude", h.amplitude}, {"phase_deg", h.phase_deg}});
  return list;
}

}  // namespace

void WriteHdf5Scan(const Scan& scan, bool float32, const std::string& path) {
  OutputSet outputs;
  const auto temporary = outputs.Stage(path);
  {
    hdf5::File file = hdf5::File::Create(temporary);
    file.CreateGroup("/scan");
    const std::vector<hsize_t> shape = {scan.z_mm.size()};
    if (float32) {
      // Store z as float32, the layout of real sensors; NaN survives the narrowing.
      file.WriteFloats("/scan/z", std::vector<float>(scan.z_mm.begin(), scan.z_mm.end()), shape);
    } else {
      file.WriteDoubles("/scan/z", scan.z_mm, shape);
    }
    if (scan.has_time()) file.WriteDoubles("/scan/t", scan.t_s, shape);
    if (scan.has_encoder()) file.WriteDoubles("/scan/angle", scan.angle_deg, shape);
    if (scan.has_axial()) file.WriteDoubles("/scan/y", scan.y_mm, shape);
    const ScanMetadata& m = scan.metadata;
    WriteOptional(file, "spindle_rpm", m.spindle_rpm);
    WriteOptional(file, "feed_mm_per_min", m.feed_mm_per_min);
    WriteOptional(file, "sample_period_s", m.sample_period_s);
    file.WriteAttribute("/scan", "radius_sign", m.radius_sign);
    file.WriteAttribute("/scan", "start_y_mm", m.start_y_mm);
    file.WriteAttribute("/scan", "start_phase_deg", m.start_phase_deg);
    WriteOptional(file, "invalid_value", m.invalid_value);
    WriteOptional(file, "range_min_mm", m.range_min_mm);
    WriteOptional(file, "range_max_mm", m.range_max_mm);
    WriteOptional(file, "wheel_diameter_mm", m.wheel_diameter_mm);
    WriteOptional(file, "wheel_width_mm", m.wheel_width_mm);
    if (!m.wheel_id.empty()) file.WriteAttribute("/scan", "wheel_id", m.wheel_id);
    if (!m.sensor.empty()) file.WriteAttribute("/scan", "sensor", m.sensor);
    if (!m.operator_name.empty()) file.WriteAttribute("/scan", "operator", m.operator_name);
    if (!m.timestamp.empty()) file.WriteAttribute("/scan", "timestamp", m.timestamp);
  }
  outputs.Commit();
}

void WriteCsvScan(const Scan& scan, const std::string& path) {
  OutputSet outputs;
  const auto temporary = outputs.Stage(path);
  FILE* out = std::fopen(temporary.c_str(), "w");
  if (out == nullptr)
    throw Error(ErrorCode::kIo, "acquisition.csv", "cannot create '" + temporary.string() + "'");
  const ScanMetadata& m = scan.metadata;
  const auto number = [&](const char* key, const std::optional<double>& value) {
    if (value) std::fprintf(out, "# %s: %.17g\n", key, *value);
  };
  number("spindle_rpm", m.spindle_rpm);
  number("feed_mm_per_min", m.feed_mm_per_min);
  number("sample_period_s", m.sample_period_s);
  number("radius_sign", m.radius_sign);
  number("start_y_mm", m.start_y_mm);
  number("start_phase_deg", m.start_phase_deg);
  number("wheel_diameter_mm", m.wheel_diameter_mm);
  number("wheel_width_mm", m.wheel_width_mm);
  if (!m.wheel_id.empty()) std::fprintf(out, "# wheel_id: %s\n", m.wheel_id.c_str());
  if (!m.sensor.empty()) std::fprintf(out, "# sensor: %s\n", m.sensor.c_str());
  if (!m.timestamp.empty()) std::fprintf(out, "# timestamp: %s\n", m.timestamp.c_str());
  std::fprintf(out, "z_mm%s%s%s\n", scan.has_time() ? ",t_s" : "", scan.has_encoder() ? ",angle_deg" : "",
               scan.has_axial() ? ",y_mm" : "");
  // Off the rim (before the first valid sample or after the last) the sensor alarms; a dropout
  // inside the scan is an empty reading.
  std::size_t first_valid = scan.size();
  std::size_t last_valid = 0;
  for (std::size_t i = 0; i < scan.size(); ++i) {
    if (std::isfinite(scan.z_mm[i])) {
      first_valid = std::min(first_valid, i);
      last_valid = i;
    }
  }
  for (std::size_t i = 0; i < scan.size(); ++i) {
    const double z = scan.z_mm[i];
    if (std::isfinite(z))
      std::fprintf(out, "%.9f", z);
    else
      std::fputs(i < first_valid || i > last_valid ? "-FFFFFFF" : "nan", out);
    if (scan.has_time()) std::fprintf(out, ",%.12g", scan.t_s[i]);
    if (scan.has_encoder()) std::fprintf(out, ",%.12f", scan.angle_deg[i]);
    if (scan.has_axial()) std::fprintf(out, ",%.12f", scan.y_mm[i]);
    std::fputc('\n', out);
  }
  const bool failed = std::ferror(out) != 0;
  if (std::fclose(out) != 0 || failed) {
    throw Error(ErrorCode::kIo, "acquisition.csv", "cannot write '" + path + "' (disk full?)");
  }
  outputs.Commit();
}

void WriteScan(const Scan& scan, bool float32, const std::filesystem::path& path) {
  const std::optional<ScanFormat> format = ScanFormatOfName(path);
  if (!format) {
    throw Error(ErrorCode::kInvalidOption, "acquisition",
                "output '" + path.string() + "' must end in " + ScanExtensionsText());
  }
  switch (*format) {
    case ScanFormat::kHdf5:
      return WriteHdf5Scan(scan, float32, path.string());
    case ScanFormat::kCsv:
      return WriteCsvScan(scan, path.string());
    default:
      break;  // the sensors' layouts are written by WriteSensorScan
  }
}

std::string TruthJson(const WheelModel& wheel, const ScanSettings& s, const SimulationCounts& counts,
                      int phases) {
  nlohmann::json truth;
  truth["model"] = {{"wheel_diameter_mm", wheel.wheel_diameter_mm},
                    {"width_mm", wheel.width_mm},
                    {"arc_radius_mm", wheel.arc_radius_mm},
                    {"center_axial_mm", wheel.center_axial_mm},
                    {"arc_radius_harmonics_mm", HarmonicsJson(wheel.arc_radius_harmonics_mm)},
                    {"center_axial_harmonics_mm", HarmonicsJson(wheel.center_axial_harmonics_mm)},
                    {"radial_harmonics_um", HarmonicsJson(wheel.radial_harmonics_um)},
                    {"profile_legendre_um", wheel.profile_legendre_um},
                    {"profile_wave_um", wheel.profile_wave_um},
                    {"profile_wave_period_mm", wheel.profile_wave_period_mm},
                    {"edge_drop_um", wheel.edge_drop_um},
                    {"edge_length_mm", wheel.edge_length_mm},
                    {"grit_sigma_um", wheel.grit_sigma_um},
                    {"grit_cell_mm", wheel.grit_cell_mm}};
  truth["settings"] = {{"spindle_rpm_nominal", s.spindle_rpm_nominal},
                       {"spindle_rpm_true", s.spindle_rpm_true},
                       {"feed_mm_per_min", s.feed_mm_per_min},
                       {"sample_period_s", s.sample_period_s},
                       {"start_y_mm", s.start_y_mm},
                       {"end_y_mm", s.end_y_mm},
                       {"start_phase_deg", s.start_phase_deg},
                       {"sensor_zero_radius_mm", s.sensor_zero_radius_mm},
                       {"radius_sign", s.radius_sign},
                       {"beam_offset_mm", s.beam_offset_mm},
                       {"noise_um", s.noise_um},
                       {"spike_rate", s.spike_rate},
                       {"spike_amplitude_um", s.spike_amplitude_um},
                       {"burst_rate", s.burst_rate},
                       {"burst_length_max", s.burst_length_max},
                       {"dropout_rate", s.dropout_rate},
                       {"dropout_length_max", s.dropout_length_max},
                       {"encoder", s.write_encoder},
                       {"seed", s.seed}};
  truth["counts"] = {{"samples", counts.samples},
                     {"off_rim", counts.off_rim},
                     {"dropouts", counts.dropouts},
                     {"spikes", counts.spikes}};
  nlohmann::json per_phase;
  for (int k = 0; k < phases; ++k) {
    const double c = 360.0 * k / phases;
    per_phase["phase_deg"].push_back(c);
    per_phase["arc_radius_mm"].push_back(wheel.ArcRadiusMm(c));
    per_phase["center_axial_mm"].push_back(wheel.CenterAxialMm(c));
    per_phase["center_radial_mm"].push_back(wheel.CenterDistanceMm(c) - s.sensor_zero_radius_mm);
  }
  truth["phases"] = per_phase;
  truth["note"] =
      "Per-phase values are the generating circle of each section (without the profile error, grit "
      "and beam offset); the sensor frame's radial coordinate is rho = R - sensor_zero_radius_mm.";
  return JsonText(truth, 2) + "\n";
}

}  // namespace arcwheel::acquisition
