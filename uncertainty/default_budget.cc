#include "uncertainty/default_budget.h"

#include <cmath>

#include "core/error.h"
#include "core/number_format.h"
#include "schema/summary.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kDefaultBudgetStage = "uncertainty.budget";
namespace s = schema::summary;

void Require(std::vector<std::string>& problems, bool ok, const std::string& name, double value,
             const std::string& rule) {
  if (!ok) problems.push_back(name + " = " + ShowSignificant(value) + " violates " + rule);
}

BudgetInput Rectangular(std::string name, std::string source, std::string unit, double half_width,
                        double sensitivity, bool relative = false) {
  return BudgetInput{.input = {.name = std::move(name),
                               .source = std::move(source),
                               .unit = std::move(unit),
                               .distribution = Distribution::kRectangular,
                               .spread = half_width,
                               .sensitivity = sensitivity},
                     .relative = relative};
}

}  // namespace

std::vector<std::string> WheelGeometry::Problems() const {
  std::vector<std::string> problems;
  Require(problems, std::isfinite(arc_radius_mm) && arc_radius_mm > 0.0, "WheelGeometry::arc_radius_mm",
          arc_radius_mm, "> 0");
  Require(problems,
          std::isfinite(band_half_width_mm) && band_half_width_mm > 0.0 && band_half_width_mm < arc_radius_mm,
          "WheelGeometry::band_half_width_mm", band_half_width_mm, "> 0 and < arc_radius_mm");
  Require(problems, std::isfinite(wheel_radius_mm) && wheel_radius_mm > 0.0, "WheelGeometry::wheel_radius_mm",
          wheel_radius_mm, "> 0");
  return problems;
}

std::vector<std::string> SensorBudgetOptions::Problems() const {
  std::vector<std::string> problems;
  const auto non_negative = [&](const char* name, double value) {
    Require(problems, std::isfinite(value) && value >= 0.0, std::string("SensorBudgetOptions::") + name,
            value, ">= 0");
  };
  non_negative("scale_ppm", scale_ppm);
  non_negative("linearity_um", linearity_um);
  Require(problems, std::isfinite(full_scale_mm) && full_scale_mm > 0.0, "SensorBudgetOptions::full_scale_mm",
          full_scale_mm, "> 0");
  non_negative("resolution_um", resolution_um);
  non_negative("axial_error_um", axial_error_um);
  non_negative("temperature_k", temperature_k);
  non_negative("expansion_per_k", expansion_per_k);
  non_negative("beam_offset_mm", beam_offset_mm);
  return problems;
}

double BandSagittaMm(const WheelGeometry& geometry) {
  return geometry.band_half_width_mm * geometry.band_half_width_mm / (2.0 * geometry.arc_radius_mm);
}

BudgetFile DefaultBudget(const WheelGeometry& geometry, const SensorBudgetOptions& options) {
  std::vector<std::string> problems = geometry.Problems();
  const std::vector<std::string> own = options.Problems();
  problems.insert(problems.end(), own.begin(), own.end());
  ThrowIfProblems(ErrorCode::kInvalidOption, kDefaultBudgetStage, problems);

  const double ra = geometry.arc_radius_mm;
  const double sagitta_mm = BandSagittaMm(geometry);
  // A smooth non-linearity of +-L over the full scale FS bows a sub-range of depth s by about
  // L (s / FS)^2: its straight part is a scale error, its curved part falls with the square.
  const double bow_um = options.linearity_um * std::pow(sagitta_mm / options.full_scale_mm, 2);
  // Ra = w^2 / (2 s): a bow d of the section's depth changes Ra by -Ra / s * d.
  const double ra_per_depth = ra / sagitta_mm;
  // An axial scale error e stretches the chord: Ra ~ w^2 / (2 s) grows by 2 e Ra.
  const double axial_ppm = options.axial_error_um / (2.0 * geometry.band_half_width_mm * 1e3) * 1e6;
  // A beam offset b reads sqrt(R^2 - b^2): the section's curvature grows by b^2 / (2 Rw^2) of itself.
  const double beam_mm = ra * options.beam_offset_mm * options.beam_offset_mm /
                         (2.0 * geometry.wheel_radius_mm * geometry.wheel_radius_mm);
  const double half_step_um = options.resolution_um / 2.0;

  const std::string scale_source = "sensor gain after calibration, +-" + ShowSignificant(options.scale_ppm) +
                                   " ppm (assumed; replace with the calibration certificate)";
  const std::string linearity_source = "sensor non-linearity +-" + ShowSignificant(options.linearity_um) +
                                       " um over " + ShowSignificant(options.full_scale_mm) +
                                       " mm (LK-H020 data sheet), its bow over the band's " +
                                       ShowFixed(sagitta_mm, 3) + " mm depth";
  const std::string resolution_source =
      "sensor resolution " + ShowSignificant(options.resolution_um) + " um (data sheet), +- half a step";
  const std::string axial_source = "axial (Y) axis encoder, +-" + ShowSignificant(options.axial_error_um) +
                                   " um over the " + ShowSignificant(2.0 * geometry.band_half_width_mm) +
                                   " mm band";
  const std::string temperature_source =
      "wheel temperature +-" + ShowSignificant(options.temperature_k) + " K from 20 degC, expansion " +
      ShowSignificant(options.expansion_per_k * 1e6) + "e-6/K (steel core)";
  const std::string beam_source =
      "beam offset +-" + ShowSignificant(options.beam_offset_mm) + " mm from the axis after alignment";

  BudgetFile budget;
  budget.quantities[std::string(s::kMeanArcRadiusMm)] = {
      Rectangular("sensor_scale", scale_source, "ppm", options.scale_ppm, -ra * 1e-6),
      Rectangular("sensor_linearity", linearity_source, "um", bow_um, -ra_per_depth * 1e-3),
      Rectangular("axial_scale", axial_source, "ppm", axial_ppm, 2.0 * ra * 1e-6),
      Rectangular("wheel_temperature", temperature_source, "K", options.temperature_k,
                  options.expansion_per_k * ra),
      Rectangular("beam_offset", beam_source, "mm", beam_mm, 1.0)};
  budget.quantities[std::string(s::kArcRadiusRangeMm)] = {
      Rectangular("sensor_scale", scale_source, "ppm", options.scale_ppm, 1e-6, true),
      Rectangular("axial_scale", axial_source, "ppm", axial_ppm, 2e-6, true)};
  // The range over the mean: the scale errors cancel; its part from the data only.
  budget.quantities[std::string(s::kArcRadiusFluctuationPct)] = {};
  budget.quantities[std::string(s::kCenterAxialDeviationMm)] = {
      Rectangular("axial_scale", axial_source, "ppm", axial_ppm, 1e-6, true)};
  for (const std::string_view key : {s::kMaxArcErrorUm, s::kMaxRunoutUm, s::kMaxRoundnessUm}) {
    auto& inputs = budget.quantities[std::string(key)];
    inputs.push_back(Rectangular("sensor_scale", scale_source, "ppm", options.scale_ppm, 1e-6, true));
    if (key == s::kMaxArcErrorUm)
      inputs.push_back(Rectangular("sensor_linearity", linearity_source, "um", bow_um, 1.0));
    inputs.push_back(Rectangular("resolution", resolution_source, "um", half_step_um, 1.0));
  }
  return budget;
}

}  // namespace arcwheel::uncertainty
