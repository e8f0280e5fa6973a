#include "fitting/outputs.h"

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"
#include "core/version.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"

namespace arcwheel::fitting {
namespace {

using nlohmann::json;
namespace key = schema::summary;
namespace h5 = schema::wheel_map;

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
  phases[key::phases::kPhaseDeg] = map.phase_deg;
  const auto column = [&](auto member) {
    json list = json::array();
    for (const PhaseFit& p : fit.phases) list.push_back(p.usable ? Number(p.*member) : json(nullptr));
    return list;
  };
  phases[key::phases::kArcRadiusMm] = column(&PhaseFit::arc_radius_mm);
  phases[key::phases::kArcRadiusSigmaMm] = column(&PhaseFit::arc_radius_sigma_mm);
  phases[key::phases::kCenterAxialMm] = column(&PhaseFit::center_axial_mm);
  phases[key::phases::kCenterAxialSigmaMm] = column(&PhaseFit::center_axial_sigma_mm);
  phases[key::phases::kCenterRadialMm] = column(&PhaseFit::center_radial_mm);
  phases[key::phases::kCenterRadialSigmaMm] = column(&PhaseFit::center_radial_sigma_mm);
  phases[key::phases::kArcErrorUm] = column(&PhaseFit::arc_error_um);
  phases[key::phases::kChi2PerDof] = column(&PhaseFit::chi2_per_dof);
  json points = json::array(), usable = json::array(), flag = json::array();
  for (const PhaseFit& p : fit.phases) {
    points.push_back(p.points);
    usable.push_back(p.usable);
    flag.push_back(p.flag);
  }
  phases[key::phases::kPointsInBand] = points;
  phases[key::phases::kUsable] = usable;
  phases[key::phases::kFlag] = flag;
  return phases;
}

json ModelJson(const WheelModel& m) {
  namespace mk = key::model;
  json harmonics = json::array();
  for (const RadiusHarmonic& h : m.radius_harmonics) {
    harmonics.push_back({{mk::harmonic::kOrder, h.order},
                         {mk::harmonic::kAmplitudeUm, Number(h.amplitude_um)},
                         {mk::harmonic::kAmplitudeSigmaUm, Number(h.amplitude_sigma_um)},
                         {mk::harmonic::kPhaseDeg, Number(h.phase_deg)},
                         {mk::harmonic::kPhaseSigmaDeg, Number(h.phase_sigma_deg)}});
  }
  json j;
  j[mk::kRadiusKnots] = m.radius_knots;
  j[mk::kAxialKnots] = m.axial_knots;
  j[mk::kRunoutKnots] = m.runout_knots;
  j[mk::kKnotsChosenBy] = m.knots_chosen ? "bic" : "given";
  j[mk::kProfileCoefficients] = m.profile_coefficients;
  j[mk::kSamples] = m.samples;
  j[mk::kParameters] = m.parameters;
  j[mk::kIterations] = m.iterations;
  j[mk::kResidualRmsUm] = Number(m.residual_rms_um);
  j[mk::kNoiseSigmaUm] = Number(m.noise_sigma_um);
  j[mk::kMeanArcRadiusMm] = Number(m.mean_arc_radius_mm);
  j[mk::kMeanArcRadiusSigmaMm] = Number(m.mean_arc_radius_sigma_mm);
  j[mk::kArcRadiusRangeMm] = Number(m.arc_radius_range_mm);
  j[mk::kArcRadiusRangeSigmaMm] = Number(m.arc_radius_range_sigma_mm);
  j[mk::kVariationChi2] = Number(m.variation_chi2);
  j[mk::kVariationDof] = m.variation_dof;
  j[mk::kVariationPValue] = Number(m.variation_p_value);
  j[mk::kSignificanceLevel] = m.significance_level;
  j[mk::kVariationSignificant] = m.variation_significant;
  j[mk::kProfilePvUm] = Number(m.profile_pv_um);
  j[mk::kRadiusHarmonics] = harmonics;
  return j;
}

void WriteModel(hdf5::File& file, const processing::WheelMap& map, const WheelModel& m) {
  const hsize_t n_phase = m.phase_deg.size(), n_u = m.profile_u_mm.size();
  const hsize_t n = m.coefficients.size();
  file.CreateGroup(std::string(h5::kModelGroup));
  file.WriteDoubles(std::string(h5::kModelArcRadiusMm), m.arc_radius_mm, {n_phase});
  file.WriteDoubles(std::string(h5::kModelArcRadiusSigmaMm), m.arc_radius_sigma_mm, {n_phase});
  file.WriteDoubles(std::string(h5::kModelCenterAxialMm), m.center_axial_mm, {n_phase});
  file.WriteDoubles(std::string(h5::kModelCenterAxialSigmaMm), m.center_axial_sigma_mm, {n_phase});
  file.WriteDoubles(std::string(h5::kModelCenterRadialMm), m.center_radial_mm, {n_phase});
  file.WriteDoubles(std::string(h5::kModelCenterRadialSigmaMm), m.center_radial_sigma_mm, {n_phase});
  file.WriteDoubles(std::string(h5::kModelProfileUMm), m.profile_u_mm, {n_u});
  file.WriteDoubles(std::string(h5::kModelProfileErrorUm), m.profile_error_um, {n_u});
  file.WriteDoubles(std::string(h5::kModelProfileErrorSigmaUm), m.profile_error_sigma_um, {n_u});
  if (m.residual_um.size() == map.n_phase() * map.n_y()) {
    file.WriteDoubles(std::string(h5::kModelResidualUm), m.residual_um, {map.n_phase(), map.n_y()});
  }
  file.WriteDoubles(std::string(h5::kModelCoefficients), m.coefficients, {n});
  file.WriteDoubles(std::string(h5::kModelCovariance), m.covariance, {n, n});
}

void WriteMap(const std::filesystem::path& path, const RunRecord& record,
              const processing::ProcessedScan& processed, const WheelFit& fit, const WheelModel* model) {
  const processing::WheelMap& map = processed.map;
  hdf5::File file = hdf5::File::Create(path);
  const hsize_t n_phase = map.n_phase();
  const hsize_t n_y = map.n_y();
  file.CreateGroup(std::string(h5::kMapGroup));
  file.WriteDoubles(std::string(h5::kMapPhaseDeg), map.phase_deg, {n_phase});
  file.WriteDoubles(std::string(h5::kMapYMm), map.y_mm, {n_y});
  file.WriteDoubles(std::string(h5::kMapRhoMm), map.rho_mm, {n_phase, n_y});
  file.WriteDoubles(std::string(h5::kMapFormErrorUm), fit.form_error_um, {n_phase, n_y});
  file.WriteInts(std::string(h5::kMapSampleCount), map.sample_count, {n_phase, n_y});
  file.WriteInts(std::string(h5::kMapDespikedCount), map.despiked_count, {n_phase, n_y});
  file.CreateGroup(std::string(h5::kFitGroup));
  const auto column = [&](std::string_view dataset, auto member) {
    std::vector<double> values;
    for (const PhaseFit& p : fit.phases) values.push_back(p.usable ? p.*member : std::nan(""));
    file.WriteDoubles(std::string(dataset), values, {n_phase});
  };
  column(h5::kFitArcRadiusMm, &PhaseFit::arc_radius_mm);
  column(h5::kFitArcRadiusSigmaMm, &PhaseFit::arc_radius_sigma_mm);
  column(h5::kFitCenterAxialMm, &PhaseFit::center_axial_mm);
  column(h5::kFitCenterAxialSigmaMm, &PhaseFit::center_axial_sigma_mm);
  column(h5::kFitCenterRadialMm, &PhaseFit::center_radial_mm);
  column(h5::kFitCenterRadialSigmaMm, &PhaseFit::center_radial_sigma_mm);
  column(h5::kFitArcErrorUm, &PhaseFit::arc_error_um);
  std::vector<int> usable, points;
  for (const PhaseFit& p : fit.phases) {
    usable.push_back(p.usable ? 1 : 0);
    points.push_back(p.points);
  }
  file.WriteInts(std::string(h5::kFitUsable), usable, {n_phase});
  file.WriteInts(std::string(h5::kFitPointsInBand), points, {n_phase});
  file.CreateGroup(std::string(h5::kAxialGroup));
  const hsize_t n_band = fit.axial_y_mm.size();
  file.WriteDoubles(std::string(h5::kAxialYMm), fit.axial_y_mm, {n_band});
  file.WriteDoubles(std::string(h5::kAxialRunoutUm), fit.runout_um, {n_band});
  file.WriteDoubles(std::string(h5::kAxialRoundnessUm), fit.roundness_um, {n_band});
  if (model != nullptr && model->fitted) WriteModel(file, map, *model);
  const std::string root(h5::kRoot);
  file.WriteAttribute(root, std::string(h5::kSchemaVersionAttribute), schema::VersionText(h5::kVersion));
  file.WriteAttribute(root, std::string(h5::kArcwheelVersionAttribute), std::string(kVersion));
  file.WriteAttribute(root, std::string(h5::kInputPathAttribute), record.input_path);
  file.WriteAttribute(root, std::string(h5::kInputSha256Attribute), record.input_sha256);
  file.WriteAttribute(root, std::string(h5::kNoiseSigmaUmAttribute), processed.noise_sigma_mm * 1000.0);
  file.WriteAttribute(root, std::string(h5::kSpindleRpmUsedAttribute), processed.rpm_used);
  for (const auto& [name, value] : record.numeric_parameters) file.WriteAttribute(root, name, value);
  for (const auto& [name, value] : record.text_parameters) file.WriteAttribute(root, name, value);
}

}  // namespace

