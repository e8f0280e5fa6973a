#include "reports/pdf_flow.h"
#include "reports/report.h"

namespace arcwheel::reports {

using internal::Cell;
using internal::kContentWidth_pt;
using internal::kLine_pt;
using internal::PdfFlow;

void RenderPdf(const ReportContent& content, const std::filesystem::path& path) {
  PdfFlow pdf(path, content.title);
  pdf.SetMetadata(content.title);
  pdf.Title(content.title);
  pdf.Heading("Scan and provenance", 3 * kLine_pt);
  const std::vector<double> key_value = {0.32 * kContentWidth_pt, 0.68 * kContentWidth_pt};
  for (const KeyValue& row : content.provenance) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Heading("Headline numbers", 10 * kLine_pt);
  pdf.Paragraph("Overall: " + VerdictText(content.overall), content.overall);
  pdf.Space(3.0);
  const std::vector<double> headline = {0.40 * kContentWidth_pt, 0.25 * kContentWidth_pt,
                                        0.20 * kContentWidth_pt, 0.15 * kContentWidth_pt};
  pdf.Row({{"Quantity", {}}, {"Value", {}}, {"Tolerance", {}}, {"Result", {}}}, headline, true);
  for (const HeadlineRow& row : content.headline) {
    pdf.Row({{row.label, {}}, {row.value, {}}, {row.tolerance, {}}, {VerdictText(row.verdict), row.verdict}},
            headline, false);
  }
  const double first_figure_pt =
      content.figures.empty() ? 0.0
                              : kContentWidth_pt * content.figures.front().height_over_width + 3.0 * kLine_pt;
  pdf.Heading("Plots", first_figure_pt);
  for (const ReportFigure& figure : content.figures) pdf.Figure(figure);
  pdf.Heading("Warnings", kLine_pt);
  if (content.warnings.empty()) pdf.Paragraph("None.");
  for (const std::string& warning : content.warnings) pdf.Paragraph("• " + warning);
  pdf.Heading("Processing parameters", kLine_pt);
  if (content.processing.empty()) pdf.Paragraph("None recorded.");
  for (const KeyValue& row : content.processing) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Finish();
}

}  // namespace arcwheel::reports
