#include "reports/html_page.h"

#include <fmt/format.h>

#include <algorithm>

#include "core/atomic_file.h"
#include "reports/pdf_flow.h"

namespace arcwheel::reports::internal {
namespace {

// Phone-first layout; print rules keep figures and tables whole on A4.
constexpr const char* kStyle = R"css(
:root { color-scheme: light; }
* { box-sizing: border-box; }
body { margin: 0 auto; padding: 12px; max-width: 980px; color: #222; background: #fff;
       font: 15px/1.45 "DejaVu Sans", "Helvetica Neue", Arial, sans-serif; }
h1 { font-size: 1.35em; margin: 0.3em 0; }
h2 { font-size: 1.1em; margin: 1.2em 0 0.4em; border-bottom: 1px solid #ccc; }
h3 { font-size: 1em; margin: 0.9em 0 0.3em; }
table { border-collapse: collapse; width: 100%; margin: 0.3em 0; }
th, td { text-align: left; padding: 4px 6px; border-bottom: 1px solid #e4e4e4; vertical-align: top; }
th[scope="row"] { width: 34%; }
td.value { overflow-wrap: anywhere; font-variant-numeric: tabular-nums; }
td.number { white-space: nowrap; font-variant-numeric: tabular-nums; }
.verdict { display: inline-block; padding: 0.15em 0.5em; font-size: 0.85em; border-radius: 4px; font-weight: bold; }
.pass { background: #d9f2dd; color: #0b5d1e; }
.fail { background: #fbd5d5; color: #8a1111; }
.none { background: #eee; color: #444; }
.table-scroll { overflow-x: auto; }
.banner { font-size: 2em; font-weight: bold; color: #fff; padding: 0.2em 0.5em; border-radius: 6px; margin: 0.3em 0; }
.banner.pass { background: #0d7a2b; color: #fff; } .banner.fail { background: #b81212; color: #fff; }
.banner.none { background: #737373; color: #fff; }
ul.failing { margin: 0.2em 0 0.6em; } p.failing { margin: 0.4em 0 0; }
table.headline td.result, table.headline td.limit { white-space: nowrap; }
table.headline .note { font-size: 0.85em; color: #8a4b00; }
table.headline td.value { white-space: nowrap; font-variant-numeric: tabular-nums; }
figure image { image-rendering: pixelated; }
.plot-phone { display: none; }
figure { margin: 0.8em 0; break-inside: avoid; page-break-inside: avoid; }
figure svg { display: block; width: 100%; height: auto; }
figcaption { font-size: 0.88em; color: #555; }
.figure-row { display: grid; grid-template-columns: repeat(auto-fit, minmax(280px, 1fr)); gap: 0 14px; }
@media (max-width: 600px) {
  body { font-size: 14px; padding: 8px; } th, td { padding: 3px 4px; }
  /* The headline table as one card per quantity: name and result on top, details below. */
  table.headline thead { display: none; }
  table.headline tr { display: grid; grid-template-columns: 1fr auto; border-bottom: 1px solid #ccc; padding: 4px 0; }
  table.headline td { display: block; border: none; padding: 1px 4px; }
  table.headline td.quantity { grid-column: 1; grid-row: 1; font-weight: bold; }
  table.headline td.result { grid-column: 2; grid-row: 1; }
  table.headline td.detail { grid-column: 1 / span 2; white-space: normal; }
  table.headline td.detail:empty { display: none; }
  table.headline td.detail::before { content: attr(data-label) ": "; color: #666; }
  .plot-wide { display: none; } .plot-phone { display: block; }
}
@page { size: A4; margin: 14mm; }
@media print { body { max-width: none; padding: 0; font-size: 10pt; } h2 { break-after: avoid; } }
)css";

}  // namespace

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      case '\'':
        out += "&#39;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

std::string HtmlPageStart(const std::string& title) {
  std::string html = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n";
  html += "<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n";
  html += "<title>" + Escape(title) + "</title>\n<style>" + kStyle + "</style>\n</head>\n<body>\n";
  return html + "<h1>" + Escape(title) + "</h1>\n";
}

std::string HtmlPageEnd() { return "</body>\n</html>\n"; }

std::string KeyValueTable(const std::vector<KeyValue>& rows) {
  std::string html = "<div class=\"table-scroll\"><table>\n";
  for (const KeyValue& row : rows) {
    html += "<tr><th scope=\"row\">" + Escape(row.key) + "</th><td class=\"value\">" + Escape(row.value) +
            "</td></tr>\n";
  }
  return html + "</table></div>\n";
}

std::string Table(const std::vector<std::string>& header, const std::vector<std::vector<std::string>>& rows) {
  std::string html = "<div class=\"table-scroll\"><table>\n<tr>";
  for (const std::string& cell : header) html += "<th>" + Escape(cell) + "</th>";
  html += "</tr>\n";
  for (const std::vector<std::string>& row : rows) {
    html += "<tr>";
    for (std::size_t c = 0; c < row.size(); ++c)
      html += (c == 0 ? "<td>" : "<td class=\"number\">") + Escape(row[c]) + "</td>";
    html += "</tr>\n";
  }
  return html + "</table></div>\n";
}

std::string FigureHtml(const ReportFigure& figure, double width_pt, const std::string& id_prefix) {
  std::string html = "<figure>\n";
  const std::string wide =
      plot::RenderSvg(figure.figure, width_pt, width_pt * figure.height_over_width, id_prefix);
  if (width_pt < 1.5 * plot::kPhoneFigureWidth_pt) {
    html += wide;
  } else {
    // A second drawing for phones, narrower and taller, so that its text is not shrunk with it
    // (CSS shows one of the two).
    constexpr double kPhoneWidth_pt = plot::kPhoneFigureWidth_pt;
    const double phone_height_pt = kPhoneWidth_pt * std::max(figure.height_over_width, 0.75);
    html += "<div class=\"plot-wide\">" + wide + "</div>\n<div class=\"plot-phone\">" +
            plot::RenderSvg(figure.figure, kPhoneWidth_pt, phone_height_pt, id_prefix + "p") + "</div>";
  }
  return html + "\n<figcaption>" + Escape(figure.caption) + "</figcaption>\n</figure>\n";
}

std::string FigureRowHtml(const std::vector<ReportFigure>& figures, const std::string& id_prefix) {
  if (figures.size() == 1) return FigureHtml(figures.front(), kFigureWidth_pt, id_prefix);
  std::string html = "<div class=\"figure-row\">\n";
  for (std::size_t i = 0; i < figures.size(); ++i) {
    html += FigureHtml(figures[i], RowFigureWidthPt(figures.size()), fmt::format("{}{}-", id_prefix, i));
  }
  return html + "</div>\n";
}

void WriteHtmlAndPdf(const std::filesystem::path& html_path, const std::function<std::string()>& render_html,
                     const std::filesystem::path& pdf_path,
                     const std::function<void(const std::filesystem::path&)>& render_pdf) {
  OutputSet outputs;
  const std::filesystem::path html_temporary = outputs.Stage(html_path);
  const std::filesystem::path pdf_temporary = outputs.Stage(pdf_path);
  render_pdf(pdf_temporary);
  WriteFileAtomically(html_temporary, render_html());
  outputs.Commit();
}

}  // namespace arcwheel::reports::internal
