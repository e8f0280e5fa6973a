#pragma once
// The page machinery the PDF reports share (wheel report, polish report): an A4 portrait flow
// of titles, headings, wrapped table rows and figures, with a footer on every page. Internal to
// reports/.

#include <cairo-pdf.h>
#include <fmt/format.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "core/error.h"
#include "reports/report_content.h"

namespace arcwheel::reports::internal {

inline constexpr const char* kPdfStage = "reports.pdf";
inline constexpr const char* kFont = "DejaVu Sans";
inline constexpr double kPageWidth_pt = 595.2756;   // A4, 210 mm
inline constexpr double kPageHeight_pt = 841.8898;  // A4, 297 mm
inline constexpr double kMargin_pt = 40.0;
inline constexpr double kContentWidth_pt = kPageWidth_pt - 2.0 * kMargin_pt;
inline constexpr double kBodySize_pt = 8.5;
inline constexpr double kLine_pt = 10.0;
inline constexpr double kRowGap_pt = 12.0;  // between figures side by side

// Width of each of `count` figures laid side by side across the page.
inline constexpr double RowFigureWidthPt(std::size_t count) {
  return count <= 1
             ? kContentWidth_pt
             : (kContentWidth_pt - kRowGap_pt * static_cast<double>(count - 1)) / static_cast<double>(count);
}

// A cell of a table row; `verdict` colours the cell's background when set.
struct Cell {
  std::string text;
  std::optional<Verdict> verdict;
};

// Lays the report out top to bottom on A4 pages, starting a new page when the next block does
// not fit.
class PdfFlow {
 public:
  // Writes to `path`; footers read "FOOTER · page x of TOTAL_PAGES" (or "page x" when 0).
  PdfFlow(const std::filesystem::path& path, std::string footer, int total_pages = 0)
      : surface_(cairo_pdf_surface_create(path.c_str(), kPageWidth_pt, kPageHeight_pt),
                 cairo_surface_destroy),
        footer_(std::move(footer)),
        total_pages_(total_pages) {
    CheckStatus("cannot create '" + path.string() + "'");
    cr_ = cairo_create(surface_.get());
  }
  // Lays out without writing anything and without painting figures: to count the pages.
  explicit PdfFlow(std::string footer)
      : surface_(cairo_pdf_surface_create_for_stream(Discard, nullptr, kPageWidth_pt, kPageHeight_pt),
                 cairo_surface_destroy),
        footer_(std::move(footer)),
        counting_(true) {
    CheckStatus("cannot create a PDF surface");
    cr_ = cairo_create(surface_.get());
  }
  PdfFlow(const PdfFlow&) = delete;
  PdfFlow& operator=(const PdfFlow&) = delete;
  ~PdfFlow() {
    if (cr_ != nullptr) cairo_destroy(cr_);
  }

  void SetMetadata(const std::string& title) {
    cairo_pdf_surface_set_metadata(surface_.get(), CAIRO_PDF_METADATA_TITLE, title.c_str());
    cairo_pdf_surface_set_metadata(surface_.get(), CAIRO_PDF_METADATA_CREATOR, "arcwheel report");
  }

  void Title(const std::string& text) {
    Font(15.0, true);
    for (const std::string& line : Wrap(text, kContentWidth_pt)) {
      Ensure(20.0);
      Text(line, kMargin_pt, y_ + 14.0);
      y_ += 20.0;
    }
    y_ += 4.0;
  }

  // A large coloured box across the page with `text` in it (the report's verdict).
  void Banner(const std::string& text, Verdict verdict) {
    constexpr double kHeight = 34.0;
    Ensure(kHeight + 4.0);
    if (verdict == Verdict::kPass) cairo_set_source_rgb(cr_, 0.05, 0.48, 0.17);
    if (verdict == Verdict::kFail) cairo_set_source_rgb(cr_, 0.72, 0.07, 0.07);
    if (verdict == Verdict::kNoTolerance) cairo_set_source_rgb(cr_, 0.45, 0.45, 0.45);
    cairo_rectangle(cr_, kMargin_pt, y_, kContentWidth_pt, kHeight);
    cairo_fill(cr_);
    Font(22.0, true);
    cairo_set_source_rgb(cr_, 1.0, 1.0, 1.0);
    Text(text, kMargin_pt + 10.0, y_ + 25.0);
    y_ += kHeight + 4.0;
  }

  // Starts a table: draws its header row (bold) now and again at the top of each page the table
  // continues on, until the next Heading or EndTable.
  void TableHeader(const std::vector<Cell>& cells, const std::vector<double>& widths) {
    header_cells_ = cells;
    header_widths_ = widths;
    Row(cells, widths, true);
  }
  void EndTable() { header_cells_.clear(); }

