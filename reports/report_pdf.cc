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

std::string DecisionLine(const ReportContent& content) {
  if (content.overall == Verdict::kFail) {
    std::string text = "Failing: ";
    for (std::size_t i = 0; i < content.failing.size(); ++i)
      text += (i == 0 ? "" : "; ") + content.failing[i];
    return text + ". " + content.rule;
  }
  if (content.overall == Verdict::kNotProven) {
    std::string text = "Not proven: ";
    for (std::size_t i = 0; i < content.not_proven.size(); ++i)
      text += (i == 0 ? "" : "; ") + content.not_proven[i];
    return text + ". " + content.rule;
  }
  if (content.overall == Verdict::kPass) return "Every limit given holds. " + content.rule;
  return "No limits given: nothing was judged (arcwheel report --tolerance KEY=MAX).";
}

// The decision block: verdict, the failing rows, the headline table with uncertainties, the
// noise's share and the limits.
void RenderDecision(PdfFlow& pdf, const ReportContent& content) {
  pdf.Banner("Overall: " + VerdictText(content.overall), content.overall);
  pdf.Paragraph(DecisionLine(content));
  pdf.Space(3.0);
  const std::vector<double> widths = {0.21 * kContentWidth_pt, 0.13 * kContentWidth_pt,
                                      0.23 * kContentWidth_pt, 0.23 * kContentWidth_pt,
                                      0.11 * kContentWidth_pt, 0.09 * kContentWidth_pt};
  pdf.TableHeader({{"Quantity", {}},
                   {"Value", {}},
                   {"Uncertainty (meaning)", {}},
                   {"Noise alone (part of the PV)", {}},
                   {"Limit", {}},
                   {"Result", {}}},
                  widths);
  for (const HeadlineRow& row : content.headline) {
    const bool judged = row.verdict != Verdict::kNoTolerance;
    pdf.Row({{row.label + (row.note.empty() ? "" : ". " + row.note), {}},
             {row.value, {}},
             {row.uncertainty, {}},
             {row.noise, {}},
             {row.tolerance, {}},
             {judged ? VerdictText(row.verdict) : "", judged ? std::optional(row.verdict) : std::nullopt}},
            widths, false);
  }
  pdf.EndTable();
}

void Layout(PdfFlow& pdf, const ReportContent& content) {
  pdf.SetMetadata(content.title);
  pdf.Title(content.title);
  RenderDecision(pdf, content);
  pdf.Heading("Scan and provenance", 3 * kLine_pt);
  const std::vector<double> key_value = {0.32 * kContentWidth_pt, 0.68 * kContentWidth_pt};
  for (const KeyValue& row : content.provenance) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
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
  if (!content.processing.empty()) pdf.TableHeader({{"Parameter", {}}, {"Value", {}}}, key_value);
  for (const KeyValue& row : content.processing) pdf.Row({{row.key, {}}, {row.value, {}}}, key_value, false);
  pdf.Finish();
}

}  // namespace

void RenderPdf(const ReportContent& content, const std::filesystem::path& path) {
  internal::RenderPdfPages(path, content.title, [&](PdfFlow& pdf) { Layout(pdf, content); });
}

}  // namespace arcwheel::reports
