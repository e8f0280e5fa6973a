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

std::string HeadlineTable(const ReportContent& content) {
  std::string html = "<p>Overall: " + VerdictBadge(content.overall) + "</p>\n";
  html +=
      "<div "
      "class=\"table-scroll\"><table>\n<tr><th>Quantity</th><th>Value</th><th>Tolerance</th><th>Result</th></"
      "tr>\n";
  for (const HeadlineRow& row : content.headline) {
    html += "<tr><td>" + Escape(row.label) + "</td><td class=\"number\">" + Escape(row.value) +
            "</td><td class=\"number\">" + Escape(row.tolerance) + "</td><td>" + VerdictBadge(row.verdict) +
            "</td></tr>\n";
  }
  return html + "</table></div>\n";
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
  html += "<h2>Scan and provenance</h2>\n" + KeyValueTable(content.provenance);
  html += "<h2>Headline numbers</h2>\n" + HeadlineTable(content);
  html += "<h2>Wheel model</h2>\n" + ModelSection(content.model);
  html += "<h2>Plots</h2>\n" + Figures(content);
  html += "<h2>Warnings</h2>\n" + Warnings(content.warnings);
  html += "<h2>Processing parameters</h2>\n";
  html += content.processing.empty() ? "<p>None recorded.</p>\n" : KeyValueTable(content.processing);
  return html + HtmlPageEnd();
}

}  // namespace arcwheel::reports