  void Heading(const std::string& text, double keep_with_next_pt) {
    EndTable();
    Ensure(22.0 + keep_with_next_pt);
    Font(11.0, true);
    y_ += 6.0;
    Text(text, kMargin_pt, y_ + 11.0);
    cairo_set_line_width(cr_, 0.5);
    cairo_set_source_rgb(cr_, 0.7, 0.7, 0.7);
    cairo_move_to(cr_, kMargin_pt, y_ + 14.5);
    cairo_line_to(cr_, kMargin_pt + kContentWidth_pt, y_ + 14.5);
    cairo_stroke(cr_);
    y_ += 19.0;
  }

  void Paragraph(const std::string& text, std::optional<Verdict> verdict = std::nullopt) {
    Row({{text, verdict}}, {kContentWidth_pt}, false);
  }

  // One table row; columns of the given widths, text wrapped inside each.
  void Row(const std::vector<Cell>& cells, const std::vector<double>& widths, bool bold) {
    Font(kBodySize_pt, bold);
    std::vector<std::vector<std::string>> lines;
    std::size_t tallest = 1;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      lines.push_back(Wrap(cells[c].text, widths[c] - 6.0));
      tallest = std::max(tallest, lines.back().size());
    }
    const double height = static_cast<double>(tallest) * kLine_pt + 2.0;
    if (Ensure(height) && !header_cells_.empty() && !bold) Row(header_cells_, header_widths_, true);
    // A page break drew the footer (and perhaps the header) in their own fonts.
    Font(kBodySize_pt, bold);
    double x = kMargin_pt;
    for (std::size_t c = 0; c < cells.size(); ++c) {
      if (cells[c].verdict) VerdictBackground(*cells[c].verdict, x, widths[c]);
      for (std::size_t l = 0; l < lines[c].size(); ++l)
        Text(lines[c][l], x + 2.0, y_ + 9.0 + static_cast<double>(l) * kLine_pt);
      x += widths[c];
    }
    cairo_set_source_rgb(cr_, 0.88, 0.88, 0.88);
    cairo_set_line_width(cr_, 0.4);
    cairo_move_to(cr_, kMargin_pt, y_ + height - 0.5);
    cairo_line_to(cr_, kMargin_pt + kContentWidth_pt, y_ + height - 0.5);
    cairo_stroke(cr_);
    y_ += height;
  }

  void Figure(const ReportFigure& figure) {
    const double height = kContentWidth_pt * figure.height_over_width;
    Font(kBodySize_pt - 0.5, false);
    const std::vector<std::string> caption = Wrap(figure.caption, kContentWidth_pt);
    Ensure(height + static_cast<double>(caption.size()) * kLine_pt + 10.0);
    if (!counting_) {
      cairo_save(cr_);
      cairo_translate(cr_, kMargin_pt, y_);
      plot::Draw(cr_, figure.figure, kContentWidth_pt, height);
      cairo_restore(cr_);
    }
    y_ += height + 2.0;
    Font(kBodySize_pt - 0.5, false);
    cairo_set_source_rgb(cr_, 0.33, 0.33, 0.33);
    for (const std::string& line : caption) {
      Text(line, kMargin_pt, y_ + 8.0);
      y_ += kLine_pt;
    }
    y_ += 8.0;
  }

  // Figures side by side, each RowFigureWidthPt(figures.size()) wide, as tall as the tallest;
  // captions below each.
  void FigureRow(const std::vector<ReportFigure>& figures) {
    if (figures.size() == 1) return Figure(figures.front());
    const double width = RowFigureWidthPt(figures.size());
    double height = 0.0;
    std::size_t caption_lines = 0;
    Font(kBodySize_pt - 0.5, false);
    std::vector<std::vector<std::string>> captions;
    for (const ReportFigure& figure : figures) {
      height = std::max(height, width * figure.height_over_width);
      captions.push_back(Wrap(figure.caption, width - 4.0));
      caption_lines = std::max(caption_lines, captions.back().size());
    }
    Ensure(height + static_cast<double>(caption_lines) * kLine_pt + 10.0);
    for (std::size_t i = 0; i < figures.size() && !counting_; ++i) {
      cairo_save(cr_);
      cairo_translate(cr_, kMargin_pt + static_cast<double>(i) * (width + kRowGap_pt), y_);
      plot::Draw(cr_, figures[i].figure, width, width * figures[i].height_over_width);
      cairo_restore(cr_);
    }
    y_ += height + 2.0;
    Font(kBodySize_pt - 0.5, false);
    cairo_set_source_rgb(cr_, 0.33, 0.33, 0.33);
    for (std::size_t i = 0; i < figures.size(); ++i) {
      for (std::size_t l = 0; l < captions[i].size(); ++l) {
        Text(captions[i][l], kMargin_pt + static_cast<double>(i) * (width + kRowGap_pt),
             y_ + 8.0 + static_cast<double>(l) * kLine_pt);
      }
    }
    y_ += static_cast<double>(caption_lines) * kLine_pt + 8.0;
  }

