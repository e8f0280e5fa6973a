#include "reports/report_content.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <ctime>
#include <limits>
#include <numbers>

#include "characteristics/wheel_characteristics.h"
#include "core/error.h"
#include "core/nan.h"
#include "core/number_format.h"
#include "core/version.h"
#include "reports/report_inputs.h"
#include "reports/statistics.h"
#include "schema/summary.h"

namespace arcwheel::reports {
namespace {

using nlohmann::json;
namespace key = schema::summary;

struct HeadlineSpec {
  std::string_view key;
  const char* label;
  Unit unit;
};

// Same order as kHeadlineKeys.
constexpr std::array<HeadlineSpec, 7> kHeadline = {{
    {key::kMeanArcRadiusMm, "Mean arc radius", units::kRadius_mm},
    {key::kArcRadiusRangeMm, "Arc radius range (max − min)", units::kLength_mm},
    {key::kArcRadiusFluctuationPct, "Arc radius fluctuation (range / mean)", units::kPercent},
    {key::kCenterAxialDeviationMm, "Arc centre axial deviation (max − min)", units::kLength_mm},
    {key::kMaxArcErrorUm, "Max arc error in the band", units::kLength_um},
    {key::kMaxRunoutUm, "Max runout in the band", units::kLength_um},
    {key::kMaxRoundnessUm, "Max roundness in the band", units::kLength_um},
}};

double HeadlineValue(const Summary& s, std::string_view name) {
  if (name == key::kMeanArcRadiusMm) return s.mean_arc_radius_mm;
  if (name == key::kArcRadiusRangeMm) return s.arc_radius_range_mm;
  if (name == key::kArcRadiusFluctuationPct) return s.arc_radius_fluctuation_pct;
  if (name == key::kCenterAxialDeviationMm) return s.center_axial_deviation_mm;
  if (name == key::kMaxArcErrorUm) return s.max_arc_error_um;
  if (name == key::kMaxRunoutUm) return s.max_runout_um;
  return s.max_roundness_um;
}

// Limits are shown as given (at most seven significant digits, core/number_format.h), not rounded to the
// value's digits.
std::string LimitText(const Limit& limit, const HeadlineSpec& spec) {
  const std::string unit(spec.unit.symbol);
  if (limit.min && limit.max)
    return FormatSignificant(*limit.min) + " … " + FormatSignificant(*limit.max) + " " + unit;
  if (limit.max) return "≤ " + FormatSignificant(*limit.max) + " " + unit;
  return "≥ " + FormatSignificant(*limit.min) + " " + unit;
}

std::size_t UsableCount(const PhaseSeries& p) {
  return static_cast<std::size_t>(std::count(p.usable.begin(), p.usable.end(), true));
}

// "≈ X from noise (expected PV of n values of 1σ s)": what a peak-to-valley of n values would be
// if each held only its noise; "" when the noise is not recorded.
std::string NoisePv(std::size_t n, double sigma, Unit unit) {
  if (!std::isfinite(sigma) || n < 2) return "";
  return "≈ " + FormatValue(ExpectedNormalRange(n) * sigma, unit) + " from noise (expected PV of " +
         std::to_string(n) + " values of 1σ " + FormatFixed(sigma, unit.decimals + 1) + " " +
         std::string(unit.symbol) + ")";
}

// The per-axial-section point count of the arc fits, for the arc error's noise share.
std::size_t SectionPoints(const ReportInputs& inputs) {
  const double median = FiniteMedian(inputs.summary.phases.points_in_band);
  if (std::isfinite(median)) return static_cast<std::size_t>(median);
  std::size_t in_band = 0;
  for (double y : inputs.map.y_mm)
    in_band += y >= inputs.summary.band_low_mm && y <= inputs.summary.band_high_mm;
  return in_band;
}

// Uncertainty (with its meaning) and the noise's share of the row's figure.
void Explain(const ReportInputs& inputs, HeadlineRow& row) {
  const Summary& s = inputs.summary;
  const std::size_t phases = UsableCount(s.phases);
  const double map_sigma_um = s.map_sigma_um;
  const std::string map_sigma_text =
      std::isfinite(map_sigma_um)
          ? "map value 1σ " + FormatValue(map_sigma_um, units::kNoise_um) + " (median)"
          : "";
  if (row.key == key::kMeanArcRadiusMm) {
    row.uncertainty = "± " + FormatValue(s.mean_arc_radius_sigma_mm, units::kRadius_mm) + " (σ of the mean)";
    if (std::isfinite(s.arc_radius_std_mm))
      row.uncertainty += "; phase-to-phase σ " + FormatValue(s.arc_radius_std_mm, units::kLength_mm);
  } else if (row.key == key::kArcRadiusRangeMm || row.key == key::kArcRadiusFluctuationPct) {
    const bool pct = row.key == key::kArcRadiusFluctuationPct;
    const double to_unit = pct ? 100.0 / s.mean_arc_radius_mm : 1.0;
    const Unit unit = pct ? units::kPercent : units::kLength_mm;
    if (std::isfinite(s.arc_radius_std_mm))
      row.uncertainty = "phase-to-phase σ " + FormatValue(s.arc_radius_std_mm * to_unit, unit);
    if (std::isfinite(s.arc_radius_noise_std_mm) && !pct) {
      row.uncertainty += "; of it noise " + FormatValue(s.arc_radius_noise_std_mm, unit) + ", wheel " +
                         FormatValue(s.arc_radius_excess_std_mm, unit) + " (in quadrature)";
    }
    row.noise = NoisePv(phases, s.arc_radius_noise_std_mm * to_unit, unit);
    if (s.model && !pct) {
      row.noise += (row.noise.empty() ? "" : "; ") + std::string("wheel model, noise removed: ") +
                   FormatWithSigma(s.model->arc_radius_range_mm, s.model->arc_radius_range_sigma_mm, unit);
    }
  } else if (row.key == key::kCenterAxialDeviationMm) {
    const double sigma_mm = FiniteMedian(s.phases.center_axial_sigma_mm);
    if (std::isfinite(sigma_mm))
      row.uncertainty = "per-phase 1σ " + FormatValue(sigma_mm, units::kLength_mm) + " (median)";
    row.noise = NoisePv(phases, sigma_mm, units::kLength_mm);
  } else if (row.key == key::kMaxArcErrorUm) {
    row.uncertainty = map_sigma_text;
    row.noise = NoisePv(SectionPoints(inputs), map_sigma_um, units::kLength_um);
  } else {  // runout and roundness: a turn of map values at one axial node
    row.uncertainty = map_sigma_text;
    row.noise = NoisePv(inputs.map.n_phase(), map_sigma_um, units::kLength_um);
    if (row.key == key::kMaxRunoutUm)
      row.note = s.runout_note.empty() ? "" : "Caveat: " + s.runout_note + ".";
  }
}

using uncertainty::DecisionRule;

// The rule a tolerance file names; else ISO 14253-1 when the summary records uncertainties,
// simple acceptance when it does not (nothing else can be decided on).
DecisionRule RuleOf(const Summary& summary, const Tolerances& tolerances) {
  if (tolerances.rule) return *tolerances.rule;
  return summary.uncertainty.empty() ? DecisionRule::kSimpleAcceptance : DecisionRule::kIso14253;
}

Verdict VerdictOf(uncertainty::Decision decision) {
  return decision == uncertainty::Decision::kConforms         ? Verdict::kPass
         : decision == uncertainty::Decision::kDoesNotConform ? Verdict::kFail
                                                              : Verdict::kNotProven;
}

// A characteristic as `process` evaluated it: one value under its operator, its U, and the
// decision process made; a limit given to the report alone is decided here, on the same value and U.
HeadlineRow CharacteristicRow(HeadlineRow row, const Summary::Characteristic& c, const HeadlineSpec& spec,
                              const std::optional<Limit>& limit, DecisionRule rule) {
  row.value = FormatValue(c.value, spec.unit);
  row.uncertainty = "U = " + FormatValue(c.expanded, spec.unit) +
                    " (k = " + FormatFixed(c.coverage_factor, 2) + "); " + c.operator_text +
                    (c.where.empty() ? "" : ", " + c.where);
  row.noise.clear();
  if (!limit) {
    row.verdict = Verdict::kNoTolerance;
  } else if (!c.decision.empty()) {
    row.verdict = c.decision == "conforms"           ? Verdict::kPass
                  : c.decision == "does not conform" ? Verdict::kFail
                                                     : Verdict::kNotProven;
  } else {
    row.verdict = VerdictOf(
        uncertainty::Decide(c.value, c.expanded, {.min = limit->min, .max = limit->max}, {.rule = rule}));
  }
  return row;
}

std::vector<HeadlineRow> HeadlineRows(const ReportInputs& inputs, const Tolerances& tolerances) {
  std::vector<HeadlineRow> rows;
  for (const HeadlineSpec& spec : kHeadline) {
    HeadlineRow row;
    row.key = spec.key;
    row.label = spec.label;
    const double value = HeadlineValue(inputs.summary, spec.key);
    row.value = FormatValue(value, spec.unit);
    Explain(inputs, row);
    std::optional<Limit> limit;
    if (const auto it = tolerances.limits.find(row.key); it != tolerances.limits.end()) limit = it->second;
    row.tolerance = limit ? LimitText(*limit, spec) : "–";
    const DecisionRule rule = RuleOf(inputs.summary, tolerances);
    if (const auto c = inputs.summary.characteristics.find(row.key);
        c != inputs.summary.characteristics.end()) {
      rows.push_back(CharacteristicRow(std::move(row), c->second, spec, limit, rule));
      continue;
    }
    const auto u = inputs.summary.uncertainty.find(row.key);
    if (u != inputs.summary.uncertainty.end()) {
      // Value, U and k as the decision uses them (docs/uncertainty.md).
      const std::string expanded =
          "U = " + FormatValue(u->second.expanded, spec.unit) +
          " (k = " + FormatFixed(u->second.coverage_factor, 2) + ", " +
          FormatFixed(100.0 * inputs.summary.coverage_probability, 0) + " %) on " +
          FormatValue(u->second.value, spec.unit) +
          (row.key == key::kMeanArcRadiusMm ? std::string() : std::string(" noise-corrected"));
      row.uncertainty = expanded + (row.uncertainty.empty() ? "" : "; " + row.uncertainty);
    }
    if (!limit) {
      row.verdict = Verdict::kNoTolerance;
    } else if (u == inputs.summary.uncertainty.end()) {
      row.verdict = Judge(value, limit);
    } else {
      const uncertainty::Decision decision = uncertainty::Decide(
          u->second.value, u->second.expanded, {.min = limit->min, .max = limit->max}, {.rule = rule});
      row.verdict = decision == uncertainty::Decision::kConforms         ? Verdict::kPass
                    : decision == uncertainty::Decision::kDoesNotConform ? Verdict::kFail
                                                                         : Verdict::kNotProven;
    }
    rows.push_back(row);
  }
  return rows;
}

Verdict Overall(const std::vector<HeadlineRow>& rows) {
  Verdict overall = Verdict::kNoTolerance;
  for (const HeadlineRow& row : rows) {
    if (row.verdict == Verdict::kFail) return Verdict::kFail;
    if (row.verdict == Verdict::kNotProven) overall = Verdict::kNotProven;
    if (row.verdict == Verdict::kPass && overall == Verdict::kNoTolerance) overall = Verdict::kPass;
  }
  return overall;
}

std::vector<std::string> NotProvenRows(const std::vector<HeadlineRow>& rows) {
  std::vector<std::string> out;
  for (const HeadlineRow& row : rows) {
    if (row.verdict == Verdict::kNotProven)
      out.push_back(row.label + ": " + row.uncertainty.substr(0, row.uncertainty.find(';')) + " (limit " +
                    row.tolerance + ")");
  }
  return out;
}

std::vector<std::string> FailingRows(const std::vector<HeadlineRow>& rows) {
  std::vector<std::string> failing;
  for (const HeadlineRow& row : rows) {
    if (row.verdict == Verdict::kFail)
      failing.push_back(row.label + ": " + row.value +
                        (row.uncertainty.rfind("U = ", 0) == 0
                             ? "; " + row.uncertainty.substr(0, row.uncertainty.find(';'))
                             : std::string()) +
                        " (limit " + row.tolerance + ")");
  }
  return failing;
}

std::string UtcNow() {
  const std::time_t now = std::time(nullptr);
  std::tm utc{};
  gmtime_r(&now, &utc);
  char text[32];
  std::strftime(text, sizeof text, "%Y-%m-%d %H:%M UTC", &utc);
  return text;
}

std::string ScanText(const json& scan, std::string_view name) {
  const auto it = scan.find(name);
  if (it == scan.end() || it->is_null()) return "not recorded";
  if (it->is_string()) return it->get<std::string>().empty() ? "not recorded" : it->get<std::string>();
  return it->dump();
}

std::string ScanNumber(const json& scan, std::string_view name, Unit unit) {
  const auto it = scan.find(name);
  if (it == scan.end() || !it->is_number()) return "not recorded";
  return FormatValue(it->get<double>(), unit);
}

double ScanValue(const json& scan, std::string_view name) {
  const auto it = scan.find(name);
  return it == scan.end() || !it->is_number() ? kNaN : it->get<double>();
}

std::vector<KeyValue> Provenance(const ReportInputs& inputs) {
  const Summary& s = inputs.summary;
  const InputProvenance& in = s.input;
  const double valid_pct =
      in.samples > 0 ? 100.0 * static_cast<double>(in.valid_samples) / static_cast<double>(in.samples) : kNaN;
  std::string estimated = FormatValue(s.spindle_rpm_estimated, units::kSpeed_rpm);
  if (!s.spindle_rpm_source.empty()) estimated += " (used: " + s.spindle_rpm_source + ")";
  std::vector<KeyValue> rows = {
      {"Wheel id", ScanText(s.scan, key::scan::kWheelId)},
      {"Scan date/time", ScanText(s.scan, key::scan::kTimestamp)},
      {"Sensor", ScanText(s.scan, key::scan::kSensor)},
      {"Wheel diameter × width", ScanNumber(s.scan, key::scan::kWheelDiameterMm, {"mm", 1}) + " × " +
                                     ScanNumber(s.scan, key::scan::kWheelWidthMm, {"mm", 1})},
      {"Operator", ScanText(s.scan, key::scan::kOperator)},
      {"Spindle speed, nominal", FormatValue(s.spindle_rpm_nominal, units::kSpeed_rpm)},
      {"Spindle speed, estimated", estimated},
      {"Feed", ScanNumber(s.scan, key::scan::kFeedMmPerMin, units::kFeed_mm_per_min)},
      {"Sample period", std::isfinite(ScanValue(s.scan, key::scan::kSamplePeriodS))
                            ? FormatDuration(ScanValue(s.scan, key::scan::kSamplePeriodS))
                            : "not recorded"},
      {"Samples", fmt::format("{}", in.samples)},
      {"Valid samples", fmt::format("{} ({} %)", in.valid_samples, FormatFixed(valid_pct, 2))},
      {"Despiked samples", fmt::format("{}", in.despiked_samples)},
      {"Band used (axial)", FormatFixed(s.band_low_mm, 3) + " … " + FormatFixed(s.band_high_mm, 3) +
                                " mm (half width " + FormatValue(s.band_half_width_mm, units::kPosition_mm) +
                                ")"},
      {"Map", fmt::format("{} phases × {} axial nodes", inputs.map.n_phase(), inputs.map.n_y())},
  };
  if (std::isfinite(s.noise_sigma_um))
    rows.push_back({"Measurement noise (1σ)", FormatValue(s.noise_sigma_um, units::kNoise_um)});
  if (std::isfinite(s.map_sigma_um))
    rows.push_back({"Map value noise (median 1σ)", FormatValue(s.map_sigma_um, units::kNoise_um)});
  rows.push_back({"Input file", in.path + (in.format.empty() ? "" : " (" + in.format + ")")});
  rows.push_back({"Input SHA-256", in.sha256});
  rows.push_back({"Processed by", "arcwheel " + s.arcwheel_version});
  rows.push_back({"Report by", std::string("arcwheel ") + kVersion});
  rows.push_back({"Report date", UtcNow()});
  // Left blank for the signature of whoever releases the wheel.
  rows.push_back({"Approved by (name, date)", "____________________________"});
  return rows;
}

void Flatten(const json& value, const std::string& prefix, std::vector<KeyValue>& out) {
  if (value.is_object() && !value.empty()) {
    for (const auto& [key, child] : value.items())
      Flatten(child, prefix.empty() ? key : prefix + "." + key, out);
    return;
  }
  out.push_back({prefix, FormatJsonValue(value)});
}

// Per-phase values with unusable phases blanked, so that plots show gaps instead of outliers.
std::vector<double> UsableOnly(const std::vector<double>& values, const std::vector<bool>& usable) {
  std::vector<double> out(values);
  for (std::size_t i = 0; i < out.size(); ++i) {
    if (!usable[i]) out[i] = kNaN;
  }
  return out;
}

double FiniteMean(const std::vector<double>& values) {
  double sum = 0.0;
  int count = 0;
  for (double v : values) {
    if (std::isfinite(v)) {
      sum += v;
      ++count;
    }
  }
  return count == 0 ? kNaN : sum / count;
}

plot::Axis FreeAxis(const std::string& label) {
  plot::Axis axis;
  axis.label = label;
  return axis;
}

const plot::Axis kPhaseAxis{"phase c (deg)", 0.0, 360.0};
const plot::Axis kAxialAxis = FreeAxis("axial position y (mm)");

ReportFigure FormErrorMap(const ReportInputs& inputs) {
  plot::HeatMap map;
  map.title = "Form error map (measured minus mean wheel)";
  map.x = FreeAxis("phase c (deg)");
  map.y = kAxialAxis;
  map.n_x = inputs.map.n_phase();
  map.n_y = inputs.map.n_y();
  map.values = inputs.map.form_error_um;
  map.x_nodes = inputs.map.phase_deg;
  map.y_nodes = inputs.map.y_mm;
  map.colour_bar_label = "form error (µm)";
  map.y_marks = {inputs.summary.band_low_mm, inputs.summary.band_high_mm};
  map.y_marks_label = "band";
  return {
      "Unwrapped form-error map: radial deviation of the wheel from the circle of mean radius and mean "
      "centre, by phase and axial position (colour range: 0.5 to 99.5 percentile; grey: no value; dashed: "
      "the band used for the fits).",
      map, 0.5};
}

ReportFigure RadiusPlot(const PhaseSeries& p) {
  plot::Series series{"arc radius Ra",      p.phase_deg, UsableOnly(p.arc_radius_mm, p.usable), {}, {},
                      plot::SeriesColour(0)};
  for (std::size_t i = 0; i < p.phase_deg.size(); ++i) {
    series.band_low.push_back(series.y[i] - p.arc_radius_sigma_mm[i]);
    series.band_high.push_back(series.y[i] + p.arc_radius_sigma_mm[i]);
  }
  plot::LinePlot plot{
      "Arc radius vs phase (shaded: ± 1σ)", kPhaseAxis, FreeAxis("arc radius Ra (mm)"), {series}, {}};
  return {"Arc radius of each axial section, with its 1-sigma band.", plot, 0.42};
}

// A model function as a line with its 1-sigma band, each value drawn as (value - offset) * scale.
plot::Series ModelSeries(const std::string& label, const std::vector<double>& x,
                         const std::vector<double>& value, const std::vector<double>& sigma, double offset,
                         double scale, plot::Rgb colour, bool dashed = false) {
  plot::Series series{label, x, {}, {}, {}, colour, false, dashed};
  for (std::size_t i = 0; i < x.size(); ++i) {
    series.y.push_back((value[i] - offset) * scale);
    series.band_low.push_back((value[i] - sigma[i] - offset) * scale);
    series.band_high.push_back((value[i] + sigma[i] - offset) * scale);
  }
  return series;
}

// With the model, the per-phase radii become dots (their 1-sigma band would hide the model's) and
// Ra(c) is drawn over them with its own band.
ReportFigure RadiusPlotWithModel(const PhaseSeries& p, const ModelCurves& model) {
  plot::Series per_phase{"per-phase fits",      p.phase_deg, UsableOnly(p.arc_radius_mm, p.usable), {}, {},
                         plot::SeriesColour(0), true};
  plot::LinePlot plot{"Arc radius vs phase: per-phase fits and the wheel model (shaded: ± 1σ)",
                      kPhaseAxis,
                      FreeAxis("arc radius Ra (mm)"),
                      {per_phase, ModelSeries("model Ra(c)", p.phase_deg, model.arc_radius_mm,
                                              model.arc_radius_sigma_mm, 0.0, 1.0, plot::SeriesColour(1))},
                      {}};
  const double median_sigma_um = FiniteMedian(UsableOnly(p.arc_radius_sigma_mm, p.usable)) * 1000.0;
  return {fmt::format("Arc radius of each axial section (dots; median 1σ {} µm), and the wheel model's Ra(c) "
                      "fitted to every sample, with its 1-sigma band.",
                      FormatFixed(median_sigma_um, 2)),
          plot, 0.42};
}

ReportFigure CentrePlot(const PhaseSeries& p, const ModelCurves* model) {
  auto deviation_um = [&p](const std::vector<double>& values) {
    std::vector<double> usable = UsableOnly(values, p.usable);
    const double mean = FiniteMean(usable);
    for (double& v : usable) v = (v - mean) * 1000.0;
    return std::pair{usable, mean};
  };
  const auto [axial, mean_axial] = deviation_um(p.center_axial_mm);
  const auto [radial, mean_radial] = deviation_um(p.center_radial_mm);
  if (model == nullptr) {
    plot::Series axial_series{"axial a − mean", p.phase_deg, axial, {}, {}, plot::SeriesColour(0)};
    plot::Series radial_series{"radial b − mean",     p.phase_deg, radial, {}, {},
                               plot::SeriesColour(1), false,       true};
    // Each phase's own 1-sigma as a band, so that motion within it reads as noise.
    auto add_band = [](plot::Series& series, const std::vector<double>& sigma_mm) {
      if (sigma_mm.size() != series.y.size()) return;
      for (std::size_t i = 0; i < sigma_mm.size(); ++i) {
        series.band_low.push_back(series.y[i] - sigma_mm[i] * 1000.0);
        series.band_high.push_back(series.y[i] + sigma_mm[i] * 1000.0);
      }
    };
    add_band(axial_series, p.center_axial_sigma_mm);
    add_band(radial_series, p.center_radial_sigma_mm);
    const bool banded = !axial_series.band_low.empty();
    plot::LinePlot plot{banded ? "Arc centre vs phase (deviation from its mean; shaded: ± 1σ)"
                               : "Arc centre vs phase (deviation from its mean)",
                        kPhaseAxis,
                        FreeAxis("centre deviation (µm)"),
                        {axial_series, radial_series},
                        {}};
    return {fmt::format("Arc centre position by phase: axial a (mean {} mm) and radial b (mean {} mm){}.",
                        FormatFixed(mean_axial, 4), FormatFixed(mean_radial, 4),
                        banded ? ", each with its per-phase 1-sigma band" : ""),
            plot, 0.42};
  }
  // The model's a(c) and b(c) against the same means, so that they lie over the per-phase points.
  const double axial_offset = std::isfinite(mean_axial) ? mean_axial : FiniteMean(model->center_axial_mm);
  const double radial_offset = std::isfinite(mean_radial) ? mean_radial : FiniteMean(model->center_radial_mm);
  plot::LinePlot plot{
      "Arc centre vs phase (deviation from the per-phase mean; shaded: model ± 1σ)",
      kPhaseAxis,
      FreeAxis("centre deviation (µm)"),
      {{"axial a, per phase", p.phase_deg, axial, {}, {}, plot::SeriesColour(0), true},
       {"radial b, per phase", p.phase_deg, radial, {}, {}, plot::SeriesColour(1), true},
       ModelSeries("model a(c)", p.phase_deg, model->center_axial_mm, model->center_axial_sigma_mm,
                   axial_offset, 1000.0, plot::SeriesColour(0)),
       ModelSeries("model b(c)", p.phase_deg, model->center_radial_mm, model->center_radial_sigma_mm,
                   radial_offset, 1000.0, plot::SeriesColour(1), true)},
      {}};
  return {
      fmt::format("Arc centre position by phase: axial a (per-phase mean {} mm) and radial b (per-phase mean "
                  "{} mm); dots: per-phase fits, lines: the wheel model with its 1-sigma band.",
                  FormatFixed(mean_axial, 4), FormatFixed(mean_radial, 4)),
      plot, 0.42};
}

ReportFigure ArcErrorPlot(const PhaseSeries& p) {
  plot::LinePlot plot{
      "Arc error vs phase",
      kPhaseAxis,
      FreeAxis("arc error, peak-to-valley (µm)"),
      {{"arc error", p.phase_deg, UsableOnly(p.arc_error_um, p.usable), {}, {}, plot::SeriesColour(2)}},
      {}};
  return {"Peak-to-valley of each section's residuals against its own fitted circle, inside the band.", plot,
          0.42};
}

ReportFigure RunoutPlot(const Summary& s) {
  plot::LinePlot plot{
      "Runout and roundness vs axial position",
      kAxialAxis,
      FreeAxis("runout, roundness (µm)"),
      {{"runout", s.axial.y_mm, s.axial.runout_um, {}, {}, plot::SeriesColour(0)},
       {"roundness", s.axial.y_mm, s.axial.roundness_um, {}, {}, plot::SeriesColour(1), false, true}},
      {{s.band_low_mm, s.band_high_mm, "band"}}};
  return {
      "Total indicated runout (max − min over a turn) and roundness (after removing the least-squares "
      "circle) at each axial node of the band.",
      plot, 0.42};
}

// Usable phases of largest and smallest arc radius; npos if none is usable.
std::pair<std::size_t, std::size_t> ExtremePhases(const PhaseSeries& p) {
  std::size_t largest = std::string::npos;
  std::size_t smallest = std::string::npos;
  for (std::size_t i = 0; i < p.arc_radius_mm.size(); ++i) {
    if (!p.usable[i] || !std::isfinite(p.arc_radius_mm[i])) continue;
    if (largest == std::string::npos || p.arc_radius_mm[i] > p.arc_radius_mm[largest]) largest = i;
    if (smallest == std::string::npos || p.arc_radius_mm[i] < p.arc_radius_mm[smallest]) smallest = i;
  }
  return {largest, smallest};
}

std::vector<ReportFigure> SectionFigures(const ReportInputs& inputs) {
  const PhaseSeries& p = inputs.summary.phases;
  const auto [largest, smallest] = ExtremePhases(p);
  if (largest == std::string::npos) return {};
  auto name = [&p](std::size_t k, const char* which) {
    return fmt::format("c = {} deg ({})", FormatFixed(p.phase_deg[k], 1), which);
  };
  const std::string large = name(largest, "largest Ra"), small = name(smallest, "smallest Ra");
  const SectionResidual r_large = SectionResiduals(inputs, largest);
  const SectionResidual r_small = SectionResiduals(inputs, smallest);
  plot::LinePlot residuals{
      "Section residuals against the fitted arc (magnified)",
      kAxialAxis,
      FreeAxis("residual |p − centre| − Ra (µm)"),
      {{large, r_large.y_mm, r_large.residual_um, {}, {}, plot::SeriesColour(0)},
       {small, r_small.y_mm, r_small.residual_um, {}, {}, plot::SeriesColour(1), false, true}},
      {}};
  // The sections themselves would lie on one curve at page scale; their residuals show the shape.
  return {
      {"Geometric residuals of the axial sections at the phases of largest and smallest arc radius against "
       "their own fitted arcs, inside the band, in micrometres.",
       residuals, 0.42}};
}

// The worst roundness section as `process`'s operator saw it (docs/characteristics.md): the
// map's turn at the node the characteristic names, filtered and associated again, its deviations
// from the reference circle drawn magnified about a base circle, with the zone's two circles; and
// the unfiltered turn's harmonic spectrum with the filter's cut-off. Empty without the
// characteristic, its node or a complete turn there.
std::vector<ReportFigure> RoundnessFigures(const ReportInputs& inputs) {
  const auto found = inputs.summary.characteristics.find(std::string(key::kMaxRoundnessUm));
  if (found == inputs.summary.characteristics.end() || !found->second.at_y_mm) return {};
  const Summary::Characteristic& c = found->second;
  const std::optional<characteristics::Association> association =
      characteristics::ParseAssociation(c.association);
  const WheelMapData& map = inputs.map;
  if (!association || map.n_phase() < 8 || map.n_y() == 0) return {};
  std::size_t node = 0;
  for (std::size_t j = 1; j < map.n_y(); ++j)
    if (std::abs(map.y_mm[j] - *c.at_y_mm) < std::abs(map.y_mm[node] - *c.at_y_mm)) node = j;
  // The radii about the spindle axis: the map's rho about the nominal radius (the deviations,
  // not the radius, make the plot: a wrong nominal moves them by (e / R)^2 of themselves).
  const json& scan = inputs.summary.scan;
  const double diameter_mm = scan.contains("wheel_diameter_mm") && scan["wheel_diameter_mm"].is_number()
                                 ? scan["wheel_diameter_mm"].get<double>()
                                 : 400.0;
  const double radius_mm = diameter_mm > 0.0 ? diameter_mm / 2.0 : 200.0;
  std::vector<double> turn(map.n_phase());
  for (std::size_t i = 0; i < map.n_phase(); ++i) turn[i] = radius_mm + map.rho_mm[i * map.n_y() + node];
  if (!std::all_of(turn.begin(), turn.end(), [](double r) { return std::isfinite(r); })) return {};
  characteristics::RoundnessSection section;
  try {
    section = characteristics::RoundnessSectionOf(map.phase_deg, turn,
                                                  {.cutoff_upr = c.cutoff_upr,
                                                   .cutoff_mm = std::nullopt,
                                                   .association = *association,
                                                   .parameter = "RONt"},
                                                  map.y_mm[node]);
  } catch (const Error&) {
    return {};  // the map's phases are not a closed profile the operator takes
  }
  const std::vector<double>& filtered = section.filtered_radius_mm;
  const characteristics::AssociatedCircle& ref = section.reference;
  // Deviations (um) from the reference circle, in the direction seen from its centre.
  const double base_um = 2.0 * std::max(section.ront_um, 1e-3);
  plot::PathMap polar;
  polar.title = fmt::format("Worst roundness section, y = {} mm: {} (magnified, base circle {} µm)",
                            FormatFixed(map.y_mm[node], 3), c.operator_text, FormatFixed(base_um, 2));
  polar.x = FreeAxis("x (µm, magnified)");
  polar.y = FreeAxis("y (µm, magnified)");
  polar.colour_bar_label = "deviation from the reference circle (µm)";
  for (std::size_t i = 0; i <= filtered.size(); ++i) {
    const std::size_t k = i % filtered.size();
    const double a = map.phase_deg[k] * std::numbers::pi / 180.0;
    const double x = filtered[k] * std::cos(a) - ref.center_x_mm,
                 y = filtered[k] * std::sin(a) - ref.center_y_mm;
    const double deviation_um = (std::hypot(x, y) - ref.radius_mm) * 1000.0;
    const double direction = std::atan2(y, x), shown = base_um + deviation_um;
    polar.x_points.push_back(shown * std::cos(direction));
    polar.y_points.push_back(shown * std::sin(direction));
    polar.values.push_back(deviation_um);
  }
  const auto circle = [&](double deviation_um, const std::string& label, plot::Rgb colour) {
    plot::Series series{label, {}, {}, {}, {}, colour, false, true};
    for (int k = 0; k <= 360; ++k) {
      const double a = k * std::numbers::pi / 180.0;
      series.x.push_back((base_um + deviation_um) * std::cos(a));
      series.y.push_back((base_um + deviation_um) * std::sin(a));
    }
    return series;
  };
  polar.overlays = {circle(0.0, "reference circle", plot::SeriesColour(0)),
                    circle(-section.ronv_um, "inner", plot::SeriesColour(1)),
                    circle(section.ronp_um, "outer", plot::SeriesColour(1))};
  std::vector<double> upr, amplitude;
  for (std::size_t k = 0; k < section.harmonic_amplitude_um.size(); ++k) {
    upr.push_back(static_cast<double>(k + 1));
    amplitude.push_back(section.harmonic_amplitude_um[k]);
  }
  plot::LinePlot spectrum{
      fmt::format("Harmonic spectrum of the worst roundness section, y = {} mm (unfiltered)",
                  FormatFixed(map.y_mm[node], 3)),
      FreeAxis("undulations per revolution (UPR)"),
      FreeAxis("amplitude (µm)"),
      {{"amplitude", upr, amplitude, {}, {}, plot::SeriesColour(2), true}},
      {}};
  if (c.cutoff_upr) {
    spectrum.x_marks = {*c.cutoff_upr};
    spectrum.x_marks_label = fmt::format("filter cut-off {} UPR", ShowSignificant(*c.cutoff_upr));
  }
  return {{fmt::format(
               "The map's turn at the node of the largest roundness, filtered and associated as the "
               "characteristic's operator says ({}); its RONt here {} µm before the noise's bias is taken "
               "off. Distances from the centre: a base circle of {} µm plus each point's deviation from "
               "the reference circle, so the form shows, not the radius. Dashed: the reference circle "
               "and the zone's inner and outer circles.",
               c.operator_text, FormatFixed(section.ront_um, 3), FormatFixed(base_um, 2)),
           polar, 1.0},
          {"Amplitude of each harmonic of the same turn before the filter (1 UPR is the eccentricity); the "
           "Gaussian filter passes half the amplitude at its cut-off.",
           spectrum, 0.42}};
}

ReportFigure ProfileErrorPlot(const ModelCurves& model) {
  plot::LinePlot plot{"Profile error p(u) common to all phases (shaded: ± 1σ)",
                      FreeAxis("distance from the arc centre u = y − a(c) (mm)"),
                      FreeAxis("profile error p (µm)"),
                      {ModelSeries("p(u)", model.profile_u_mm, model.profile_error_um,
                                   model.profile_error_sigma_um, 0.0, 1.0, plot::SeriesColour(1))},
                      {}};
  return {
      "The wheel model's profile error: the departure from an arc that every phase shares, held to zero "
      "mean, slope and curvature over the band (those belong to b, a and Ra), with its 1-sigma band.",
      plot, 0.42};
}

ReportFigure ModelResidualMap(const ReportInputs& inputs) {
  plot::HeatMap map;
  map.title = "Wheel model residual (measured minus model)";
  map.x = FreeAxis("phase c (deg)");
  // The model is fitted inside the band only; outside it every cell would be grey.
  map.y = kAxialAxis;
  if (inputs.summary.band_high_mm > inputs.summary.band_low_mm) {
    map.y.min = inputs.summary.band_low_mm;
    map.y.max = inputs.summary.band_high_mm;
  }
  map.n_x = inputs.map.n_phase();
  map.n_y = inputs.map.n_y();
  map.values = inputs.map.model->residual_um;
  map.x_nodes = inputs.map.phase_deg;
  map.y_nodes = inputs.map.y_mm;
  map.colour_bar_label = "model residual (µm)";
  return {
      "Mean residual of the samples in each map cell against the wheel model, inside the band (colour "
      "range: 0.5 to 99.5 percentile; grey: no sample). Grit texture and local damage stay here; a pattern "
      "that repeats over phases is profile or radius variation the model does not describe.",
      map, 0.5};
}

ReportFigure CoverageMap(const ReportInputs& inputs) {
  const WheelMapData& map = inputs.map;
  plot::CategoryMap coverage;
  coverage.title = "Coverage and despiking";
  coverage.x = FreeAxis("phase c (deg)");
  coverage.y = kAxialAxis;
  coverage.n_x = map.n_phase();
  coverage.n_y = map.n_y();
  coverage.x_nodes = map.phase_deg;
  coverage.y_nodes = map.y_mm;
  coverage.coarse_display = true;
  coverage.y_marks = {inputs.summary.band_low_mm, inputs.summary.band_high_mm};
  coverage.y_marks_label = "band";
  coverage.codes.resize(map.sample_count.size());
  std::size_t despiked_cells = 0, missing_cells = 0;
  double despiked_samples = 0.0;
  for (std::size_t i = 0; i < coverage.codes.size(); ++i) {
    const bool missing = !(map.sample_count[i] > 0.0) || !std::isfinite(map.rho_mm[i]);
    const bool despiked = map.despiked_count[i] > 0.0;
    coverage.codes[i] = missing ? 2 : (despiked ? 1 : 0);
    missing_cells += missing;
    despiked_cells += despiked && !missing;
    if (despiked && !missing) despiked_samples += map.despiked_count[i];
  }
  coverage.categories = {
      {"samples ok", {0.86, 0.90, 0.94}},
      {fmt::format("despiked: {} cells, {} samples", despiked_cells, FormatSignificant(despiked_samples)),
       {0.90, 0.62, 0.00}},
      {fmt::format("no valid sample: {} cells", missing_cells), {0.80, 0.10, 0.10}}};
  return {fmt::format(
              "Map cells by their raw samples: where samples were missing or replaced by despiking, enlarged "
              "to blocks of a few points so that a single cell shows (a block takes its worst cell). {} of "
              "{} cells hold despiked samples, {} hold no valid sample.",
              despiked_cells, coverage.codes.size(), missing_cells),
          coverage, 0.5};
}

std::string WithSigma(double value, double sigma, int decimals, const char* unit) {
  return FormatSigned(value, decimals) + " ± " + FormatFixed(sigma, decimals) + " " + unit;
}

// p-values below 0.001 as "p < 0.001": the test's decision needs no more digits.
std::string PValueText(double p_value) {
  if (std::isfinite(p_value) && p_value < 0.001) return "p < 0.001";
  return "p = " + FormatFixed(p_value, 3);
}

std::string VariesText(const ModelSummary& m) {
  return fmt::format("{} (χ² = {} with {} dof, {}; significance level {})",
                     m.variation_significant ? "yes" : "no", FormatFixed(m.variation_chi2, 1),
                     m.variation_dof, PValueText(m.variation_p_value),
                     FormatSignificant(m.significance_level));
}

std::string KnotsText(const ModelSummary& m) {
  auto knots = [](int count) { return count == 1 ? std::string("1 (constant)") : fmt::format("{}", count); };
  const std::string how = m.knots_chosen_by == "bic" ? "chosen by the Bayesian information criterion"
                          : m.knots_chosen_by == "given"
                              ? "as given (--model-knots, --model-axial-knots, --model-runout-knots)"
                              : "chosen by " + m.knots_chosen_by;
  return fmt::format("Ra(c) {}, a(c) {}, b(c) {} per turn; {}", knots(m.radius_knots), knots(m.axial_knots),
                     knots(m.runout_knots), how);
}

std::string ResidualText(const ModelSummary& m) {
  const double ratio = m.residual_rms_um / m.noise_sigma_um;
  return fmt::format("{} µm against a noise estimate of {} µm (ratio {})", FormatFixed(m.residual_rms_um, 3),
                     FormatFixed(m.noise_sigma_um, 3), FormatFixed(ratio, 2));
}

// One line on why a summary has no model, from what it records.
std::string NoModelNote(const Summary& s) {
  const auto setting = s.processing.find(key::processing::kModel);
  if (setting != s.processing.end() && *setting == "off")
    return "Wheel model: not fitted (processed with --no-model).";
  if (s.schema_version.empty() || s.schema_version == "1.0")
    return "Wheel model: not in this summary (schema " +
           (s.schema_version.empty() ? "1.0" : s.schema_version) + ", written before the model).";
  return "Wheel model: not in this summary (it could not be fitted; see Warnings).";
}

ModelReport ModelPart(const Summary& s) {
  ModelReport part;
  if (!s.model) {
    part.note = NoModelNote(s);
    return part;
  }
  const ModelSummary& m = *s.model;
  part.shown = true;
  part.rows = {
      {"Mean arc radius (± 1σ)", WithSigma(m.mean_arc_radius_mm, m.mean_arc_radius_sigma_mm, 5, "mm")},
      {"Arc radius range, max − min of Ra(c) (± 1σ)",
       WithSigma(m.arc_radius_range_mm, m.arc_radius_range_sigma_mm, 4, "mm") +
           (m.radius_knots == 1 ? " (Ra(c) fitted as a constant)" : "")},
      {"Radius varies with phase", VariesText(m)},
      {"Knots", KnotsText(m)},
      {"Residual RMS", ResidualText(m)},
      {"Profile error p(u), peak-to-valley", FormatFixed(m.profile_pv_um, 2) + " µm"},
  };
  for (const ModelHarmonic& h : m.radius_harmonics) {
    part.harmonics.push_back({fmt::format("{}", h.order),
                              WithSigma(h.amplitude_um, h.amplitude_sigma_um, 2, "µm"),
                              WithSigma(h.phase_deg, h.phase_sigma_deg, 1, "deg")});
  }
  return part;
}

}  // namespace

std::string FormatSigned(double value, int decimals) { return FormatFixed(value, decimals); }

double ExpectedNormalRange(std::size_t n) {
  if (n < 2) return 0.0;
  // E[max - min] = integral of 1 - F(x)^n - (1 - F(x))^n over x (F the normal CDF); the integrand
  // is below 1e-12 outside |x| < 12 for any n a report meets.
  constexpr double kStep = 1e-3;
  const double count = static_cast<double>(n);
  double sum = 0.0;
  for (double x = -12.0; x <= 12.0; x += kStep) {
    const double cdf = 0.5 * std::erfc(-x / std::sqrt(2.0));
    sum += 1.0 - std::pow(cdf, count) - std::pow(1.0 - cdf, count);
  }
  return sum * kStep;
}

std::string FormatNumber(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos) text = fmt::format("{:.{}f}", 0.0, decimals);
  return text;
}

