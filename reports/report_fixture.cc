#include "reports/report_fixture.h"

#include <cmath>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

#include "fitting/outputs.h"
#include "schema/summary.h"

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

double FixtureModelResidual_um(double phase_deg, double y_mm, bool has_samples) {
  if (!has_samples || y_mm < 2.0 || y_mm > 18.0) return kNaN;
  return 0.1 * std::sin(3.0 * phase_deg * kDegToRad) * std::cos(y_mm);
}

namespace {

namespace parameter = schema::summary::processing;

processing::ProcessedScan FixtureScan(const FixtureOptions& options) {
  processing::ProcessedScan scan;
  scan.samples = 2400000;
  scan.valid_samples = 2399000;
  scan.first_valid = 0;
  scan.last_valid = scan.samples - 1;
  scan.despike.rejected = 37;
  scan.despike.threshold_um = 5.0;
  scan.noise_sigma_mm = 0.31e-3;
  scan.speed.available = true;
  scan.speed.fitted_rpm = 999.87;
  scan.speed.sigma_rpm = 0.02;
  scan.phase_source = processing::PhaseSource::kEstimated;
  scan.rpm_used = 999.87;
  scan.warnings = {"spindle speed estimated from the data (999.87 rpm vs 1000 nominal)"};

  processing::WheelMap& map = scan.map;
  map.phase_deg = PhaseNodes(options);
  map.y_mm = AxialNodes(options);
  map.knot_step_deg = 360.0 / static_cast<double>(options.n_phase);
  map.axial_step_mm = 0.1;
  const std::size_t cells = options.n_phase * options.n_y;
  map.rho_mm.resize(cells);
  map.sample_count.assign(cells, 4);
  map.despiked_count.assign(cells, 0);
  for (std::size_t i = 0; i < options.n_phase; ++i) {
    for (std::size_t j = 0; j < options.n_y; ++j) {
      const std::size_t k = i * options.n_y + j;
      map.rho_mm[k] = Rho(map.phase_deg[i], map.y_mm[j], options.radial_offset_um);
      if (IsMissing(map.phase_deg[i], map.y_mm[j])) {
        map.rho_mm[k] = kNaN;
        map.sample_count[k] = 0;
      }
      if (IsDespiked(map.phase_deg[i], map.y_mm[j])) map.despiked_count[k] = 1;
    }
  }
  // Every map value has a 1-sigma of 0.05 um: the median the writer records.
  map.map_sigma_mm = 0.05e-3;
  return scan;
}

fitting::WheelFit FixtureFit(const FixtureOptions& options, const processing::WheelMap& map) {
  fitting::WheelFit fit;
  for (const double c : map.phase_deg) {
    fit.phases.push_back({.arc_radius_mm = FixtureArcRadius_mm(c),
                          .arc_radius_sigma_mm = 0.0004,
                          .center_axial_mm = FixtureCenterAxial_mm(c),
                          .center_axial_sigma_mm = 0.0002,
                          .center_radial_mm = FixtureCenterRadial_mm(c),
                          .center_radial_sigma_mm = 0.0003,
                          .arc_error_um = 1.0 + 0.5 * std::cos(3.0 * c * kDegToRad),
                          .chi2_per_dof = 1.0,
                          .points = 160,
                          .usable = true,
                          .flag = ""});
  }
  // Headline literals; their printed forms are "75.01234 ± 0.00021 mm", "0.0061 mm",
  // "0.008 %", "0.0043 mm", "1.58 µm", "7.13 µm", "3.47 µm".
  fit.mean_arc_radius_mm = 75.01234;
  fit.mean_arc_radius_sigma_mm = 0.00021;
  fit.arc_radius_range_mm = 0.0061;
  fit.arc_radius_fluctuation_pct = 0.008;
  fit.arc_radius_std_mm = 0.0021;
  fit.mean_center_axial_mm = 10.0;
  fit.center_axial_deviation_mm = 0.0043;
  fit.mean_center_radial_mm = 25.0;
  fit.band_low_mm = 2.0;
  fit.band_high_mm = 18.0;
  fit.max_arc_error_um = 1.58;
  fit.max_runout_um = 7.13;
  fit.max_roundness_um = 3.47;
  fit.median_chi2_per_dof = 1.0;
  fit.usable_phases = static_cast<int>(options.n_phase);
  for (const double y : map.y_mm) {
    if (y < 2.0 || y > 18.0) continue;
    fit.axial_y_mm.push_back(y);
    fit.runout_um.push_back(6.0 + 0.05 * y);
    fit.roundness_um.push_back(3.0 + 0.02 * y);
  }
  // Form error against the mean wheel (Ra 75 mm, centre (10, 25) mm).
  fit.form_error_um.resize(map.rho_mm.size());
  for (std::size_t i = 0; i < map.n_phase(); ++i) {
    for (std::size_t j = 0; j < map.n_y(); ++j) {
      const double u = map.y_mm[j] - 10.0;
      fit.form_error_um[i * map.n_y() + j] =
          (map.rho(i, j) - (25.0 + std::sqrt(75.0 * 75.0 - u * u))) * 1000.0;
    }
  }
  return fit;
}

// The model's numbers; their printed forms are "75.00003 ± 0.00002 mm", "0.0060 ± 0.0003 mm",
// "yes (χ² = 912.3 with 7 dof, p < 0.001; significance level 0.01)", "0.313 µm against a noise
// estimate of 0.310 µm (ratio 1.01)", "0.84 µm", and the harmonics (order, amplitude, phase)
// "1", "0.04 ± 0.11 µm", "12.5 ± 160.0 deg"; "2", "3.00 ± 0.12 µm", "−90.0 ± 2.3 deg".
fitting::WheelModel FixtureModel(const processing::WheelMap& map) {
  fitting::WheelModel model;
  model.fitted = true;
  model.radius_knots = 8;
  model.axial_knots = 4;
  model.runout_knots = 16;
  model.profile_coefficients = 30;
  model.knots_chosen = true;
  model.band_low_mm = 2.0;
  model.band_high_mm = 18.0;
  model.center_axial_reference_mm = 10.0;
  model.samples = 1280000;
  model.parameters = 55;
  model.iterations = 4;
  model.residual_rms_um = 0.3127;
  model.noise_sigma_um = 0.31;
  model.mean_arc_radius_mm = 75.00003;
  model.mean_arc_radius_sigma_mm = 0.00002;
  model.arc_radius_range_mm = 0.0060;
  model.arc_radius_range_sigma_mm = 0.0003;
  model.variation_chi2 = 912.345;
  model.variation_dof = 7;
  model.variation_p_value = 1e-12;
  model.significance_level = 0.01;
  model.variation_significant = true;
  model.radius_harmonics = {{.order = 1,
                             .amplitude_um = 0.04,
                             .amplitude_sigma_um = 0.11,
                             .phase_deg = 12.5,
                             .phase_sigma_deg = 160.0},
                            {.order = 2,
                             .amplitude_um = 3.0,
                             .amplitude_sigma_um = 0.12,
                             .phase_deg = -90.0,
                             .phase_sigma_deg = 2.3}};
  model.profile_pv_um = 0.84;
  model.phase_deg = map.phase_deg;
  for (const double c : map.phase_deg) {
    model.arc_radius_mm.push_back(FixtureArcRadius_mm(c));
    model.arc_radius_sigma_mm.push_back(0.0002);
    model.center_axial_mm.push_back(FixtureCenterAxial_mm(c));
    model.center_axial_sigma_mm.push_back(0.0001);
    model.center_radial_mm.push_back(FixtureCenterRadial_mm(c));
    model.center_radial_sigma_mm.push_back(0.00015);
  }
  for (int k = 0; k <= 160; ++k) {
    const double u = -8.0 + 0.1 * k;
    model.profile_u_mm.push_back(u);
    model.profile_error_um.push_back(0.42 * std::cos(M_PI * u / 8.0));
    model.profile_error_sigma_um.push_back(0.02);
  }
  for (std::size_t i = 0; i < map.n_phase(); ++i) {
    for (std::size_t j = 0; j < map.n_y(); ++j) {
      const bool has_samples = map.sample_count[i * map.n_y() + j] > 0;
      model.residual_um.push_back(FixtureModelResidual_um(map.phase_deg[i], map.y_mm[j], has_samples));
    }
  }
  // Coefficients and covariance as the writer stores them; the report does not read them.
  model.coefficients.assign(3, 0.0);
  model.covariance.assign(9, 0.0);
  return model;
}

fitting::RunRecord FixtureRecord(const FixtureOptions& options) {
  fitting::RunRecord record;
  record.input_path = "/data/scans/wheel_W17.h5";
  record.input_sha256 = kSha;
  record.input_format = "hdf5";
  record.metadata.wheel_id = "W17-arc75";
  record.metadata.sensor = "Keyence LK-H008";
  record.metadata.operator_name = "A. Operator";
  record.metadata.timestamp = "2026-03-04T10:20:30Z";
  record.metadata.wheel_diameter_mm = 200.0;
  record.metadata.wheel_width_mm = 20.0;
  record.metadata.feed_mm_per_min = 10.0;
  record.metadata.sample_period_s = 0.0001;
  record.metadata.spindle_rpm = 1000.0;
  record.metadata.radius_sign = 1;
  record.metadata.start_y_mm = 0.0;
  record.numeric_parameters = {{std::string(parameter::kPhases), static_cast<double>(options.n_phase)},
                               {std::string(parameter::kBandHalfWidthMm), 8.0},
                               {std::string(parameter::kDespikeWindowHalfWidth), 5.0},
                               {std::string(parameter::kDespikeThresholdUm), 5.0}};
  record.text_parameters = {{std::string(parameter::kFitSpan), "band"},
                            {std::string(parameter::kModel), options.with_model ? "on" : "off"}};
  return record;
}

}  // namespace

nlohmann::json FixtureSummary(const FixtureOptions& options) {
  const processing::ProcessedScan scan = FixtureScan(options);
  const fitting::WheelModel model = FixtureModel(scan.map);
  return nlohmann::json::parse(fitting::SummaryJson(
      FixtureRecord(options), scan, FixtureFit(options, scan.map), options.with_model ? &model : nullptr));
}

void WriteFixture(const std::filesystem::path& outdir, const FixtureOptions& options,
                  const nlohmann::json& summary) {
  WriteFixture(outdir, options);
  std::ofstream(outdir / schema::summary::kFileName) << summary.dump(2);
}

void WriteFixture(const std::filesystem::path& outdir, const FixtureOptions& options) {
  const processing::ProcessedScan scan = FixtureScan(options);
  const fitting::WheelModel model = FixtureModel(scan.map);
  fitting::WriteProcessOutputs(outdir, FixtureRecord(options), scan, FixtureFit(options, scan.map),
                               options.with_model ? &model : nullptr);
}

}  // namespace arcwheel::reports::testing
