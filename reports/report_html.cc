#include <fmt/format.h>

#include "reports/report.h"

namespace arcwheel::reports {
namespace {

// Plots are drawn at this width (points) and scaled by CSS to the screen or the printed page.
constexpr double kFigureWidth_pt = 640.0;

// Phone-first layout; print rules keep figures and tables whole on A4.
constexpr const char* kStyle = R"css(
:root { color-scheme: light; }
* { box-sizing: border-box; }
body { margin: 0 auto; padding: 12px; max-width: 980px; color: #222; background: #fff;
       font: 15px/1.45 "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; }
h1 { font-size: 1.35em; margin: 0.3em 0; }
h2 { font-size: 1.1em; margin: 1.2em 0 0.4em; border-bottom: 1px solid #ccc; }
table { border-collapse: collapse; width: 100%; margin: 0.3em 0; }
th, td { text-align: left; padding: 4px 6px; border-bottom: 1px solid #e4e4e4; vertical-align: top; }
td.value { overflow-wrap: anywhere; font-variant-numeric: tabular-nums; }
td.number { white-space: nowrap; font-variant-numeric: tabular-nums; }
.verdict { display: inline-block; padding: 0.15em 0.5em; font-size: 0.85em; border-radius: 4px; font-weight: bold; }
.pass { background: #d9f2dd; color: #0b5d1e; }
.fail { background: #fbd5d5; color: #8a1111; }
.none { background: #eee; color: #444; }
.table-scroll { overflow-x: auto; }
figure { margin: 0.8em 0; break-inside: avoid; page-break-inside: avoid; }
figure svg { display: block; width: 100%; height: auto; }
figcaption { font-size: 0.88em; color: #555; }
@media (max-width: 600px) { body { font-size: 14px; padding: 8px; } th, td { padding: 3px 4px; } }
@page { size: A4; margin: 14mm; }
@media print { body { max-width: none; padding: 0; font-size: 10pt; } h2 { break-after: avoid; } }
)css";

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string VerdictClass(Verdict verdict) {
  return verdict == Verdict::kPass ? "pass" : verdict == Verdict::kFail ? "fail" : "none";
}

std::string VerdictBadge(Verdict verdict) {
  return "<span class=\"verdict " + VerdictClass(verdict) + "\">" + VerdictText(verdict) + "</span>";
}

std::string KeyValueTable(const std::vector<KeyValue>& rows) {
  std::string html = "<div class=\"table-scroll\"><table>\n";
  for (const KeyValue& row : rows) {
    html += "<tr><th scope=\"row\">" + Escape(row.key) + "</th><td class=\"value\">" + Escape(row.value) + "</td></tr>\n";
  }
  return html + "</table></div>\n";
}

std::string HeadlineTable(const ReportContent& content) {
  std::string html = "<p>Overall: " + VerdictBadge(content.overall) + "</p>\n";
  html += "<div class=\"table-scroll\"><table>\n<tr><th>Quantity</th><th>Value</th><th>Tolerance</th><th>Result</th></tr>\n";
  for (const HeadlineRow& row : content.headline) {
    html += "<tr><td>" + Escape(row.label) + "</td><td class=\"number\">" + Escape(row.value) + "</td><td class=\"number\">" +
            Escape(row.tolerance) + "</td><td>" + VerdictBadge(row.verdict) + "</td></tr>\n";
  }
  return html + "</table></div>\n";
}

std::string Figures(const ReportContent& content) {
  std::string html;
  for (std::size_t i = 0; i < content.figures.size(); ++i) {
    const ReportFigure& figure = content.figures[i];
    html += "<figure>\n";
    html += plot::RenderSvg(figure.figure, kFigureWidth_pt, kFigureWidth_pt * figure.height_over_width, fmt::format("f{}-", i));
    html += "\n<figcaption>" + Escape(figure.caption) + "</figcaption>\n</figure>\n";
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
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<title>" + Escape(content.title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n";
  html += "<h1>" + Escape(content.title) + "</h1>\n";
  html += "<h2>Scan and provenance</h2>\n" + KeyValueTable(content.provenance);
  html += "<h2>Headline numbers</h2>\n" + HeadlineTable(content);
  html += "<h2>Plots</h2>\n" + Figures(content);
  html += "<h2>Warnings</h2>\n" + Warnings(content.warnings);
  html += "<h2>Processing parameters</h2>\n";
  html += content.processing.empty() ? "<p>None recorded.</p>\n" : KeyValueTable(content.processing);
  html += "</body>\n</html>\n";
  return html;
}

}  // namespace arcwheel::reports