  void Space(double height_pt) { y_ += height_pt; }

  void Finish() {
    Footer();
    cairo_show_page(cr_);
    cairo_destroy(cr_);
    cr_ = nullptr;
    cairo_surface_finish(surface_.get());
    CheckStatus("cannot write the PDF");
  }

  // Pages begun so far (all of them after Finish).
  [[nodiscard]] int Pages() const { return page_ - 1; }

 private:
  static cairo_status_t Discard(void* /*closure*/, const unsigned char* /*data*/, unsigned int /*length*/) {
    return CAIRO_STATUS_SUCCESS;
  }

  void CheckStatus(const std::string& what) const {
    const cairo_status_t status = cairo_surface_status(surface_.get());
    if (status != CAIRO_STATUS_SUCCESS)
      throw Error(ErrorCode::kIo, kPdfStage, what + ": " + cairo_status_to_string(status));
  }

  void Font(double size_pt, bool bold) {
    cairo_select_font_face(cr_, kFont, CAIRO_FONT_SLANT_NORMAL,
                           bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
    cairo_set_font_size(cr_, size_pt);
    cairo_set_source_rgb(cr_, 0.13, 0.13, 0.13);
  }

  void Text(const std::string& text, double x, double baseline) {
    cairo_move_to(cr_, x, baseline);
    cairo_show_text(cr_, text.c_str());
  }

  double Width(const std::string& text) {
    cairo_text_extents_t extents;
    cairo_text_extents(cr_, text.c_str(), &extents);
    return extents.x_advance;
  }

  // Greedy word wrap; a word wider than the line (a path, a hash) is broken between characters.
  std::vector<std::string> Wrap(const std::string& text, double width) {
    std::vector<std::string> lines(1);
    std::size_t start = 0;
    while (start <= text.size()) {
      const std::size_t space = text.find(' ', start);
      const std::string word =
          text.substr(start, space == std::string::npos ? std::string::npos : space - start);
      const std::string joined = lines.back().empty() ? word : lines.back() + " " + word;
      if (Width(joined) <= width) {
        lines.back() = joined;
      } else if (Width(word) <= width) {
        lines.push_back(word);
      } else {
        for (std::size_t i = 0; i < word.size();) {
          std::size_t length = 1;
          while (i + length < word.size() && Width(word.substr(i, length + 1)) <= width) ++length;
          while (i + length < word.size() && (static_cast<unsigned char>(word[i + length]) & 0xC0) == 0x80)
            ++length;
          if (!lines.back().empty()) lines.emplace_back();
          lines.back() = word.substr(i, length);
          i += length;
        }
      }
      if (space == std::string::npos) break;
      start = space + 1;
    }
    return lines;
  }

  void VerdictBackground(Verdict verdict, double x, double width) {
    if (verdict == Verdict::kPass) cairo_set_source_rgb(cr_, 0.85, 0.95, 0.87);
    if (verdict == Verdict::kFail) cairo_set_source_rgb(cr_, 0.98, 0.84, 0.84);
    if (verdict == Verdict::kNoTolerance) cairo_set_source_rgb(cr_, 0.93, 0.93, 0.93);
    cairo_rectangle(cr_, x, y_ + 1.0, width - 2.0, kLine_pt);
    cairo_fill(cr_);
    cairo_set_source_rgb(cr_, 0.13, 0.13, 0.13);
  }

  // Starts a new page when `height` does not fit on this one; true if it did.
  bool Ensure(double height) {
    if (y_ + height <= kPageHeight_pt - kMargin_pt || y_ <= kMargin_pt) return false;
    Footer();
    cairo_show_page(cr_);
    y_ = kMargin_pt;
    return true;
  }

  void Footer() {
    Font(7.0, false);
    cairo_set_source_rgb(cr_, 0.45, 0.45, 0.45);
    const std::string page =
        total_pages_ > 0 ? fmt::format("page {} of {}", page_, total_pages_) : fmt::format("page {}", page_);
    Text(footer_ + " · " + page, kMargin_pt, kPageHeight_pt - kMargin_pt / 2.0);
    ++page_;
  }

  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface_;
  cairo_t* cr_ = nullptr;
  std::string footer_;
  int total_pages_ = 0;
  bool counting_ = false;
  std::vector<Cell> header_cells_;
  std::vector<double> header_widths_;
  double y_ = kMargin_pt;
  int page_ = 1;
};

// Lays the document out twice: once to count its pages, then into `path` with "page x of N" in
// every footer. `draw` must lay out the same content both times and end with Finish().
inline void RenderPdfPages(const std::filesystem::path& path, const std::string& footer,
                           const std::function<void(PdfFlow&)>& draw) {
  int pages = 0;
  {
    PdfFlow counter(footer);
    draw(counter);
    pages = counter.Pages();
  }
  PdfFlow pdf(path, footer, pages);
  draw(pdf);
}

}  // namespace arcwheel::reports::internal
