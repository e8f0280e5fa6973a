#include "reports/regenerate_report.h"

#include <fmt/format.h>

#include <algorithm>

#include "reports/html_page.h"
#include "reports/pdf_flow.h"

namespace arcwheel::reports {
namespace {

using internal::kContentWidth_pt;
using internal::kLine_pt;

// The map as a heat map: plot::HeatMap holds [n_x, n_y], the grid map [n_y, n_x].
ReportFigure MapFigure(const ChainMap& map) {
  plot::HeatMap h;
  h.title = map.caption;
  h.x = {.label = "x (mm)"};
  h.y = {.label = "y (mm)"};
  h.n_x = map.x_mm.size();
  h.n_y = map.y_mm.size();
  h.x_nodes = map.x_mm;
  h.y_nodes = map.y_mm;
  h.values.resize(h.n_x * h.n_y);
  for (std::size_t j = 0; j < h.n_y; ++j)
    for (std::size_t i = 0; i < h.n_x; ++i) h.values[i * h.n_y + j] = map.values_um[j * h.n_x + i];
  h.colour_bar_label = "error (µm)";
  h.equal_aspect = true;
  return {.caption = map.caption, .figure = h, .height_over_width = 0.8};
}

std::vector<ReportFigure> MapFigures(const RegenerateReportContent& content) {
  std::vector<ReportFigure> figures;
  for (const ChainMap& map : content.maps) figures.push_back(MapFigure(map));
  return figures;
}

const std::vector<std::string> kRegenerationHeader = {"Quantity", "Previous", "Now", "Change"};

std::string RenderHtml(const RegenerateReportContent& content, const std::vector<ReportFigure>& figures) {
  using namespace internal;
  std::string html = HtmlPageStart(content.title);
  html += "<h2>Inputs</h2>\n" + KeyValueTable(content.provenance);
  for (const ChainStep& step : content.steps) {
    html += "<h2>" + Escape(step.title) + "</h2>\n<p>" + Escape(step.status) + "</p>\n" +
            KeyValueTable(step.rows);
  }
  if (!figures.empty()) {
    html += "<h2>Maps</h2>\n";
    for (std::size_t k = 0; k < figures.size(); ++k)
      html += FigureRowHtml({figures[k]}, fmt::format("m{}-", k));
  }
  html += "<h2>Since the previous regeneration</h2>\n";
  if (content.previous.empty()) {
    html += "<p>No previous regeneration given (--previous) or found beside this one.</p>\n";
  } else {
    html += "<p>" + Escape(content.previous) + "</p>\n" + Table(kRegenerationHeader, content.changes);
  }
  return html + HtmlPageEnd();
}

void RenderPdf(const RegenerateReportContent& content, const std::vector<ReportFigure>& figures,
               const std::filesystem::path& path) {
  internal::PdfFlow pdf(path, content.title);
  pdf.SetMetadata(content.title);
  pdf.Title(content.title);
  const std::vector<double> key_value = {0.32 * kContentWidth_pt, 0.68 * kContentWidth_pt};
  pdf.Heading("Inputs", 3 * kLine_pt);
  for (const KeyValue& row : content.provenance) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  for (const ChainStep& step : content.steps) {
    pdf.Heading(step.title, 3 * kLine_pt);
    pdf.Paragraph(step.status);
    for (const KeyValue& row : step.rows) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  }
  for (const ReportFigure& figure : figures) pdf.Figure(figure);
  pdf.Heading("Since the previous regeneration", 3 * kLine_pt);
  if (content.previous.empty()) {
    pdf.Paragraph("No previous regeneration given (--previous) or found beside this one.");
  } else {
    pdf.Paragraph(content.previous);
    const std::vector<double> widths(4, 0.25 * kContentWidth_pt);
    pdf.Row({{kRegenerationHeader[0], {}},
             {kRegenerationHeader[1], {}},
             {kRegenerationHeader[2], {}},
             {kRegenerationHeader[3], {}}},
            widths, true);
    for (const std::vector<std::string>& row : content.changes)
      pdf.Row({{row[0], {}}, {row[1], {}}, {row[2], {}}, {row[3], {}}}, widths, false);
  }
  pdf.Finish();
}

}  // namespace

WrittenRegenerateReport WriteRegenerateReport(const RegenerateReportContent& content,
                                              const std::filesystem::path& outdir) {
  const std::vector<ReportFigure> figures = MapFigures(content);
  WrittenRegenerateReport written{outdir / "regenerate_report.html", outdir / "regenerate_report.pdf"};
  internal::WriteHtmlAndPdf(
      written.html, [&] { return RenderHtml(content, figures); }, written.pdf,
      [&](const std::filesystem::path& pdf) { RenderPdf(content, figures, pdf); });
  return written;
}

}  // namespace arcwheel::reports
