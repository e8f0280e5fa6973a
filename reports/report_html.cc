#include <fmt/format.h>

#include "reports/html_page.h"
#include "reports/report.h"

namespace arcwheel::reports {
namespace {

using internal::Escape;
using internal::FigureHtml;
using internal::HtmlPageEnd;
using internal::HtmlPageStart;
using internal::KeyValueTable;
using internal::kFigureWidth_pt;
using internal::Table;

std::string VerdictClass(Verdict verdict) {
  return verdict == Verdict::kPass ? "pass" : verdict == Verdict::kFail ? "fail" : "none";
}

std::string VerdictBadge(Verdict verdict) {
  return "<span class=\"verdict " + VerdictClass(verdict) + "\">" + VerdictText(verdict) + "</span>";
}

std::string VerdictReasons(const ReportContent& content) {
  if (content.overall == Verdict::kFail) {
    std::string html = "<p class=\"failing\"><strong>Failing:</strong></p>\n<ul class=\"failing\">\n";
    for (const std::string& row : content.failing) html += "<li>" + Escape(row) + "</li>\n";
    return html + "</ul>\n<p>" + Escape(content.rule) + "</p>\n";
  }
  if (content.overall == Verdict::kNotProven) {
    std::string html = "<p class=\"failing\"><strong>Not proven:</strong></p>\n<ul class=\"failing\">\n";
    for (const std::string& row : content.not_proven) html += "<li>" + Escape(row) + "</li>\n";
    return html + "</ul>\n<p>" + Escape(content.rule) + "</p>\n";
  }
  if (content.overall == Verdict::kPass)
    return "<p>Every limit given holds.</p>\n<p>" + Escape(content.rule) + "</p>\n";
  return "<p>No limits given: nothing was judged (<code>arcwheel report --tolerance KEY=MAX</code>).</p>\n";
}

std::string Cell(const std::string& css_class, const std::string& label, const std::string& html) {
  return "<td class=\"" + css_class + "\" data-label=\"" + Escape(label) + "\">" + html + "</td>";
}

// The decision block: verdict, failing rows, and the headline table. On a phone the table
// reflows into one card per quantity (CSS), so that the Result stays on screen.
std::string DecisionBlock(const ReportContent& content) {
  std::string html = "<section class=\"decision\" id=\"decision\">\n";
  html += "<div class=\"banner " + VerdictClass(content.overall) +
          "\">Overall: " + VerdictText(content.overall) + "</div>\n" + VerdictReasons(content);
  html +=
      "<table class=\"headline\">\n<thead><tr><th>Quantity</th><th>Value</th><th>Uncertainty (meaning)</th>"
      "<th>Noise alone (part of the PV)</th><th>Limit</th><th>Result</th></tr></thead>\n<tbody>\n";
  for (const HeadlineRow& row : content.headline) {
    const bool judged = row.verdict != Verdict::kNoTolerance;
    html += "<tr>" +
            Cell("quantity", "Quantity",
                 Escape(row.label) +
                     (row.note.empty() ? "" : "<div class=\"note\">" + Escape(row.note) + "</div>")) +
            Cell("value detail", "Value", Escape(row.value)) +
            Cell("detail", "Uncertainty", Escape(row.uncertainty)) +
            Cell("detail", "Noise alone", Escape(row.noise)) +
            Cell("limit detail", "Limit", Escape(row.tolerance)) +
            Cell("result", "Result", judged ? VerdictBadge(row.verdict) : "") + "</tr>\n";
  }
  return html + "</tbody>\n</table>\n</section>\n";
}

std::string ModelSection(const ModelReport& model) {
  if (!model.shown) return "<p>" + Escape(model.note) + "</p>\n";
  std::string html = KeyValueTable(model.rows);
  html += "<h3>Radius harmonics of Ra(c)</h3>\n";
  if (model.harmonics.empty()) return html + "<p>None: Ra(c) is modelled as a constant.</p>\n";
  return html + Table({"Order", "Amplitude", "Phase"}, model.harmonics);
}

std::string Figures(const ReportContent& content) {
  std::string html;
  for (std::size_t i = 0; i < content.figures.size(); ++i) {
    html += FigureHtml(content.figures[i], kFigureWidth_pt, fmt::format("f{}-", i));
  }
  return html;
}

std::string Warnings(const std::vector<std::string>& warnings) {
  if (warnings.empty()) return "<p>None.</p>\n";
  std::string html = "<ul>\n";
  for (const std::string& warning : warnings) html += "<li>" + Escape(warning) + "</li>\n";
  return html + "</ul>\n";
}

}  // namespace

std::string RenderHtml(const ReportContent& content) {
  std::string html = HtmlPageStart(content.title);
  html += DecisionBlock(content);
  html += "<h2>Scan and provenance</h2>\n" + KeyValueTable(content.provenance);
  html += "<h2>Wheel model</h2>\n" + ModelSection(content.model);
  html += "<h2>Plots</h2>\n" + Figures(content);
  html += "<h2>Warnings</h2>\n" + Warnings(content.warnings);
  html += "<h2>Processing parameters</h2>\n";
  html += content.processing.empty() ? "<p>None recorded.</p>\n" : KeyValueTable(content.processing);
  return html + HtmlPageEnd();
}

}  // namespace arcwheel::reports
