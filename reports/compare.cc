#include "reports/compare.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/nan.h"
#include "reports/html_page.h"
#include "reports/pdf_flow.h"
#include "reports/statistics.h"
#include "schema/summary.h"

namespace arcwheel::reports {
namespace {

namespace key = schema::summary;
constexpr const char* kCompareStage = "reports.compare";

std::string WheelId(const Summary& s) {
  const auto it = s.scan.find(key::scan::kWheelId);
  return it != s.scan.end() && it->is_string() ? it->get<std::string>() : "";
}

std::string Timestamp(const Summary& s) {
  const auto it = s.scan.find(key::scan::kTimestamp);
  return it != s.scan.end() && it->is_string() ? it->get<std::string>() : "";
}

HeadlineChange Change(std::string name, std::string label, Unit unit, double before, double before_sigma,
                      double after, double after_sigma) {
  HeadlineChange c{std::move(name), std::move(label), unit, before, after, before_sigma, after_sigma};
  c.change = after - before;
  c.sigma = std::hypot(before_sigma, after_sigma);
  c.significant = std::isfinite(c.sigma) && std::abs(c.change) > kSignificanceSigmas * c.sigma;
  return c;
}

constexpr double kCoverageFactor95 = 1.959964;  // normal: the sigmas have many degrees of freedom

std::vector<HeadlineChange> Changes(const Summary& b, const Summary& a) {
  std::vector<HeadlineChange> changes = {
      Change(std::string(key::kMeanArcRadiusMm), "Mean arc radius", units::kRadius_mm, b.mean_arc_radius_mm,
             b.mean_arc_radius_sigma_mm, a.mean_arc_radius_mm, a.mean_arc_radius_sigma_mm),
      Change(std::string(key::kMeanCenterAxialMm), "Mean arc centre, axial", units::kLength_mm,
             b.mean_center_axial_mm, b.mean_center_axial_sigma_mm, a.mean_center_axial_mm,
             a.mean_center_axial_sigma_mm),
      Change(std::string(key::kArcRadiusRangeMm), "Arc radius range (max − min)", units::kLength_mm,
             b.arc_radius_range_mm, kNaN, a.arc_radius_range_mm, kNaN),
      Change(std::string(key::kArcRadiusFluctuationPct), "Arc radius fluctuation", units::kPercent,
             b.arc_radius_fluctuation_pct, kNaN, a.arc_radius_fluctuation_pct, kNaN),
      Change(std::string(key::kCenterAxialDeviationMm), "Arc centre axial deviation (max − min)",
             units::kLength_mm, b.center_axial_deviation_mm, kNaN, a.center_axial_deviation_mm, kNaN),
      Change(std::string(key::kMaxArcErrorUm), "Max arc error in the band", units::kLength_um,
             b.max_arc_error_um, kNaN, a.max_arc_error_um, kNaN),
      Change(std::string(key::kMaxRunoutUm), "Max runout in the band", units::kLength_um, b.max_runout_um,
             kNaN, a.max_runout_um, kNaN),
      Change(std::string(key::kMaxRoundnessUm), "Max roundness in the band", units::kLength_um,
             b.max_roundness_um, kNaN, a.max_roundness_um, kNaN),
  };
  // With uncertainties in both summaries, a peak-to-valley change is that of the noise-corrected
  // estimates, with the type A sigma of each (the same sensor's type B parts cancel).
  for (HeadlineChange& c : changes) {
    const auto before = b.uncertainty.find(c.key);
    const auto after = a.uncertainty.find(c.key);
    if (c.key == key::kMeanArcRadiusMm || before == b.uncertainty.end() || after == a.uncertainty.end())
      continue;
    c = Change(c.key, c.label + " (noise-corrected)", c.unit, before->second.value,
               before->second.type_a_uncertainty, after->second.value, after->second.type_a_uncertainty);
  }
  if (b.model && a.model) {
    changes.push_back(Change("model.mean_arc_radius_mm", "Wheel model: mean arc radius", units::kRadius_mm,
                             b.model->mean_arc_radius_mm, b.model->mean_arc_radius_sigma_mm,
                             a.model->mean_arc_radius_mm, a.model->mean_arc_radius_sigma_mm));
    changes.push_back(Change("model.arc_radius_range_mm", "Wheel model: range of Ra(c)", units::kLength_mm,
                             b.model->arc_radius_range_mm, b.model->arc_radius_range_sigma_mm,
                             a.model->arc_radius_range_mm, a.model->arc_radius_range_sigma_mm));
  }
  return changes;
}

// Index i with nodes[i] <= value <= nodes[i + 1], or npos outside.
std::size_t Bracket(const std::vector<double>& nodes, double value) {
  if (nodes.size() < 2 || value < nodes.front() || value > nodes.back()) return std::string::npos;
  const auto upper = std::upper_bound(nodes.begin(), nodes.end(), value);
  const auto i = static_cast<std::size_t>(std::distance(nodes.begin(), upper));
  return std::min(i == 0 ? 0 : i - 1, nodes.size() - 2);
}

MapDifference Difference(const WheelMapData& before, const WheelMapData& after, const std::string& where) {
  const double low = std::max(before.y_mm.front(), after.y_mm.front());
  const double high = std::min(before.y_mm.back(), after.y_mm.back());
  if (!(high > low)) {
    throw Error(ErrorCode::kBadInput, kCompareStage,
                fmt::format("{}: the two maps share no axial range (before {} … {} mm, after {} … {} mm)",
                            where, FormatFixed(before.y_mm.front(), 3), FormatFixed(before.y_mm.back(), 3),
                            FormatFixed(after.y_mm.front(), 3), FormatFixed(after.y_mm.back(), 3)));
  }
  auto step = [](const WheelMapData& m) {
    return (m.y_mm.back() - m.y_mm.front()) / static_cast<double>(m.n_y() - 1);
  };
  const double y_step = std::min(step(before), step(after));
  const auto n_y = static_cast<std::size_t>(std::floor((high - low) / y_step + 1e-9)) + 1;
  MapDifference d;
  d.phase_deg = before.phase_deg;
  for (std::size_t j = 0; j < n_y; ++j) d.y_mm.push_back(low + y_step * static_cast<double>(j));
  double sum_squares = 0.0;
  std::size_t count = 0;
  d.min_um = INFINITY;
  d.max_um = -INFINITY;
  for (const double c : d.phase_deg) {
    for (const double y : d.y_mm) {
      const double value = (InterpolateRho_mm(after, c, y) - InterpolateRho_mm(before, c, y)) * 1000.0;
      d.difference_um.push_back(value);
      if (!std::isfinite(value)) continue;
      sum_squares += value * value;
      ++count;
      d.min_um = std::min(d.min_um, value);
      d.max_um = std::max(d.max_um, value);
    }
  }
  d.median_um = FiniteMedian(d.difference_um);
  d.rms_um = count > 0 ? std::sqrt(sum_squares / static_cast<double>(count)) : kNaN;
  if (count == 0) d.min_um = d.max_um = kNaN;
  return d;
}

// ---- Rendering ----

std::vector<std::vector<std::string>> ChangeRows(const Comparison& c) {
  std::vector<std::vector<std::string>> rows;
  for (const HeadlineChange& h : c.changes) {
    const bool has_sigma = std::isfinite(h.sigma);
    auto with_sigma = [&h](double value, double sigma) {
      return std::isfinite(sigma) ? FormatWithSigma(value, sigma, h.unit) : FormatValue(value, h.unit);
    };
    std::string change =
        has_sigma ? FormatWithSigma(h.change, h.sigma, h.unit) : FormatValue(h.change, h.unit);
    // An explicit plus for a gain, unless the change rounds to zero.
    if (h.change > 0.0 && change.find_first_of("123456789") < change.find(' ')) change = "+" + change;
    std::string verdict = "no σ recorded";
    if (has_sigma) verdict = h.significant ? "yes (> 3σ)" : "no (≤ 3σ)";
    rows.push_back(
        {h.label, with_sigma(h.before, h.before_sigma), with_sigma(h.after, h.after_sigma), change, verdict});
  }
  return rows;
}

const std::vector<std::string> kChangeHeader = {"Quantity", "Before", "After", "Change (after − before) ± σ",
                                                "Significant"};

std::vector<KeyValue> Sources(const Comparison& c) {
  return {{"Wheel id", c.wheel_id.empty() ? "not recorded" : c.wheel_id},
          {"Before", c.before_dir.string() + " (scan " +
                         (c.before_timestamp.empty() ? "time not recorded" : c.before_timestamp) + ")"},
          {"After", c.after_dir.string() + " (scan " +
                        (c.after_timestamp.empty() ? "time not recorded" : c.after_timestamp) + ")"},
          {"Combined σ", "sqrt(σ_before² + σ_after²), each the summary's own 1σ"},
          {"Significant", "|change| > 3 combined σ"}};
}

std::vector<KeyValue> MapRows(const MapDifference& d) {
  return {{"Grid", fmt::format("{} phases × {} axial nodes, {} … {} mm", d.phase_deg.size(), d.y_mm.size(),
                               FormatFixed(d.y_mm.front(), 3), FormatFixed(d.y_mm.back(), 3))},
          {"Median difference", FormatValue(d.median_um, units::kLength_um)},
          {"RMS difference (about zero)", FormatValue(d.rms_um, units::kLength_um)},
          {"Range", FormatFixed(d.min_um, 2) + " … " + FormatValue(d.max_um, units::kLength_um)}};
}

ReportFigure DifferenceFigure(const Comparison& c) {
  plot::HeatMap map;
  map.title = "Radial map difference, after − before";
  map.x.label = "phase c (deg)";
  map.y.label = "axial position y (mm)";
  map.n_x = c.map.phase_deg.size();
  map.n_y = c.map.y_mm.size();
  map.values = c.map.difference_um;
  map.x_nodes = c.map.phase_deg;
  map.y_nodes = c.map.y_mm;
  map.colour_bar_label = "Δρ (µm)";
  map.y_marks = {c.band_low_mm, c.band_high_mm};
  map.y_marks_label = "band";
  return {
      "Difference of the radial maps ρ(c, y), after minus before, on the common grid (negative: the wheel "
      "lost material; colour range: 0.5 to 99.5 percentile; grey: no value in one of the maps).",
      map, 0.5};
}

std::string Title(const Comparison& c) {
  return "Scan comparison: " + (c.wheel_id.empty() ? std::string("wheel id not recorded") : c.wheel_id);
}

std::string RenderComparisonHtml(const Comparison& c) {
  using namespace internal;
  std::string html = HtmlPageStart(Title(c));
  html += "<h2>Headline changes</h2>\n" + Table(kChangeHeader, ChangeRows(c));
  html += "<h2>Map difference</h2>\n" + KeyValueTable(MapRows(c.map)) +
          FigureHtml(DifferenceFigure(c), kFigureWidth_pt, "d-");
  html += "<h2>Scans and rules</h2>\n" + KeyValueTable(Sources(c));
  return html + HtmlPageEnd();
}

void LayoutComparisonPdf(internal::PdfFlow& pdf, const Comparison& c) {
  using internal::kContentWidth_pt;
  using internal::kLine_pt;
  pdf.SetMetadata(Title(c));
  pdf.Title(Title(c));
  pdf.Heading("Headline changes", 3 * kLine_pt);
  const std::vector<double> widths = {0.26 * kContentWidth_pt, 0.19 * kContentWidth_pt,
                                      0.19 * kContentWidth_pt, 0.22 * kContentWidth_pt,
                                      0.14 * kContentWidth_pt};
  std::vector<internal::Cell> header;
  for (const std::string& text : kChangeHeader) header.push_back({text, {}});
  pdf.TableHeader(header, widths);
  for (const std::vector<std::string>& row : ChangeRows(c)) {
    std::vector<internal::Cell> cells;
    for (const std::string& text : row) cells.push_back({text, {}});
    pdf.Row(cells, widths, false);
  }
  const std::vector<double> key_value = {0.32 * kContentWidth_pt, 0.68 * kContentWidth_pt};
  pdf.Heading("Map difference", 6 * kLine_pt);
  for (const KeyValue& row : MapRows(c.map)) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Figure(DifferenceFigure(c));
  pdf.Heading("Scans and rules", 3 * kLine_pt);
  for (const KeyValue& row : Sources(c)) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Finish();
}

nlohmann::json Number(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

}  // namespace

double InterpolateRho_mm(const WheelMapData& source, double phase_deg, double y_mm) {
  const std::size_t j = Bracket(source.y_mm, y_mm);
  if (j == std::string::npos) return kNaN;
  const std::vector<double>& c = source.phase_deg;
  // Phase neighbours, with the wrap from the last node to the first plus 360 deg.
  const double wrapped = phase_deg - 360.0 * std::floor((phase_deg - c.front()) / 360.0);
  std::size_t i0 = Bracket(c, wrapped), i1 = i0 + 1;
  double c0 = 0.0, c1 = 0.0;
  if (i0 == std::string::npos) {
    i0 = c.size() - 1, i1 = 0;
    c0 = c.back(), c1 = c.front() + 360.0;
  } else {
    c0 = c[i0], c1 = c[i1];
  }
  const double u = (wrapped - c0) / (c1 - c0);
  const double v = (y_mm - source.y_mm[j]) / (source.y_mm[j + 1] - source.y_mm[j]);
  const std::size_t n_y = source.n_y();
  auto at = [&](std::size_t i, std::size_t jj) { return source.rho_mm[i * n_y + jj]; };
  return (1 - u) * ((1 - v) * at(i0, j) + v * at(i0, j + 1)) + u * ((1 - v) * at(i1, j) + v * at(i1, j + 1));
}

Comparison CompareScans(const ReportInputs& before, const ReportInputs& after) {
  const std::string before_id = WheelId(before.summary), after_id = WheelId(after.summary);
  if (!before_id.empty() && !after_id.empty() && before_id != after_id) {
    throw Error(ErrorCode::kBadInput, kCompareStage,
                fmt::format("'{}' key 'scan.wheel_id' = '{}' but '{}' has '{}': not the same wheel",
                            before.summary_path.string(), before_id, after.summary_path.string(), after_id));
  }
  Comparison c;
  c.before_dir = before.summary_path.parent_path();
  c.after_dir = after.summary_path.parent_path();
  c.wheel_id = before_id.empty() ? after_id : before_id;
  c.before_timestamp = Timestamp(before.summary);
  c.after_timestamp = Timestamp(after.summary);
  c.changes = Changes(before.summary, after.summary);
  c.map = Difference(before.map, after.map,
                     "'" + before.map_path.string() + "' and '" + after.map_path.string() + "'");
  c.band_low_mm = before.summary.band_low_mm;
  c.band_high_mm = before.summary.band_high_mm;
  return c;
}

nlohmann::json ComparisonJson(const Comparison& c) {
  nlohmann::json changes = nlohmann::json::array();
  for (const HeadlineChange& h : c.changes) {
    changes.push_back(
        {{"key", h.key},
         {"before", Number(h.before)},
         {"before_sigma", Number(h.before_sigma)},
         {"after", Number(h.after)},
         {"after_sigma", Number(h.after_sigma)},
         {"change", Number(h.change)},
         {"sigma", Number(h.sigma)},
         {"significant", std::isfinite(h.sigma) ? nlohmann::json(h.significant) : nlohmann::json(nullptr)},
         {"U", Number(kCoverageFactor95 * h.sigma)}});
  }
  return {{"wheel_id", c.wheel_id},
          {"before", {{"folder", c.before_dir.string()}, {"timestamp", c.before_timestamp}}},
          {"after", {{"folder", c.after_dir.string()}, {"timestamp", c.after_timestamp}}},
          {"sigma_rule", "sigma = sqrt(before_sigma^2 + after_sigma^2); null where a summary records none"},
          {"significance_rule", "significant when |change| > 3 sigma"},
          {"expanded_rule",
           "U = 1.96 sigma (95 %, normal); peak-to-valley changes are of the noise-corrected "
           "estimates with their type A sigmas when both summaries record uncertainties"},
          {"changes", changes},
          {"map_difference",
           {{"quantity", "rho after minus rho before, um"},
            {"n_phase", c.map.phase_deg.size()},
            {"n_y", c.map.y_mm.size()},
            {"y_min_mm", c.map.y_mm.front()},
            {"y_max_mm", c.map.y_mm.back()},
            {"median_um", Number(c.map.median_um)},
            {"rms_um", Number(c.map.rms_um)},
            {"min_um", Number(c.map.min_um)},
            {"max_um", Number(c.map.max_um)}}}};
}

WrittenComparison WriteComparison(const std::filesystem::path& before_dir,
                                  const std::filesystem::path& after_dir,
                                  const std::filesystem::path& outdir) {
  const ReportInputs before = ReadReportInputs(before_dir);
  const ReportInputs after = ReadReportInputs(after_dir);
  const Comparison comparison = CompareScans(before, after);
  WrittenComparison written{outdir / "compare.json", outdir / "compare.html", outdir / "compare.pdf"};
  OutputSet outputs;
  outputs.CreateFolder(outdir);
  const std::filesystem::path json_temporary = outputs.Stage(written.json);
  const std::filesystem::path html_temporary = outputs.Stage(written.html);
  const std::filesystem::path pdf_temporary = outputs.Stage(written.pdf);
  internal::RenderPdfPages(pdf_temporary, Title(comparison),
                           [&](internal::PdfFlow& pdf) { LayoutComparisonPdf(pdf, comparison); });
  WriteFileAtomically(html_temporary, RenderComparisonHtml(comparison));
  WriteFileAtomically(json_temporary, JsonText(ComparisonJson(comparison), 2) + "\n");
  outputs.Commit();
  return written;
}

}  // namespace arcwheel::reports