std::string VerdictText(Verdict verdict) {
  switch (verdict) {
    case Verdict::kPass:
      return "PASS";
    case Verdict::kFail:
      return "FAIL";
    case Verdict::kNotProven:
      return "NOT PROVEN";
    default:
      return "NO TOLERANCE";
  }
}

SectionResidual SectionResiduals(const ReportInputs& inputs, std::size_t phase_index) {
  const PhaseSeries& p = inputs.summary.phases;
  const double a = p.center_axial_mm[phase_index], b = p.center_radial_mm[phase_index];
  const double radius = p.arc_radius_mm[phase_index];
  SectionResidual residual;
  for (std::size_t j = 0; j < inputs.map.n_y(); ++j) {
    const double y = inputs.map.y_mm[j];
    if (y < inputs.summary.band_low_mm || y > inputs.summary.band_high_mm) continue;
    const double rho = inputs.map.rho_mm[phase_index * inputs.map.n_y() + j];
    residual.y_mm.push_back(y);
    residual.residual_um.push_back((std::hypot(y - a, rho - b) - radius) * 1000.0);
  }
  return residual;
}

std::vector<KeyValue> FlattenJson(const nlohmann::json& object) {
  std::vector<KeyValue> rows;
  if (!object.empty()) Flatten(object, "", rows);
  return rows;
}

