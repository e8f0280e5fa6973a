#include "reports/polish_report.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <regex>

#include "core/version.h"
#include "reports/html_page.h"
#include "reports/pdf_flow.h"

namespace arcwheel::reports {
namespace {

using internal::kContentWidth_pt;
using internal::kLine_pt;
using internal::RowFigureWidthPt;

// "um" written as a unit in ASCII, as the path CSV's comments do, with the micro sign.
std::string MicroSign(const std::string& text) {
  return std::regex_replace(text, std::regex(R"(\bum\b)"), "µm");
}

// The "# key: value" comment of the path CSV that starts with `key`, or "not recorded".
std::string Comment(const PolishingPathTable& path, const std::string& key) {
  for (const std::string& line : path.comments) {
    if (line.rfind(key + ": ", 0) == 0) return MicroSign(line.substr(key.size() + 2));
  }
  return "not recorded";
}

std::vector<KeyValue> Provenance(const PolishReportInputs& in) {
  const PolishSummary& s = in.summary;
  std::vector<KeyValue> rows = {
      {"Job", s.job_name},
      {"Surface", Comment(in.path, "surface")},
      {"Aperture", Comment(in.path, "aperture")},
      {"Removal function", Comment(in.path, "removal function")},
      {"Error map", s.error_map_file.empty() ? "not recorded" : s.error_map_file},
      {"Output folder", in.sources.front().path.parent_path().string()},
  };
  for (const SourceFile& file : in.sources)
    rows.push_back({file.path.filename().string() + " SHA-256", file.sha256});
  rows.push_back({"Polished by", "arcwheel " + s.arcwheel_version});
  rows.push_back({"Report by", std::string("arcwheel ") + kVersion});
  return rows;
}

// A machine limit as the job gives it (shortest form), or "none" for 0 (not limited).
std::string Limit(double value, const char* unit) {
  return value > 0.0 ? FormatSignificant(value) + " " + unit : "none";
}

std::string SpeedLimits(const PolishSummary& s) {
  if (s.limit_min_speed_mm_s > 0.0)
    return "limits " + FormatSignificant(s.limit_min_speed_mm_s) + " … " +
           FormatSignificant(s.limit_max_speed_mm_s) + " mm/s";
  return "limit " + Limit(s.limit_max_speed_mm_s, "mm/s");
}

std::vector<KeyValue> PathRows(const PolishSummary& s) {
  return {
      {"Total dwell time", FormatDuration(s.total_time_s)},
      {"Path points", fmt::format("{} (rows of polishing_path.csv)", s.points)},
      {"Aperture nodes", fmt::format("{} (rows of residual_map.csv)", s.aperture_nodes)},
      {"TCP speed range", FormatFixed(s.min_speed_mm_s, 3) + " … " +
                              FormatValue(s.max_speed_mm_s, units::kSpeed_mm_per_s) + " (" + SpeedLimits(s) +
                              ")"},
      {"Largest acceleration", FormatValue(s.max_acceleration_mm_s2, units::kAcceleration_mm_per_s2) +
                                   " (limit " + Limit(s.limit_max_acceleration_mm_s2, "mm/s²") + ")"},
      {"Solver iterations", fmt::format("{} ({})", s.solver_iterations,
                                        s.solver_converged ? "converged" : "iteration limit reached")},
  };
}

// Height over width of a figure `width_pt` wide whose equal-aspect plot spans x_span by y_span:
// the plot area of reports/plot.cc (50 pt left, 18 top, 30 bottom, 80 right for the colour
// bar) sized to the data, so that little of the figure is left blank.
double MapRatio(double width_pt, double x_span, double y_span) {
  const double area_width = width_pt - 130.0;
  return std::clamp((area_width * y_span / x_span + 48.0) / width_pt, 0.4, 1.3);
}

plot::HeatMap ResidualHeatMap(const ResidualMap& map, const std::string& title,
                              const std::vector<double>& values, const std::string& colour_label) {
  plot::HeatMap heat;
  heat.title = title;
  heat.x.label = "x (mm)";
  heat.y.label = "y (mm)";
  heat.n_x = map.n_x();
  heat.n_y = map.n_y();
  heat.values = values;
  heat.x_nodes = map.x_mm;
  heat.y_nodes = map.y_mm;
  heat.colour_bar_label = colour_label;
  heat.equal_aspect = true;
  return heat;
}

// Grid extent of the residual map's cells, for the figure's aspect ratio.
double Span(const std::vector<double>& nodes) {
  return nodes.size() > 1 ? (nodes.back() - nodes.front()) * static_cast<double>(nodes.size()) /
                                static_cast<double>(nodes.size() - 1)
                          : 1.0;
}

std::vector<std::vector<ReportFigure>> MapRows(const ResidualMap& map) {
  // Target, removal and residual share one scale: the range of all three, so that colours compare
  // across them and the residual shows how much of the target is left.
  double low = INFINITY, high = -INFINITY;
  for (const std::vector<double>* values : {&map.target_um, &map.removal_um, &map.residual_um}) {
    for (double v : *values) {
      if (std::isfinite(v)) low = std::min(low, v), high = std::max(high, v);
    }
  }
  const double width = RowFigureWidthPt(2);
  // A residual of nm size is shown in nm on its own scale, so that its ticks read as whole numbers.
  double residual_low = INFINITY, residual_high = -INFINITY;
  for (double v : map.residual_um) {
    if (std::isfinite(v))
      residual_low = std::min(residual_low, v), residual_high = std::max(residual_high, v);
  }
  const bool in_nm = std::isfinite(residual_low) && residual_high - residual_low < 0.1;
  std::vector<double> residual_own = map.residual_um;
  if (in_nm) {
    for (double& v : residual_own) v *= 1000.0;
  }
  const double ratio = MapRatio(width, Span(map.x_mm), Span(map.y_mm));
  const std::string shared_label = "depth (µm)";
  auto shared = [&](const std::string& title, const std::vector<double>& values) {
    plot::HeatMap heat = ResidualHeatMap(map, title, values, shared_label);
    if (std::isfinite(low)) heat.colour_min = low, heat.colour_max = high;
    return heat;
  };
  return {
      {{fmt::format("Removal target: the error minus its minimum plus the uniform layer. Target, removal and "
                    "residual share one colour scale, {} … {} µm, the range of all three.",
                    FormatFixed(low, 3), FormatFixed(high, 3)),
        shared("Removal target (before)", map.target_um), ratio},
       {"Removal the dwell times are predicted to make, on the target's colour scale.",
        shared("Predicted removal", map.removal_um), ratio}},
      {{"Predicted residual (target minus removal) on the target's colour scale: what is left of it.",
        shared("Predicted residual (after)", map.residual_um), ratio},
       {"The same residual on its own scale (0.5 to 99.5 percentile) to show its shape; grey: no node.",
        ResidualHeatMap(map, "Predicted residual, own scale", residual_own,
                        in_nm ? "residual (nm)" : "residual (µm)"),
        ratio}}};
}

// The clear aperture's outline (centred on the part origin) when the job records it.
std::vector<plot::Series> ApertureOutline(const nlohmann::json& job) {
  const auto aperture = job.find("aperture");
  if (aperture == job.end() || !aperture->is_object()) return {};
  plot::Series outline{"aperture", {}, {}, {}, {}, {0.35, 0.35, 0.35}};
  outline.dashed = true;
  const auto diameter = aperture->find("diameter_mm");
  const auto size = aperture->find("size_mm");
  if (aperture->value("shape", "") == "circle" && diameter != aperture->end() && diameter->is_number()) {
    const double r = diameter->get<double>() / 2.0;
    for (int k = 0; k <= 180; ++k) {
      outline.x.push_back(r * std::cos(2.0 * M_PI * k / 180.0));
      outline.y.push_back(r * std::sin(2.0 * M_PI * k / 180.0));
    }
  } else if (size != aperture->end() && size->is_array() && size->size() == 2 && (*size)[0].is_number() &&
             (*size)[1].is_number()) {
    const double hx = (*size)[0].get<double>() / 2.0, hy = (*size)[1].get<double>() / 2.0;
    outline.x = {-hx, hx, hx, -hx, -hx};
    outline.y = {-hy, -hy, hy, hy, -hy};
  } else {
    return {};
  }
  return {outline};
}

std::vector<ReportFigure> PathMaps(const PolishReportInputs& in) {
  const PolishingPathTable& p = in.path;
  auto map = [&](const std::string& title, const std::vector<double>& values, const std::string& label) {
    plot::PathMap path;
    path.title = title;
    path.x.label = "x (mm)";
    path.y.label = "y (mm)";
    path.x_points = p.x_mm;
    path.y_points = p.y_mm;
    path.values = values;
    path.colour_bar_label = label;
    path.overlays = ApertureOutline(in.summary.job);
    return path;
  };
  const auto [x_low, x_high] = std::minmax_element(p.x_mm.begin(), p.x_mm.end());
  const auto [y_low, y_high] = std::minmax_element(p.y_mm.begin(), p.y_mm.end());
  const double x_span = std::max(*x_high - *x_low, 1e-9), y_span = std::max(*y_high - *y_low, 1e-9);
  const double ratio = MapRatio(RowFigureWidthPt(2), x_span, y_span);
  return {
      {"Tool path, each segment coloured by the TCP speed into its end point (colour range: 0.5 to 99.5 "
       "percentile); dashed: the clear aperture.",
       map("Path, coloured by speed", p.speed_mm_s, "speed (mm/s)"), ratio},
      {"The same path coloured by the dwell of each segment's end point, the time the tool takes over that "
       "segment (0.5 to 99.5 percentile).",
       map("Path, coloured by dwell", p.dwell_s, "dwell per point (s)"), ratio}};
}

ReportFigure SpeedPlot(const PolishReportInputs& in) {
  const PolishingPathTable& p = in.path;
  const PolishSummary& s = in.summary;
  plot::LinePlot plot;
  plot.title = "TCP speed along the path";
  plot.x.label = "path length (mm)";
  plot.y.label = "TCP speed (mm/s)";
  plot.series.push_back({"TCP speed", p.path_length_mm, p.speed_mm_s, {}, {}, plot::SeriesColour(0)});
  const std::vector<double> ends = {p.path_length_mm.front(), p.path_length_mm.back()};
  auto limit = [&](const std::string& label, double value, int colour) {
    plot::Series line{label, ends, {value, value}, {}, {}, plot::SeriesColour(colour)};
    line.dashed = true;
    plot.series.push_back(line);
  };
  std::string caption = "TCP speed into each point against the length of the path up to it";
  if (s.limit_max_speed_mm_s > 0.0)
    limit("max speed " + FormatSignificant(s.limit_max_speed_mm_s) + " mm/s", s.limit_max_speed_mm_s, 1);
  if (s.limit_min_speed_mm_s > 0.0)
    limit("min speed " + FormatSignificant(s.limit_min_speed_mm_s) + " mm/s", s.limit_min_speed_mm_s, 2);
  caption += s.limit_max_speed_mm_s > 0.0 ? "; dashed: the machine's speed limits from the job." : ".";
  return {caption, plot, 0.42};
}

// Joints 1 - 6 along the path against their limits (the robot's solution, robot_joints.csv), in
// two rows of three.
std::vector<std::vector<ReportFigure>> JointRows(const PolishReportInputs& in) {
  const PolishSummary& s = in.summary;
  const RobotJointsTable& t = in.robot_joints;
  std::vector<std::vector<ReportFigure>> rows(2);
  for (std::size_t i = 0; i < 6; ++i) {
    plot::LinePlot plot;
    plot.title = fmt::format("Joint {}", i + 1);
    plot.x.label = "target";
    plot.y.label = fmt::format("joint {} (deg)", i + 1);
    plot.series.push_back({"angle", t.target, t.joint_deg[i], {}, {}, plot::SeriesColour(0)});
    const std::vector<double> ends = {t.target.front(), t.target.back()};
    for (const double limit : s.robot_limits_deg[i]) {
      plot::Series line{"limit", ends, {limit, limit}, {}, {}, plot::SeriesColour(5)};
      line.dashed = true;
      plot.series.push_back(line);
    }
    const std::string caption =
        i == 0 ? fmt::format(
                     "Joint angles of the {} at each target (cfx {}); dashed: the joint's limits. "
                     "Smallest margin to a limit: joint 1 {:.1f} deg.",
                     s.robot_model, s.robot_cfx, s.robot_min_limit_margin_deg[i])
               : fmt::format(
                     "Smallest margin to a limit: {:.1f} deg{}.", s.robot_min_limit_margin_deg[i],
                     i == 4 ? fmt::format("; smallest |joint 5| {:.1f} deg", s.robot_wrist_margin_deg) : "");
    rows[i / 3].push_back({caption, plot, 0.75});
  }
  return rows;
}

// Which segments were slowed for the joints and what that cost, or "none".
std::string SlowedText(const PolishSummary& s) {
  if (s.robot_slowed_targets.empty()) return "none: every joint runs the dwell's speeds";
  constexpr std::size_t kListed = 8;
  std::vector<std::string> listed;
  for (std::size_t n = 0; n < std::min(kListed, s.robot_slowed_targets.size()); ++n)
    listed.push_back(fmt::format("{} (x{:.3g})", s.robot_slowed_targets[n], s.robot_slowed_factor[n]));
  if (s.robot_slowed_targets.size() > kListed) listed.push_back("...");
  return fmt::format(
      "{} segments slowed for the joints, into targets {}; {:.4g} s added, adding up to {:.4g} nm "
      "of removal (RMS {:.4g} nm) at ({:.1f}, {:.1f}) mm, in the prediction",
      s.robot_slowed_targets.size(), fmt::join(listed, ", "), s.robot_added_time_s, s.robot_added_max_nm,
      s.robot_added_rms_nm, s.robot_added_max_at_mm[0], s.robot_added_max_at_mm[1]);
}

}  // namespace

PolishReportContent ComposePolishReport(const PolishReportInputs& inputs) {
  const PolishSummary& s = inputs.summary;
  PolishReportContent content;
  content.title = "Polishing report: " + s.job_name;
  content.provenance = Provenance(inputs);
  // Each column in the unit its PV calls for: a residual of nm size in nm.
  content.form = {
      {"PV", FormatHeight(s.before_pv_um, s.before_pv_um), FormatHeight(s.after_pv_um, s.after_pv_um)},
      {"RMS (about the mean)", FormatHeight(s.before_rms_um, s.before_pv_um),
       FormatHeight(s.after_rms_um, s.after_pv_um)}};
  content.path = PathRows(s);
  content.figure_rows = MapRows(inputs.residual);
  content.figure_rows.push_back(PathMaps(inputs));
  content.figure_rows.push_back({SpeedPlot(inputs)});
  if (s.has_robot && inputs.robot_joints.size() > 0) {
    for (std::vector<ReportFigure>& row : JointRows(inputs)) content.figure_rows.push_back(std::move(row));
    content.path.push_back(
        {"Robot", fmt::format("{}, arm configuration cfx {}", s.robot_model, s.robot_cfx)});
    double margin = s.robot_min_limit_margin_deg[0], ratio = 0.0;
    for (std::size_t i = 0; i < 6; ++i) {
      margin = std::min(margin, s.robot_min_limit_margin_deg[i]);
      ratio = std::max(ratio, s.robot_max_speed_ratio[i]);
    }
    content.path.push_back(
        {"Robot margins", fmt::format("joint limits >= {:.1f} deg, |joint 5| >= {:.1f} deg, "
                                      "joint speeds <= {:.3f} of their maxima",
                                      margin, s.robot_wrist_margin_deg, ratio)});
    content.path.push_back({"Slowed segments", SlowedText(s)});
  }
  content.job = FlattenJson(s.job);
  return content;
}

std::string RenderPolishHtml(const PolishReportContent& content) {
  using namespace internal;
  std::string html = HtmlPageStart(content.title);
  html += "<h2>Job and sources</h2>\n" + KeyValueTable(content.provenance);
  html += "<h2>Form error over the aperture</h2>\n" +
          Table({"Quantity", "Before (error)", "After (predicted residual)"}, content.form);
  html += "<h2>Path and dwell</h2>\n" + KeyValueTable(content.path);
  html += "<h2>Plots</h2>\n";
  for (std::size_t r = 0; r < content.figure_rows.size(); ++r)
    html += FigureRowHtml(content.figure_rows[r], fmt::format("r{}-", r));
  html += "<h2>Job as used</h2>\n" + KeyValueTable(content.job);
  return html + HtmlPageEnd();
}

namespace {

void LayoutPolishPdf(internal::PdfFlow& pdf, const PolishReportContent& content) {
  pdf.SetMetadata(content.title);
  pdf.Title(content.title);
  const std::vector<double> key_value = {0.32 * kContentWidth_pt, 0.68 * kContentWidth_pt};
  pdf.Heading("Job and sources", 3 * kLine_pt);
  for (const KeyValue& row : content.provenance) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Heading("Form error over the aperture", 3 * kLine_pt);
  const std::vector<double> form = {0.32 * kContentWidth_pt, 0.34 * kContentWidth_pt,
                                    0.34 * kContentWidth_pt};
  pdf.TableHeader({{"Quantity", {}}, {"Before (error)", {}}, {"After (predicted residual)", {}}}, form);
  for (const std::vector<std::string>& row : content.form)
    pdf.Row({{row[0], {}}, {row[1], {}}, {row[2], {}}}, form, false);
  pdf.Heading("Path and dwell", 3 * kLine_pt);
  for (const KeyValue& row : content.path) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  const double first_row_pt = content.figure_rows.empty()
                                  ? 0.0
                                  : RowFigureWidthPt(content.figure_rows.front().size()) *
                                            content.figure_rows.front().front().height_over_width +
                                        3.0 * kLine_pt;
  pdf.Heading("Plots", first_row_pt);
  for (const std::vector<ReportFigure>& row : content.figure_rows) pdf.FigureRow(row);
  pdf.Heading("Job as used", 2 * kLine_pt);
  pdf.TableHeader({{"Job key", {}}, {"Value", {}}}, key_value);
  for (const KeyValue& row : content.job) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Finish();
}

}  // namespace

void RenderPolishPdf(const PolishReportContent& content, const std::filesystem::path& path) {
  internal::RenderPdfPages(path, content.title,
                           [&](internal::PdfFlow& pdf) { LayoutPolishPdf(pdf, content); });
}

WrittenPolishReports WritePolishReports(const std::filesystem::path& outdir) {
  const PolishReportContent content = ComposePolishReport(ReadPolishReportInputs(outdir));
  WrittenPolishReports written{outdir / "polish_report.html", outdir / "polish_report.pdf"};
  internal::WriteHtmlAndPdf(
      written.html, [&] { return RenderPolishHtml(content); }, written.pdf,
      [&](const std::filesystem::path& pdf) { RenderPolishPdf(content, pdf); });
  return written;
}

}  // namespace arcwheel::reports
