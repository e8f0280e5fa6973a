#pragma once
// The HTML machinery the reports share (wheel report, polish report): one self-contained,
// phone-first page with inline CSS and inline SVG plots. Internal to reports/.

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include "reports/report_content.h"

namespace arcwheel::reports::internal {

// `text` with &, <, >, " and ' escaped for HTML text and attributes.
[[nodiscard]] std::string Escape(const std::string& text);

// From <!DOCTYPE html> to the <h1> title (inclusive); close with HtmlPageEnd().
[[nodiscard]] std::string HtmlPageStart(const std::string& title);
[[nodiscard]] std::string HtmlPageEnd();

// A two-column table of keys (row headers) and values.
[[nodiscard]] std::string KeyValueTable(const std::vector<KeyValue>& rows);

// A table with a header row; numeric columns (index >= 1) do not wrap.
[[nodiscard]] std::string Table(const std::vector<std::string>& header,
                                const std::vector<std::vector<std::string>>& rows);

// One figure with its caption, drawn `width_pt` wide; ids in its SVG start with `id_prefix`.
[[nodiscard]] std::string FigureHtml(const ReportFigure& figure, double width_pt,
                                     const std::string& id_prefix);

// Figures side by side (stacked on a phone), each drawn at the PDF's width for that many
// figures in a row so that both reports show the same drawing.
[[nodiscard]] std::string FigureRowHtml(const std::vector<ReportFigure>& figures,
                                        const std::string& id_prefix);

// Writes a report's PDF, which `render_pdf` draws to the path it is given, and then its HTML page,
// which `render_html` returns, both to temporary files renamed into place together: a failure
// leaves neither. In that order: drawn before the PDF, the PNG images embedded in the HTML come
// out with other bytes (seen on the shipped demo; the cause is not known). Throws Error{kIo}.
void WriteHtmlAndPdf(const std::filesystem::path& html_path, const std::function<std::string()>& render_html,
                     const std::filesystem::path& pdf_path,
                     const std::function<void(const std::filesystem::path&)>& render_pdf);

// Width (points) at which a full-width figure is drawn; CSS scales it to the screen.
inline constexpr double kFigureWidth_pt = 640.0;

}  // namespace arcwheel::reports::internal
