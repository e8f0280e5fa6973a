#pragma once
// What a wheel report says, independent of its format: the HTML and PDF renderers
// (reports/report.h) lay out the same ReportContent.

#include <string>
#include <vector>

#include "reports/format.h"
#include "reports/plot.h"
#include "reports/tolerances.h"

namespace arcwheel::reports {

struct ReportInputs;  // reports/report_inputs.h

struct KeyValue {
  std::string key;
  std::string value;
};

// One row of the headline table (the decision block). Numbers are shown at fixed precision
// (reports/format.h): lengths in mm with 4 decimals (0.1 um; the mean arc radius and its sigma
// with 5), um values with 2, percentages with 3. A number that could not be computed shows as
// "n/a".
struct HeadlineRow {
  std::string key;    // summary.json key, e.g. "max_runout_um"
  std::string label;  // e.g. "Max runout in the band"
  std::string value;  // e.g. "7.13 µm"
  // The uncertainty with its meaning, e.g. "± 0.00021 mm (σ of the mean)" or "phase-to-phase σ
  // 0.0021 mm"; "" when the summary has none.
  std::string uncertainty;
  // For a peak-to-valley figure, the part that noise alone explains, e.g. "≈ 0.50 µm from noise
  // (expected PV of 360 values of 1σ 0.08 µm)"; "" for other rows.
  std::string noise;
  std::string note;       // a caveat shown with the row (runout: wheel plus spindle), or ""
  std::string tolerance;  // e.g. "≤ 10 µm", or "–" without one
  Verdict verdict = Verdict::kNoTolerance;
};

struct ReportFigure {
  std::string caption;
  plot::Figure figure;
  double height_over_width = 0.45;  // aspect ratio the renderers keep
};

// The wheel model's part of the report (docs/wheel_model.md): a table and the harmonics of Ra(c);
// its curves are drawn into ReportContent::figures. Numbers at fixed precision: mm as the
// headline table (5 decimals for the mean radius, 4 for the range), um with 2 (3 for the residual
// RMS and the noise, as the provenance prints the noise), degrees with 1, chi-square with 1.
struct ModelReport {
  bool shown = false;
  std::string note;            // when not shown: one line saying why
  std::vector<KeyValue> rows;  // mean radius, range, "radius varies", knots, residual, profile PV
  std::vector<std::vector<std::string>> harmonics;  // order, amplitude ± 1σ, phase ± 1σ
};

struct ReportContent {
  std::string title;                  // "Wheel inspection report: WHEEL-ID"
  std::vector<KeyValue> provenance;   // wheel, scan settings, input file and SHA-256, versions
  std::vector<HeadlineRow> headline;  // in kHeadlineKeys order
  // kFail if any row fails, else kNotProven if any is not proven, else kPass if some pass.
  Verdict overall = Verdict::kNoTolerance;
  // The failing rows, each "label: value (limit ...)", in headline order.
  std::vector<std::string> failing;
  // The rows neither proven to conform nor not to, each "label: U = ... (limit ...)".
  std::vector<std::string> not_proven;
  // Which rule decided, e.g. "Decision rule: ISO 14253-1:2017 default rule (...), the default."
  std::string rule;
  ModelReport model;
  std::vector<ReportFigure> figures;
  std::vector<KeyValue> processing;  // summary.json "processing", flattened to dotted keys
  std::vector<std::string> warnings;
};

// Builds the report from the two inputs and the tolerances. No I/O; the provenance's report date
// is the current time (UTC).
[[nodiscard]] ReportContent ComposeReport(const ReportInputs& inputs, const Tolerances& tolerances);

// A JSON object's leaves as dotted keys ("despike.threshold_um"), each value as FormatJsonValue
// (reports/format.h) writes it: strings unquoted, integers whole, other numbers at six
// significant digits.
[[nodiscard]] std::vector<KeyValue> FlattenJson(const nlohmann::json& object);

// "PASS", "FAIL" or "NO TOLERANCE".
[[nodiscard]] std::string VerdictText(Verdict verdict);

// `value` with `decimals` decimals, or "n/a" when not finite; a hyphen for a minus sign. Kept for
// callers that need plain ASCII; the reports print through reports/format.h.
[[nodiscard]] std::string FormatNumber(double value, int decimals);

// FormatFixed (reports/format.h): "−" (U+2212) for a minus sign, as tables print it.
[[nodiscard]] std::string FormatSigned(double value, int decimals);

// Expected range (max − min) of n independent standard normal values (the control-chart constant
// d2(n)): 1.128 for 2, 3.078 for 10, 5.015 for 100. 0 for n < 2.
[[nodiscard]] double ExpectedNormalRange(std::size_t n);

// Geometric residuals |p - centre| - Ra, in um, of the section at map phase row `phase_index`
// against the circle (center_axial_mm, center_radial_mm, arc_radius_mm) of that phase, for the
// map's axial nodes inside [band_low_mm, band_high_mm]. NaN where the map has no value.
struct SectionResidual {
  std::vector<double> y_mm;
  std::vector<double> residual_um;
};
[[nodiscard]] SectionResidual SectionResiduals(const ReportInputs& inputs, std::size_t phase_index);

}  // namespace arcwheel::reports
