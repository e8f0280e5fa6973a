#include "fitting/outputs.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/version.h"

namespace arcwheel::fitting {
namespace {

using nlohmann::json;

// JSON has no NaN: a number that could not be computed is null.
json Number(double value) { return std::isfinite(value) ? json(value) : json(nullptr); }

json Numbers(const std::vector<double>& values) {
  json list = json::array();
  for (const double v : values) list.push_back(Number(v));
  return list;
}

json Optional(const std::optional<double>& value) { return value ? json(*value) : json(nullptr); }

std::string PhaseSourceName(processing::PhaseSource source) {
  switch (source) {
    case processing::PhaseSource::kNominal:
      return "nominal";
    case processing::PhaseSource::kEstimated:
      return "estimated";
    case processing::PhaseSource::kEncoder:
      return "encoder";
  }
  return "nominal";
}

json PhasesJson(const processing::WheelMap& map, const WheelFit& fit) {
  json phases;
  phases["phase_deg"] = map.phase_deg;
  const auto column = [&](auto member) {
    json list = json::array();
    for (const PhaseFit& p : fit.phases) list.push_back(p.usable ? Number(p.*member) : json(nullptr));
    return list;
  };
  phases["arc_radius_mm"] = column(&PhaseFit::arc_radius_mm);
  phases["arc_radius_sigma_mm"] = column(&PhaseFit::arc_radius_sigma_mm);
  phases["center_axial_mm"] = column(&PhaseFit::center_axial_mm);
  phases["center_axial_sigma_mm"] = column(&PhaseFit::center_axial_sigma_mm);
  phases["center_radial_mm"] = column(&PhaseFit::center_radial_mm);
  phases["center_radial_sigma_mm"] = column(&PhaseFit::center_radial_sigma_mm);
  phases["arc_error_um"] = column(&PhaseFit::arc_error_um);
  phases["chi2_per_dof"] = column(&PhaseFit::chi2_per_dof);
  json points = json::array(), usable = json::array(), flag = json::array();
  for (const PhaseFit& p : fit.phases) {
    points.push_back(p.points);
    usable.push_back(p.usable);
    flag.push_back(p.flag);
  }
  phases["points_in_band"] = points;
  phases["usable"] = usable;
  phases["flag"] = flag;
  return phases;
}

void WriteMap(const std::filesystem::path& path, const RunRecord& record,
              const processing::ProcessedScan& processed, const WheelFit& fit) {
  const processing::WheelMap& map = processed.map;
  hdf5::File file = hdf5::File::Create(path);
  const hsize_t n_phase = map.n_phase();
  const hsize_t n_y = map.n_y();
  file.CreateGroup("/map");
  file.WriteDoubles("/map/phase_deg", map.phase_deg, {n_phase});
  file.WriteDoubles("/map/y_mm", map.y_mm, {n_y});
  file.WriteDoubles("/map/rho", map.rho_mm, {n_phase, n_y});
  file.WriteDoubles("/map/form_error_um", fit.form_error_um, {n_phase, n_y});
  file.WriteInts("/map/sample_count", map.sample_count, {n_phase, n_y});
  file.WriteInts("/map/despiked_count", map.despiked_count, {n_phase, n_y});
  file.CreateGroup("/fit");
  const auto column = [&](const char* name, auto member) {
    std::vector<double> values;
    for (const PhaseFit& p : fit.phases) values.push_back(p.usable ? p.*member : std::nan(""));
    file.WriteDoubles(std::string("/fit/") + name, values, {n_phase});
  };
  column("arc_radius_mm", &PhaseFit::arc_radius_mm);
  column("arc_radius_sigma_mm", &PhaseFit::arc_radius_sigma_mm);
  column("center_axial_mm", &PhaseFit::center_axial_mm);
  column("center_axial_sigma_mm", &PhaseFit::center_axial_sigma_mm);
  column("center_radial_mm", &PhaseFit::center_radial_mm);
  column("center_radial_sigma_mm", &PhaseFit::center_radial_sigma_mm);
  column("arc_error_um", &PhaseFit::arc_error_um);
  std::vector<int> usable, points;
  for (const PhaseFit& p : fit.phases) {
    usable.push_back(p.usable ? 1 : 0);
    points.push_back(p.points);
  }
  file.WriteInts("/fit/usable", usable, {n_phase});
  file.WriteInts("/fit/points_in_band", points, {n_phase});
  file.CreateGroup("/axial");
  const hsize_t n_band = fit.axial_y_mm.size();
  file.WriteDoubles("/axial/y_mm", fit.axial_y_mm, {n_band});
  file.WriteDoubles("/axial/runout_um", fit.runout_um, {n_band});
  file.WriteDoubles("/axial/roundness_um", fit.roundness_um, {n_band});
  file.WriteAttribute("/", "arcwheel_version", std::string(kVersion));
  file.WriteAttribute("/", "input_path", record.input_path);
  file.WriteAttribute("/", "input_sha256", record.input_sha256);
  file.WriteAttribute("/", "noise_sigma_um", processed.noise_sigma_mm * 1000.0);
  file.WriteAttribute("/", "spindle_rpm_used", processed.rpm_used);
  for (const auto& [name, value] : record.numeric_parameters) file.WriteAttribute("/", name, value);
  for (const auto& [name, value] : record.text_parameters) file.WriteAttribute("/", name, value);
}

}  // namespace

std::string SummaryJson(const RunRecord& record, const processing::ProcessedScan& processed,
                        const WheelFit& fit) {
  const processing::WheelMap& map = processed.map;
  const acquisition::ScanMetadata& m = record.metadata;
  json s;
  s["arcwheel_version"] = kVersion;
  s["input"] = {{"path", record.input_path},
                {"sha256", record.input_sha256},
                {"format", record.input_format},
                {"samples", processed.samples},
                {"valid_samples", processed.valid_samples},
                {"despiked_samples", processed.despike.rejected},
                {"stuck_samples", processed.stuck.dropped}};
  s["scan"] = {{"wheel_id", m.wheel_id},
               {"sensor", m.sensor},
               {"operator", m.operator_name},
               {"timestamp", m.timestamp},
               {"wheel_diameter_mm", Optional(m.wheel_diameter_mm)},
               {"wheel_width_mm", Optional(m.wheel_width_mm)},
               {"feed_mm_per_min", Optional(m.feed_mm_per_min)},
               {"sample_period_s", Optional(m.sample_period_s)},
               {"radius_sign", m.radius_sign},
               {"start_y_mm", m.start_y_mm},
               {"has_encoder", record.has_encoder},
               {"first_valid_sample", processed.first_valid},
               {"last_valid_sample", processed.last_valid}};
  s["spindle_rpm_nominal"] = Optional(m.spindle_rpm);
  s["spindle_rpm_estimated"] = processed.rpm_used;
  s["spindle_rpm_source"] = PhaseSourceName(processed.phase_source);
  s["spindle_rpm_sigma"] = processed.speed.available ? json(processed.speed.sigma_rpm) : json(nullptr);
  s["spindle_rpm_fitted"] = processed.speed.available ? json(processed.speed.fitted_rpm) : json(nullptr);
  s["noise_sigma_um"] = processed.noise_sigma_mm * 1000.0;
  std::vector<double> point_sigmas;
  for (const auto& section : map.sections)
    point_sigmas.insert(point_sigmas.end(), section.sigma_mm.begin(), section.sigma_mm.end());
  std::sort(point_sigmas.begin(), point_sigmas.end());
  s["map_sigma_um"] =
      point_sigmas.empty() ? json(nullptr) : json(point_sigmas[point_sigmas.size() / 2] * 1000.0);
  s["mean_arc_radius_mm"] = fit.mean_arc_radius_mm;
  s["mean_arc_radius_sigma_mm"] = fit.mean_arc_radius_sigma_mm;
  s["arc_radius_range_mm"] = fit.arc_radius_range_mm;
  s["arc_radius_fluctuation_pct"] = fit.arc_radius_fluctuation_pct;
  s["arc_radius_std_mm"] = fit.arc_radius_std_mm;
  s["arc_radius_noise_std_mm"] = fit.arc_radius_noise_std_mm;
  s["arc_radius_excess_std_mm"] = fit.arc_radius_excess_std_mm;
  s["mean_center_axial_mm"] = fit.mean_center_axial_mm;
  s["mean_center_axial_sigma_mm"] = fit.mean_center_axial_sigma_mm;
  s["center_axial_deviation_mm"] = fit.center_axial_deviation_mm;
  s["mean_center_radial_mm"] = fit.mean_center_radial_mm;
  double band_half = 8.0;
  for (const auto& [name, value] : record.numeric_parameters) {
    if (name == "band_half_width_mm") band_half = value;
  }
  s["band_half_width_mm"] = band_half;
  s["band_mm"] = {fit.band_low_mm, fit.band_high_mm};
  s["max_arc_error_um"] = fit.max_arc_error_um;
  s["max_runout_um"] = fit.max_runout_um;
  s["max_roundness_um"] = fit.max_roundness_um;
  s["median_chi2_per_dof"] = Number(fit.median_chi2_per_dof);
  s["usable_phases"] = fit.usable_phases;
  s["runout_note"] =
      "runout is that of the wheel plus the spindle's error motion: one sensor cannot separate them";
  s["phases"] = PhasesJson(map, fit);
  s["axial"] = {{"y_mm", fit.axial_y_mm},
                {"runout_um", Numbers(fit.runout_um)},
                {"roundness_um", Numbers(fit.roundness_um)}};
  s["mean_profile"] = {{"u_mm", fit.profile_u_mm}, {"error_um", Numbers(fit.profile_error_um)}};
  json parameters;
  for (const auto& [name, value] : record.numeric_parameters) parameters[name] = value;
  for (const auto& [name, value] : record.text_parameters) parameters[name] = value;
  parameters["knot_step_deg"] = map.knot_step_deg;
  parameters["axial_step_mm"] = map.axial_step_mm;
  parameters["despike_threshold_used_um"] = processed.despike.threshold_um;
  parameters["stuck_run_samples_used"] = processed.stuck.min_run;
  s["processing"] = parameters;
  json warnings = json::array();
  for (const auto& w : processed.warnings) warnings.push_back(w);
  for (const auto& w : fit.warnings) warnings.push_back(w);
  s["warnings"] = warnings;
  return s.dump(2) + "\n";
}

void WriteProcessOutputs(const std::filesystem::path& outdir, const RunRecord& record,
                         const processing::ProcessedScan& processed, const WheelFit& fit) {
  EnsureDirectory(outdir);
  OutputSet outputs;
  const auto summary_path = outputs.Stage(outdir / "summary.json");
  const auto map_path = outputs.Stage(outdir / "wheel_map.h5");
  {
    const std::string summary = SummaryJson(record, processed, fit);
    std::ofstream out(summary_path, std::ios::binary);
    out << summary;
    out.flush();
    if (!out)
      throw Error(ErrorCode::kIo, "output",
                  "cannot write '" + (outdir / "summary.json").string() + "' (disk full?)");
  }
  WriteMap(map_path, record, processed, fit);
  outputs.Commit();
}

}  // namespace arcwheel::fitting
