#include "reports/report_fixture.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "core/hdf5.h"

namespace arcwheel::reports::testing {
namespace {

constexpr double kDegToRad = M_PI / 180.0;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr const char* kSha = "3b1f5e0c9a7d4e2b8c6f1a0d9e8b7c6a5f4e3d2c1b0a99887766554433221100";

std::vector<double> PhaseNodes(const FixtureOptions& o) {
  std::vector<double> phases(o.n_phase);
  for (std::size_t i = 0; i < o.n_phase; ++i)
    phases[i] = 360.0 * static_cast<double>(i) / static_cast<double>(o.n_phase);
  return phases;
}

std::vector<double> AxialNodes(const FixtureOptions& o) {
  std::vector<double> y(o.n_y);
  for (std::size_t j = 0; j < o.n_y; ++j)
    y[j] = 20.0 * static_cast<double>(j) / static_cast<double>(o.n_y - 1);
  return y;
}

bool IsMissing(double phase_deg, double y_mm) { return phase_deg >= 90.0 && phase_deg < 100.0 && y_mm < 1.0; }
bool IsDespiked(double phase_deg, double y_mm) {
  return phase_deg >= 180.0 && phase_deg < 190.0 && y_mm >= 5.0 && y_mm < 6.0;
}

double Rho(double phase_deg, double y_mm, double offset_um) {
  const double u = y_mm - FixtureCenterAxial_mm(phase_deg);
  const double radius = FixtureArcRadius_mm(phase_deg);
  return FixtureCenterRadial_mm(phase_deg) + std::sqrt(radius * radius - u * u) + offset_um / 1000.0;
}

}  // namespace

double FixtureArcRadius_mm(double phase_deg) { return 75.0 + 0.003 * std::sin(2.0 * phase_deg * kDegToRad); }
double FixtureCenterAxial_mm(double phase_deg) { return 10.0 + 0.002 * std::cos(phase_deg * kDegToRad); }
double FixtureCenterRadial_mm(double phase_deg) { return 25.0 + 0.001 * std::sin(phase_deg * kDegToRad); }

nlohmann::json FixtureSummary(const FixtureOptions& options) {
  using nlohmann::json;
  const std::vector<double> phases = PhaseNodes(options);
  json p = {{"phase_deg", phases}};
  for (const char* key :
       {"arc_radius_mm", "arc_radius_sigma_mm", "center_axial_mm", "center_axial_sigma_mm",
        "center_radial_mm", "center_radial_sigma_mm", "arc_error_um", "points_in_band", "usable", "flag"}) {
    p[key] = json::array();
  }
  for (double c : phases) {
    p["arc_radius_mm"].push_back(FixtureArcRadius_mm(c));
    p["arc_radius_sigma_mm"].push_back(0.0004);
    p["center_axial_mm"].push_back(FixtureCenterAxial_mm(c));
    p["center_axial_sigma_mm"].push_back(0.0002);
    p["center_radial_mm"].push_back(FixtureCenterRadial_mm(c));
    p["center_radial_sigma_mm"].push_back(0.0003);
    p["arc_error_um"].push_back(1.0 + 0.5 * std::cos(3.0 * c * kDegToRad));
    p["points_in_band"].push_back(160);
    p["usable"].push_back(true);
    p["flag"].push_back("");
  }
  json axial = {{"y_mm", json::array()}, {"runout_um", json::array()}, {"roundness_um", json::array()}};
  for (double y : AxialNodes(options)) {
    if (y < 2.0 || y > 18.0) continue;
    axial["y_mm"].push_back(y);
    axial["runout_um"].push_back(6.0 + 0.05 * y);
    axial["roundness_um"].push_back(3.0 + 0.02 * y);
  }
  return {
      {"arcwheel_version", "0.1.0"},
      {"input",
       {{"path", "/data/scans/wheel_W17.h5"},
        {"sha256", kSha},
        {"samples", 2400000},
        {"valid_samples", 2399000},
        {"despiked_samples", 37},
        {"format", "hdf5"}}},
      {"scan",
       {{"wheel_id", "W17-arc75"},
        {"sensor", "Keyence LK-H008"},
        {"operator", "A. Operator"},
        {"timestamp", "2026-03-04T10:20:30Z"},
        {"wheel_diameter_mm", 200.0},
        {"wheel_width_mm", 20.0},
        {"feed_mm_per_min", 10.0},
        {"sample_period_s", 0.0001},
        {"radius_sign", 1},
        {"start_y_mm", 0.0},
        {"has_encoder", false}}},
      {"spindle_rpm_nominal", 1000.0},
      {"spindle_rpm_estimated", 999.87},
      {"spindle_rpm_sigma", 0.02},
      {"spindle_rpm_source", "estimated"},
      {"noise_sigma_um", 0.31},
      {"map_sigma_um", 0.05},
      // Headline literals; their printed forms are "75.01234 ± 0.00021 mm", "0.0061 mm",
      // "0.008 %", "0.0043 mm", "1.58 µm", "7.13 µm", "3.47 µm".
      {"mean_arc_radius_mm", 75.01234},
      {"mean_arc_radius_sigma_mm", 0.00021},
      {"arc_radius_range_mm", 0.0061},
      {"arc_radius_fluctuation_pct", 0.008},
      {"arc_radius_std_mm", 0.0021},
      {"mean_center_axial_mm", 10.0},
      {"center_axial_deviation_mm", 0.0043},
      {"mean_center_radial_mm", 25.0},
      {"band_half_width_mm", 8.0},
      {"band_mm", {2.0, 18.0}},
      {"max_arc_error_um", 1.58},
      {"max_runout_um", 7.13},
      {"max_roundness_um", 3.47},
      {"runout_note", "runout is the wheel's runout plus the spindle's error motion"},
      {"phases", p},
      {"axial", axial},
      {"processing",
       {{"despike", {{"window_half_width", 5}, {"threshold_um", 5.0}}},
        {"map", {{"phases", static_cast<int>(options.n_phase)}, {"axial_step_mm", 0.1}}},
        {"fit", {{"band_half_width_mm", 8.0}, {"fit_span", "band"}}}}},
      {"warnings", {"spindle speed estimated from the data (999.87 rpm vs 1000 nominal)"}},
  };
}

void WriteFixture(const std::filesystem::path& outdir, const FixtureOptions& options,
                  const nlohmann::json& summary) {
  std::filesystem::create_directories(outdir);
  std::ofstream(outdir / "summary.json") << summary.dump(2);
  const std::vector<double> phases = PhaseNodes(options);
  const std::vector<double> y = AxialNodes(options);
  const std::size_t cells = options.n_phase * options.n_y;
  std::vector<double> rho(cells), form_error(cells);
  std::vector<int> samples(cells, 4), despiked(cells, 0);
  for (std::size_t i = 0; i < options.n_phase; ++i) {
    for (std::size_t j = 0; j < options.n_y; ++j) {
      const std::size_t k = i * options.n_y + j;
      rho[k] = Rho(phases[i], y[j], options.radial_offset_um);
      form_error[k] = (rho[k] - (25.0 + std::sqrt(75.0 * 75.0 - (y[j] - 10.0) * (y[j] - 10.0)))) * 1000.0;
      if (IsMissing(phases[i], y[j])) {
        rho[k] = form_error[k] = kNaN;
        samples[k] = 0;
      }
      if (IsDespiked(phases[i], y[j])) despiked[k] = 1;
    }
  }
  hdf5::File file = hdf5::File::Create(outdir / "wheel_map.h5");
  const std::vector<hsize_t> grid = {options.n_phase, options.n_y};
  file.CreateGroup("/map");
  file.WriteDoubles("/map/phase_deg", phases, {options.n_phase});
  file.WriteDoubles("/map/y_mm", y, {options.n_y});
  file.WriteDoubles("/map/rho", rho, grid);
  file.WriteDoubles("/map/form_error_um", form_error, grid);
  file.WriteInts("/map/sample_count", samples, grid);
  file.WriteInts("/map/despiked_count", despiked, grid);
  file.CreateGroup("/fit");
  const nlohmann::json& p = summary.at("phases");
  for (const char* key :
       {"arc_radius_mm", "arc_radius_sigma_mm", "center_axial_mm", "center_radial_mm", "arc_error_um"}) {
    if (p.contains(key) && p.at(key).size() == options.n_phase) {
      std::vector<double> values;
      for (const auto& v : p.at(key)) values.push_back(v.is_number() ? v.get<double>() : kNaN);
      file.WriteDoubles(std::string("/fit/") + key, values, {options.n_phase});
    }
  }
  file.WriteAttribute("/", "arcwheel_version", std::string("0.1.0"));
  file.WriteAttribute("/", "input_path", std::string("/data/scans/wheel_W17.h5"));
  file.WriteAttribute("/", "input_sha256", std::string(kSha));
}

void WriteFixture(const std::filesystem::path& outdir, const FixtureOptions& options) {
  WriteFixture(outdir, options, FixtureSummary(options));
}

}  // namespace arcwheel::reports::testing