std::string SummaryJson(const RunRecord& record, const processing::ProcessedScan& processed,
                        const WheelFit& fit, const WheelModel* model, const nlohmann::json* later_stages) {
  const processing::WheelMap& map = processed.map;
  const acquisition::ScanMetadata& m = record.metadata;
  json s;
  s[key::kSchemaVersion] = schema::VersionText(key::kVersion);
  s[key::kArcwheelVersion] = kVersion;
  s[key::kInput] = {{key::input::kPath, record.input_path},
                    {key::input::kSha256, record.input_sha256},
                    {key::input::kFormat, record.input_format},
                    {key::input::kSamples, processed.samples},
                    {key::input::kValidSamples, processed.valid_samples},
                    {key::input::kDespikedSamples, processed.despike.rejected},
                    {key::input::kStuckSamples, processed.stuck.dropped}};
  {
    json columns = json::object();
    for (const acquisition::ScanReadRecord::Column& c : record.read.columns)
      columns[c.quantity] = {{key::input::kColumnName, c.name}, {key::input::kColumnUnit, c.unit}};
    json markers = json::object();
    for (const auto& [kind, count] : record.read.invalid_markers) markers[kind] = count;
    json sources = json::object();
    for (const auto& [setting, source] : record.read.sources) sources[setting] = source;
    json& input = s[key::kInput];
    input[key::input::kColumns] = std::move(columns);
    input[key::input::kInvalidMarkers] = std::move(markers);
    input[key::input::kScanSettings] = record.read.settings_path;
    input[key::input::kSources] = std::move(sources);
  }
  s[key::kScan] = {{key::scan::kWheelId, m.wheel_id},
                   {key::scan::kSensor, m.sensor},
                   {key::scan::kOperator, m.operator_name},
                   {key::scan::kTimestamp, m.timestamp},
                   {key::scan::kWheelDiameterMm, Optional(m.wheel_diameter_mm)},
                   {key::scan::kWheelWidthMm, Optional(m.wheel_width_mm)},
                   {key::scan::kFeedMmPerMin, Optional(m.feed_mm_per_min)},
                   {key::scan::kSamplePeriodS, Optional(m.sample_period_s)},
                   {key::scan::kRadiusSign, m.radius_sign},
                   {key::scan::kStartYMm, m.start_y_mm},
                   {key::scan::kHasEncoder, record.has_encoder},
                   {key::scan::kFirstValidSample, processed.first_valid},
                   {key::scan::kLastValidSample, processed.last_valid}};
  s[key::kSpindleRpmNominal] = Optional(m.spindle_rpm);
  s[key::kSpindleRpmEstimated] = processed.rpm_used;
  s[key::kSpindleRpmSource] = PhaseSourceName(processed.phase_source);
  s[key::kSpindleRpmSigma] = processed.speed.available ? json(processed.speed.sigma_rpm) : json(nullptr);
  s[key::kSpindleRpmFitted] = processed.speed.available ? json(processed.speed.fitted_rpm) : json(nullptr);
  s[key::kNoiseSigmaUm] = processed.noise_sigma_mm * 1000.0;
  s[key::kMapSigmaUm] = map.map_sigma_mm > 0.0 ? json(map.map_sigma_mm * 1000.0) : json(nullptr);
  s[key::kMeanArcRadiusMm] = fit.mean_arc_radius_mm;
  s[key::kMeanArcRadiusSigmaMm] = fit.mean_arc_radius_sigma_mm;
  s[key::kArcRadiusRangeMm] = fit.arc_radius_range_mm;
  s[key::kArcRadiusFluctuationPct] = fit.arc_radius_fluctuation_pct;
  s[key::kArcRadiusStdMm] = fit.arc_radius_std_mm;
  s[key::kArcRadiusNoiseStdMm] = fit.arc_radius_noise_std_mm;
  s[key::kArcRadiusExcessStdMm] = fit.arc_radius_excess_std_mm;
  s[key::kMeanCenterAxialMm] = fit.mean_center_axial_mm;
  s[key::kMeanCenterAxialSigmaMm] = fit.mean_center_axial_sigma_mm;
  s[key::kCenterAxialDeviationMm] = fit.center_axial_deviation_mm;
  s[key::kMeanCenterRadialMm] = fit.mean_center_radial_mm;
  double band_half = 8.0;
  for (const auto& [name, value] : record.numeric_parameters) {
    if (name == key::processing::kBandHalfWidthMm) band_half = value;
  }
  s[key::kBandHalfWidthMm] = band_half;
  s[key::kBandMm] = {fit.band_low_mm, fit.band_high_mm};
  s[key::kMaxArcErrorUm] = fit.max_arc_error_um;
  s[key::kMaxRunoutUm] = fit.max_runout_um;
  s[key::kMaxRoundnessUm] = fit.max_roundness_um;
  s[key::kMedianChi2PerDof] = Number(fit.median_chi2_per_dof);
  s[key::kUsablePhases] = fit.usable_phases;
  s[key::kRunoutNote] =
      "runout is that of the wheel plus the spindle's error motion: one sensor cannot separate them";
  s[key::kPhases] = PhasesJson(map, fit);
  s[key::kAxial] = {{key::axial::kYMm, fit.axial_y_mm},
                    {key::axial::kRunoutUm, Numbers(fit.runout_um)},
                    {key::axial::kRoundnessUm, Numbers(fit.roundness_um)}};
  s[key::kMeanProfile] = {{key::mean_profile::kUMm, fit.profile_u_mm},
                          {key::mean_profile::kErrorUm, Numbers(fit.profile_error_um)}};
  json parameters;
  for (const auto& [name, value] : record.numeric_parameters) parameters[name] = value;
  for (const auto& [name, value] : record.text_parameters) parameters[name] = value;
  parameters[key::processing::kKnotStepDeg] = map.knot_step_deg;
  parameters[key::processing::kAxialStepMm] = map.axial_step_mm;
  parameters[key::processing::kDespikeThresholdUsedUm] = processed.despike.threshold_um;
  parameters[key::processing::kStuckRunSamplesUsed] = processed.stuck.min_run;
  s[key::kProcessing] = parameters;
  json warnings = json::array();
  for (const auto& w : processed.warnings) warnings.push_back(w);
  for (const auto& w : fit.warnings) warnings.push_back(w);
  s[key::kWarnings] = warnings;
  if (model != nullptr && model->fitted) s[key::kModel] = ModelJson(*model);
  if (later_stages != nullptr) {
    for (const auto& [name, object] : later_stages->items()) s[name] = object;
  }
  return JsonText(s, 2) + "\n";
}

void WriteProcessOutputs(const std::filesystem::path& outdir, const RunRecord& record,
                         const processing::ProcessedScan& processed, const WheelFit& fit,
                         const WheelModel* model, const nlohmann::json* later_stages) {
  // A folder this call makes goes again if a write fails: nothing of a failed run stays behind.
  OutputSet outputs;
  outputs.CreateFolder(outdir);
  const auto summary_path = outputs.Stage(outdir / key::kFileName);
  const auto map_path = outputs.Stage(outdir / h5::kFileName);
  {
    const std::string summary = SummaryJson(record, processed, fit, model, later_stages);
    std::ofstream out(summary_path, std::ios::binary);
    out << summary;
    out.flush();
    if (!out)
      throw Error(ErrorCode::kIo, "output",
                  "cannot write '" + (outdir / key::kFileName).string() + "' (disk full?)");
  }
  WriteMap(map_path, record, processed, fit, model);
  outputs.Commit();
}

}  // namespace arcwheel::fitting