ReportContent ComposeReport(const ReportInputs& inputs, const Tolerances& tolerances) {
  const Summary& s = inputs.summary;
  ReportContent content;
  const std::string wheel = ScanText(s.scan, key::scan::kWheelId);
  content.title =
      "Wheel inspection report: " + (wheel == "not recorded" ? std::string("wheel id not recorded") : wheel);
  content.provenance = Provenance(inputs);
  content.headline = HeadlineRows(inputs, tolerances);
  content.overall = Overall(content.headline);
  content.failing = FailingRows(content.headline);
  content.not_proven = NotProvenRows(content.headline);
  const DecisionRule rule = RuleOf(s, tolerances);
  content.rule = std::string("Decision rule: ") + std::string(uncertainty::DecisionRuleTitle(rule)) +
                 (tolerances.rule         ? ", as the tolerance file names it."
                  : s.uncertainty.empty() ? ": the summary records no uncertainty."
                                          : ", the default.");
  content.model = ModelPart(s);
  // ReadReportInputs guarantees the map's /model when the summary has one.
  const ModelCurves* model = content.model.shown && inputs.map.model ? &*inputs.map.model : nullptr;
  content.figures = {FormErrorMap(inputs)};
  if (model != nullptr && !model->residual_um.empty()) content.figures.push_back(ModelResidualMap(inputs));
  content.figures.push_back(model != nullptr ? RadiusPlotWithModel(s.phases, *model) : RadiusPlot(s.phases));
  content.figures.push_back(CentrePlot(s.phases, model));
  if (model != nullptr) content.figures.push_back(ProfileErrorPlot(*model));
  content.figures.push_back(ArcErrorPlot(s.phases));
  content.figures.push_back(RunoutPlot(s));
  for (ReportFigure& figure : SectionFigures(inputs)) content.figures.push_back(std::move(figure));
  for (ReportFigure& figure : RoundnessFigures(inputs)) content.figures.push_back(std::move(figure));
  content.figures.push_back(CoverageMap(inputs));
  if (!s.processing.empty()) Flatten(s.processing, "", content.processing);
  // The warnings are texts of summary.json, which keeps every digit; the report shows seven.
  for (const std::string& warning : s.warnings) content.warnings.push_back(ShowNumbersIn(warning));
  return content;
}

}  // namespace arcwheel::reports
