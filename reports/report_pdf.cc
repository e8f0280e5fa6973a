#include "reports/pdf_flow.h"
#include "reports/report.h"

namespace arcwheel::reports {

using internal::Cell;
using internal::kContentWidth_pt;
using internal::kLine_pt;
using internal::PdfFlow;

namespace {

void RenderModel(PdfFlow& pdf, const ModelReport& model) {
  pdf.Heading("Wheel model", model.shown ? 8 * kLine_pt : kLine_pt);
  if (!model.shown) return pdf.Paragraph(model.note);
  const std::vector<double> key_value = {0.32 * kContentWidth_pt, 0.68 * kContentWidth_pt};
  for (const KeyValue& row : model.rows) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Space(4.0);
  if (model.harmonics.empty())
    return pdf.Paragraph("Radius harmonics: none (Ra(c) is modelled as a constant).");
  const std::vector<double> columns = {0.32 * kContentWidth_pt, 0.34 * kContentWidth_pt,
                                       0.34 * kContentWidth_pt};
  pdf.Row({{"Radius harmonic of Ra(c): order", {}}, {"Amplitude", {}}, {"Phase", {}}}, columns, true);
  for (const std::vector<std::string>& row : model.harmonics)
    pdf.Row({{row[0], {}}, {row[1], {}}, {row[2], {}}}, columns, false);
}

}  // namespace

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
  RenderModel(pdf, content.model);
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
