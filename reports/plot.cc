#include "reports/plot.h"

#include <cairo-svg.h>
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <memory>
#include <sstream>
#include <tuple>

#include "core/check.h"
#include "core/error.h"

namespace arcwheel::reports::plot {
namespace {

constexpr const char* kFont = "DejaVu Sans";
constexpr double kTitleSize_pt = 10.0;
constexpr double kLabelSize_pt = 8.0;

constexpr double kLegendRow_pt = 13.0;
constexpr double kColourBarWidth_pt = 10.0;
// Display resolution of a heat map: larger grids are averaged down in blocks, which keeps the
// embedded image small without hiding anything a reader can see at page size.
constexpr std::size_t kMaxImageColumns = 720;
constexpr std::size_t kMaxImageRows = 480;
const Rgb kMissingColour{0.80, 0.80, 0.80};
const Rgb kInk{0.15, 0.15, 0.15};
const Rgb kGrid{0.88, 0.88, 0.88};
const Rgb kMarkColour{0.60, 0.10, 0.45};

struct Range {
  double low = 0.0;
  double high = 1.0;
};

struct Rect {
  double x = 0.0;
  double y = 0.0;
  double width = 0.0;
  double height = 0.0;
};

// Maps data coordinates to the plot rectangle (y grows upwards in data, downwards on the page).
struct Frame {
  Rect area;
  Range x;
  Range y;
  [[nodiscard]] double Px(double value) const {
    return area.x + (value - x.low) / (x.high - x.low) * area.width;
  }
  [[nodiscard]] double Py(double value) const {
    return area.y + area.height - (value - y.low) / (y.high - y.low) * area.height;
  }
};

void SetColour(cairo_t* cr, const Rgb& colour, double alpha = 1.0) {
  cairo_set_source_rgba(cr, colour.r, colour.g, colour.b, alpha);
}

void SetFont(cairo_t* cr, double size_pt, bool bold = false) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_pt);
}

double TextWidth(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  return extents.x_advance;
}

// Writes `text` with its anchor at (x, y): align_x 0 left, 0.5 centre, 1 right; the baseline is
// placed so that the text's middle is at y. `angle_rad` turns it about the anchor.
void DrawText(cairo_t* cr, const std::string& text, double x, double y, double align_x,
              double angle_rad = 0.0) {
  cairo_font_extents_t font;
  cairo_font_extents(cr, &font);
  cairo_save(cr);
  cairo_translate(cr, x, y);
  cairo_rotate(cr, angle_rad);
  cairo_move_to(cr, -align_x * TextWidth(cr, text), (font.ascent - font.descent) / 2.0);
  cairo_show_text(cr, text.c_str());
  cairo_restore(cr);
}

Range Padded(double low, double high) {
  if (!std::isfinite(low) || !std::isfinite(high)) return {0.0, 1.0};
  // A flat series (or one flat up to rounding) gets a range around its value instead of a
  // magnified view of floating-point noise.
  const double magnitude = std::max(std::abs(low), std::abs(high));
  if (high - low <= 1e-9 * std::max(1.0, magnitude)) {
    const double half = magnitude > 1e-6 ? magnitude * 1e-3 : 1.0;
    return {low - half, high + half};
  }
  const double pad = 0.04 * (high - low);
  return {low - pad, high + pad};
}

void Extend(double value, double& low, double& high) {
  if (!std::isfinite(value)) return;
  low = std::min(low, value);
  high = std::max(high, value);
}

Range ResolveRange(const Axis& axis, double data_low, double data_high, bool pad) {
  Range range = pad ? Padded(data_low, data_high) : Range{data_low, data_high};
  if (!pad && !(range.high > range.low)) range = Padded(data_low, data_high);
  if (axis.min) range.low = *axis.min;
  if (axis.max) range.high = *axis.max;
  ARCWHEEL_CHECK(range.high > range.low) << "axis '" << axis.label << "' has an empty range";
  return range;
}

// Lays out title, legend rows and axes inside width x height: `extra_top_pt` below a one-line title
// (further title lines, legend rows), `right_pt` kept free on the right.
Rect PlotArea(double width, double height, double extra_top_pt, double right_pt) {
  constexpr double kLeft = 50.0;
  constexpr double kBottom = 30.0;
  const double top = 18.0 + extra_top_pt;
  return {kLeft, top, std::max(10.0, width - kLeft - right_pt - 8.0), std::max(10.0, height - top - kBottom)};
}

// A title that fits the figure's width: on one line at 10 pt, else shrunk down to 8.5 pt, else
// wrapped at spaces at 8.5 pt (a phone's narrow figure).
struct TitleLayout {
  std::vector<std::string> lines;
  double size_pt = kTitleSize_pt;
  // Height beyond the one line PlotArea always leaves.
  [[nodiscard]] double ExtraPt() const { return static_cast<double>(lines.size() - 1) * (size_pt + 2.0); }
};

TitleLayout LayOutTitle(cairo_t* cr, const std::string& title, double width) {
  constexpr double kSmallest_pt = 8.5;
  const double available = width - 8.0;
  SetFont(cr, kTitleSize_pt, true);
  const double natural = TextWidth(cr, title);
  if (natural <= available) return {{title}, kTitleSize_pt};
  const double shrunk = kTitleSize_pt * available / natural;
  if (shrunk >= kSmallest_pt) return {{title}, shrunk};
  SetFont(cr, kSmallest_pt, true);
  TitleLayout layout{{""}, kSmallest_pt};
  std::istringstream words(title);
  for (std::string word; words >> word;) {
    const std::string joined = layout.lines.back().empty() ? word : layout.lines.back() + " " + word;
    if (TextWidth(cr, joined) <= available || layout.lines.back().empty()) {
      layout.lines.back() = joined;
    } else {
      layout.lines.push_back(word);
    }
  }
  return layout;
}

void DrawTitle(cairo_t* cr, const TitleLayout& title, double width) {
  SetFont(cr, title.size_pt, true);
  SetColour(cr, kInk);
  for (std::size_t k = 0; k < title.lines.size(); ++k)
    DrawText(cr, title.lines[k], width / 2.0, 9.0 + static_cast<double>(k) * (title.size_pt + 2.0), 0.5);
}

// At least three ticks, so that a small plot (a map half a page wide) still shows a scale on
// both sides of zero.
int MaxTicks(double length_pt, double spacing_pt) {
  return std::max(3, static_cast<int>(length_pt / spacing_pt));
}

void DrawAxes(cairo_t* cr, const Frame& frame, const Axis& x_axis, const Axis& y_axis, bool grid) {
  const Rect& a = frame.area;
  const double x_step = NiceStep(frame.x.low, frame.x.high, MaxTicks(a.width, 55.0));
  const double y_step = NiceStep(frame.y.low, frame.y.high, MaxTicks(a.height, 28.0));
  const std::vector<double> x_ticks = NiceTicks(frame.x.low, frame.x.high, MaxTicks(a.width, 55.0));
  const std::vector<double> y_ticks = NiceTicks(frame.y.low, frame.y.high, MaxTicks(a.height, 28.0));
  cairo_set_line_width(cr, 0.5);
  if (grid) {
    SetColour(cr, kGrid);
    for (double t : x_ticks) {
      cairo_move_to(cr, frame.Px(t), a.y);
      cairo_line_to(cr, frame.Px(t), a.y + a.height);
    }
    for (double t : y_ticks) {
      cairo_move_to(cr, a.x, frame.Py(t));
      cairo_line_to(cr, a.x + a.width, frame.Py(t));
    }
    cairo_stroke(cr);
  }
  SetColour(cr, kInk);
  cairo_set_line_width(cr, 0.8);
  cairo_rectangle(cr, a.x, a.y, a.width, a.height);
  cairo_stroke(cr);
  SetFont(cr, kTickSize_pt);
  for (double t : x_ticks) {
    cairo_move_to(cr, frame.Px(t), a.y + a.height);
    cairo_line_to(cr, frame.Px(t), a.y + a.height + 3.0);
    cairo_stroke(cr);
    DrawText(cr, FormatTick(t, x_step), frame.Px(t), a.y + a.height + 9.0, 0.5);
  }
  for (double t : y_ticks) {
    cairo_move_to(cr, a.x - 3.0, frame.Py(t));
    cairo_line_to(cr, a.x, frame.Py(t));
    cairo_stroke(cr);
    DrawText(cr, FormatTick(t, y_step), a.x - 5.0, frame.Py(t), 1.0);
  }
  SetFont(cr, kLabelSize_pt);
  DrawText(cr, x_axis.label, a.x + a.width / 2.0, a.y + a.height + 22.0, 0.5);
  DrawText(cr, y_axis.label, 10.0, a.y + a.height / 2.0, 0.5, -M_PI / 2.0);
}

struct LegendEntry {
  std::string label;
  Rgb colour;
  enum class Swatch { kLine, kDashed, kDot, kBox } swatch = Swatch::kLine;
};

double LegendEntryWidth(cairo_t* cr, const LegendEntry& entry) {
  SetFont(cr, kLabelSize_pt);
  return 18.0 + TextWidth(cr, entry.label) + 14.0;
}

// Rows the legend takes when wrapped to `width` (0 without entries).
int LegendRows(cairo_t* cr, const std::vector<LegendEntry>& entries, double width) {
  if (entries.empty()) return 0;
  int rows = 1;
  double cursor = 0.0;
  for (const LegendEntry& entry : entries) {
    const double entry_width = LegendEntryWidth(cr, entry);
    if (cursor > 0.0 && cursor + entry_width > width) ++rows, cursor = 0.0;
    cursor += entry_width;
  }
  return rows;
}

// Entries left to right from (x, y), wrapped onto further rows at `width`.
void DrawLegend(cairo_t* cr, const std::vector<LegendEntry>& entries, double x, double y, double width) {
  double cursor = x;
  for (const LegendEntry& entry : entries) {
    const double entry_width = LegendEntryWidth(cr, entry);
    if (cursor > x && cursor - x + entry_width > width) cursor = x, y += kLegendRow_pt;
    SetColour(cr, entry.colour);
    switch (entry.swatch) {
      case LegendEntry::Swatch::kBox:
        cairo_rectangle(cr, cursor, y - 4.0, 14.0, 8.0);
        cairo_fill(cr);
        break;
      case LegendEntry::Swatch::kDot:
        cairo_arc(cr, cursor + 7.0, y, 2.0, 0.0, 2.0 * M_PI);
        cairo_fill(cr);
        break;
      default: {
        const double dash[] = {3.0, 2.0};
        cairo_set_dash(cr, dash, entry.swatch == LegendEntry::Swatch::kDashed ? 2 : 0, 0.0);
        cairo_set_line_width(cr, 1.5);
        cairo_move_to(cr, cursor, y);
        cairo_line_to(cr, cursor + 14.0, y);
        cairo_stroke(cr);
        cairo_set_dash(cr, nullptr, 0, 0.0);
      }
    }
    SetColour(cr, kInk);
    DrawText(cr, entry.label, cursor + 18.0, y, 0.0);
    cursor += entry_width;
  }
}

void CheckSeries(const Series& series) {
  ARCWHEEL_CHECK(series.x.size() == series.y.size())
      << "series '" << series.label << "' x and y differ in size";
  ARCWHEEL_CHECK(series.y_error.empty() || series.y_error.size() == series.x.size())
      << "series '" << series.label << "' error bars do not match its points";
  ARCWHEEL_CHECK(series.band_low.size() == series.band_high.size() &&
                 (series.band_low.empty() || series.band_low.size() == series.x.size()))
      << "series '" << series.label << "' band does not match its points";
}

void DrawBand(cairo_t* cr, const Frame& frame, const Series& series) {
  // One closed polygon per run of finite band values, so that a gap stays a gap.
  std::size_t i = 0;
  const std::size_t n = series.x.size();
  while (i < n) {
    while (i < n && !(std::isfinite(series.band_low[i]) && std::isfinite(series.band_high[i]))) ++i;
    std::size_t end = i;
    while (end < n && std::isfinite(series.band_low[end]) && std::isfinite(series.band_high[end])) ++end;
    if (end > i) {
      for (std::size_t k = i; k < end; ++k)
        cairo_line_to(cr, frame.Px(series.x[k]), frame.Py(series.band_high[k]));
      for (std::size_t k = end; k-- > i;)
        cairo_line_to(cr, frame.Px(series.x[k]), frame.Py(series.band_low[k]));
      cairo_close_path(cr);
      SetColour(cr, series.colour, 0.25);
      cairo_fill(cr);
    }
    i = end;
  }
}

void DrawSeries(cairo_t* cr, const Frame& frame, const Series& series) {
  if (!series.band_low.empty()) DrawBand(cr, frame, series);
  SetColour(cr, series.colour);
  if (!series.y_error.empty()) {
    cairo_set_line_width(cr, 0.9);
    for (std::size_t i = 0; i < series.x.size(); ++i) {
      if (!std::isfinite(series.x[i]) || !std::isfinite(series.y[i]) || !std::isfinite(series.y_error[i]))
        continue;
      const double x = frame.Px(series.x[i]);
      const double top = frame.Py(series.y[i] + series.y_error[i]);
      const double bottom = frame.Py(series.y[i] - series.y_error[i]);
      cairo_move_to(cr, x, top);
      cairo_line_to(cr, x, bottom);
      cairo_move_to(cr, x - 2.5, top);
      cairo_line_to(cr, x + 2.5, top);
      cairo_move_to(cr, x - 2.5, bottom);
      cairo_line_to(cr, x + 2.5, bottom);
    }
    cairo_stroke(cr);
  }
  if (series.markers) {
    for (std::size_t i = 0; i < series.x.size(); ++i) {
      if (!std::isfinite(series.x[i]) || !std::isfinite(series.y[i])) continue;
      cairo_new_sub_path(cr);
      cairo_arc(cr, frame.Px(series.x[i]), frame.Py(series.y[i]), series.marker_size_pt, 0.0, 2.0 * M_PI);
    }
    cairo_fill(cr);
    return;
  }
  const double dash[] = {4.0, 2.5};
  cairo_set_dash(cr, dash, series.dashed ? 2 : 0, 0.0);
  cairo_set_line_width(cr, 1.1);
  cairo_set_line_join(cr, CAIRO_LINE_JOIN_ROUND);
  bool pen_down = false;
  for (std::size_t i = 0; i < series.x.size(); ++i) {
    const bool finite = std::isfinite(series.x[i]) && std::isfinite(series.y[i]);
    if (!finite) {
      pen_down = false;
      continue;
    }
    if (pen_down) {
      cairo_line_to(cr, frame.Px(series.x[i]), frame.Py(series.y[i]));
    } else {
      cairo_move_to(cr, frame.Px(series.x[i]), frame.Py(series.y[i]));
      pen_down = true;
    }
  }
  cairo_stroke(cr);
  cairo_set_dash(cr, nullptr, 0, 0.0);
}

void DrawLinePlot(cairo_t* cr, const LinePlot& plot, double width, double height) {
  double x_low = INFINITY, x_high = -INFINITY, y_low = INFINITY, y_high = -INFINITY;
  for (const Series& series : plot.series) {
    CheckSeries(series);
    for (std::size_t i = 0; i < series.x.size(); ++i) {
      if (!std::isfinite(series.y[i])) continue;
      Extend(series.x[i], x_low, x_high);
      Extend(series.y[i], y_low, y_high);
      if (!series.band_low.empty()) {
        Extend(series.band_low[i], y_low, y_high);
        Extend(series.band_high[i], y_low, y_high);
      }
      if (!series.y_error.empty()) {
        Extend(series.y[i] - series.y_error[i], y_low, y_high);
        Extend(series.y[i] + series.y_error[i], y_low, y_high);
      }
    }
  }
  for (double x : plot.x_marks) Extend(x, x_low, x_high);
  std::vector<LegendEntry> legend;
  if (plot.series.size() > 1) {
    for (const Series& s : plot.series) {
      legend.push_back({s.label, s.colour,
                        s.markers  ? LegendEntry::Swatch::kDot
                        : s.dashed ? LegendEntry::Swatch::kDashed
                                   : LegendEntry::Swatch::kLine});
    }
  }
  for (const XSpan& span : plot.spans)
    legend.push_back({span.label, {0.55, 0.55, 0.55}, LegendEntry::Swatch::kBox});
  if (!plot.x_marks.empty())
    legend.push_back({plot.x_marks_label, kMarkColour, LegendEntry::Swatch::kDashed});
  const double legend_width = width - 58.0;
  const TitleLayout title = LayOutTitle(cr, plot.title, width);
  const Frame frame{
      PlotArea(width, height, title.ExtraPt() + LegendRows(cr, legend, legend_width) * kLegendRow_pt, 0.0),
      ResolveRange(plot.x, x_low, x_high, true), ResolveRange(plot.y, y_low, y_high, true)};
  DrawTitle(cr, title, width);
  if (!legend.empty())
    DrawLegend(cr, legend, frame.area.x, 18.0 + title.ExtraPt() + kLegendRow_pt / 2.0, legend_width);
  DrawAxes(cr, frame, plot.x, plot.y, true);
  cairo_save(cr);
  cairo_rectangle(cr, frame.area.x, frame.area.y, frame.area.width, frame.area.height);
  cairo_clip(cr);
  for (const XSpan& span : plot.spans) {
    SetColour(cr, {0.55, 0.55, 0.55}, 0.15);
    cairo_rectangle(cr, frame.Px(span.low), frame.area.y, frame.Px(span.high) - frame.Px(span.low),
                    frame.area.height);
    cairo_fill(cr);
  }
  for (double x : plot.x_marks) {
    const double dash[] = {5.0, 3.0};
    SetColour(cr, kMarkColour);
    cairo_set_line_width(cr, 1.2);
    cairo_set_dash(cr, dash, 2, 0.0);
    cairo_move_to(cr, frame.Px(x), frame.area.y);
    cairo_line_to(cr, frame.Px(x), frame.area.y + frame.area.height);
    cairo_stroke(cr);
    cairo_set_dash(cr, nullptr, 0, 0.0);
  }
  for (const Series& series : plot.series) DrawSeries(cr, frame, series);
  cairo_restore(cr);
  if (plot.series.empty() || !std::isfinite(y_low)) {
    SetFont(cr, kLabelSize_pt);
    SetColour(cr, kInk);
    DrawText(cr, "no data", frame.area.x + frame.area.width / 2.0, frame.area.y + frame.area.height / 2.0,
             0.5);
  }
}

// Node extent of a regular grid: half a spacing beyond the first and last node.
Range CellExtent(const std::vector<double>& nodes) {
  const double half =
      nodes.size() > 1 ? 0.5 * (nodes.back() - nodes.front()) / static_cast<double>(nodes.size() - 1) : 0.5;
  return {nodes.front() - half, nodes.back() + half};
}

std::uint32_t PackArgb(const Rgb& c) {
  auto byte = [](double v) {
    return static_cast<std::uint32_t>(std::lround(std::clamp(v, 0.0, 1.0) * 255.0));
  };
  return 0xFF000000u | (byte(c.r) << 16) | (byte(c.g) << 8) | byte(c.b);
}

using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

// Builds the display image of an n_x x n_y grid: columns follow x, rows follow y from the top
// (largest y) down. `colour_of_block(i0, i1, j0, j1)` gives the colour of a block of cells.
template <typename BlockColour>
SurfacePtr GridImage(std::size_t n_x, std::size_t n_y, const BlockColour& colour_of_block,
                     std::size_t max_columns = kMaxImageColumns, std::size_t max_rows = kMaxImageRows) {
  const std::size_t columns = std::min(n_x, max_columns);
  const std::size_t rows = std::min(n_y, max_rows);
  SurfacePtr image(
      cairo_image_surface_create(CAIRO_FORMAT_ARGB32, static_cast<int>(columns), static_cast<int>(rows)),
      cairo_surface_destroy);
  cairo_surface_flush(image.get());
  unsigned char* data = cairo_image_surface_get_data(image.get());
  const int stride = cairo_image_surface_get_stride(image.get());
  for (std::size_t row = 0; row < rows; ++row) {
    const std::size_t flipped = rows - 1 - row;
    const std::size_t j0 = flipped * n_y / rows;
    const std::size_t j1 = std::max(j0 + 1, (flipped + 1) * n_y / rows);
    auto* line = reinterpret_cast<std::uint32_t*>(data + static_cast<std::ptrdiff_t>(row) * stride);
    for (std::size_t column = 0; column < columns; ++column) {
      const std::size_t i0 = column * n_x / columns;
      const std::size_t i1 = std::max(i0 + 1, (column + 1) * n_x / columns);
      line[column] = PackArgb(colour_of_block(i0, i1, j0, j1));
    }
  }
  cairo_surface_mark_dirty(image.get());
  return image;
}

void PaintGridImage(cairo_t* cr, const Frame& frame, cairo_surface_t* image, const Range& x_extent,
                    const Range& y_extent) {
  const double left = frame.Px(x_extent.low);
  const double right = frame.Px(x_extent.high);
  const double top = frame.Py(y_extent.high);
  const double bottom = frame.Py(y_extent.low);
  cairo_save(cr);
  cairo_rectangle(cr, frame.area.x, frame.area.y, frame.area.width, frame.area.height);
  cairo_clip(cr);
  cairo_translate(cr, left, top);
  cairo_scale(cr, (right - left) / cairo_image_surface_get_width(image),
              (bottom - top) / cairo_image_surface_get_height(image));
  cairo_set_source_surface(cr, image, 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
}

void CheckGrid(std::size_t n_x, std::size_t n_y, std::size_t cells, const std::vector<double>& x_nodes,
               const std::vector<double>& y_nodes, const std::string& title) {
  ARCWHEEL_CHECK(n_x > 0 && n_y > 0 && cells == n_x * n_y && x_nodes.size() == n_x && y_nodes.size() == n_y)
      << "grid '" << title << "' sizes do not match";
}

// The 0.5 and 99.5 percentiles of the finite values, replaced by the fixed limits when given.
Range ColourRange(const std::vector<double>& values, const std::optional<double>& colour_min,
                  const std::optional<double>& colour_max) {
  std::vector<double> finite;
  finite.reserve(values.size());
  for (double v : values) {
    if (std::isfinite(v)) finite.push_back(v);
  }
  Range range{0.0, 1.0};
  if (!finite.empty()) {
    auto percentile = [&finite](double p) {
      const auto k = static_cast<std::ptrdiff_t>(std::lround(p * static_cast<double>(finite.size() - 1)));
      std::nth_element(finite.begin(), finite.begin() + k, finite.end());
      return finite[static_cast<std::size_t>(k)];
    };
    range = {percentile(0.005), percentile(0.995)};
  }
  if (colour_min) range.low = *colour_min;
  if (colour_max) range.high = *colour_max;
  if (!(range.high > range.low)) range = Padded(range.low, range.high);
  return range;
}

void DrawColourBar(cairo_t* cr, const Rect& area, const Range& range, const std::string& label) {
  const Rect bar{area.x + area.width + 8.0, area.y, kColourBarWidth_pt, area.height};
  constexpr int kSteps = 256;
  SurfacePtr strip(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, 1, kSteps), cairo_surface_destroy);
  cairo_surface_flush(strip.get());
  unsigned char* data = cairo_image_surface_get_data(strip.get());
  const int stride = cairo_image_surface_get_stride(strip.get());
  for (int row = 0; row < kSteps; ++row) {
    *reinterpret_cast<std::uint32_t*>(data + row * stride) = PackArgb(Viridis(1.0 - (row + 0.5) / kSteps));
  }
  cairo_surface_mark_dirty(strip.get());
  cairo_save(cr);
  cairo_translate(cr, bar.x, bar.y);
  cairo_scale(cr, bar.width, bar.height / kSteps);
  cairo_set_source_surface(cr, strip.get(), 0.0, 0.0);
  cairo_pattern_set_filter(cairo_get_source(cr), CAIRO_FILTER_NEAREST);
  cairo_paint(cr);
  cairo_restore(cr);
  SetColour(cr, kInk);
  cairo_set_line_width(cr, 0.6);
  cairo_rectangle(cr, bar.x, bar.y, bar.width, bar.height);
  cairo_stroke(cr);
  const Frame scale{bar, {0.0, 1.0}, range};
  const int max_ticks = MaxTicks(bar.height, 28.0);
  const double step = NiceStep(range.low, range.high, max_ticks);
  SetFont(cr, kTickSize_pt);
  for (double t : NiceTicks(range.low, range.high, max_ticks)) {
    cairo_move_to(cr, bar.x + bar.width, scale.Py(t));
    cairo_line_to(cr, bar.x + bar.width + 3.0, scale.Py(t));
    cairo_stroke(cr);
    DrawText(cr, FormatTick(t, step), bar.x + bar.width + 5.0, scale.Py(t), 0.0);
  }
  SetFont(cr, kLabelSize_pt);
  DrawText(cr, label, bar.x + bar.width + 44.0, bar.y + bar.height / 2.0, 0.5, M_PI / 2.0);
}

// Shrinks the plot area (keeping its top-left corner) so that a unit of x and of y have the same
// length on the page.
Frame EqualAspect(Frame frame) {
  const double per_unit = std::min(frame.area.width / (frame.x.high - frame.x.low),
                                   frame.area.height / (frame.y.high - frame.y.low));
  frame.area.width = per_unit * (frame.x.high - frame.x.low);
  frame.area.height = per_unit * (frame.y.high - frame.y.low);
  return frame;
}

// Dashed lines across the map at `marks` (e.g. the band's ends), in white over black so that they
// show on every colour, labelled at the right end inside the plot.
void DrawYMarks(cairo_t* cr, const Frame& frame, const std::vector<double>& marks, const std::string& label) {
  const double dash[] = {4.0, 3.0};
  for (double y : marks) {
    if (!(y > frame.y.low && y < frame.y.high)) continue;
    for (const auto& [colour, line_width, offset] :
         {std::tuple{Rgb{0, 0, 0}, 2.2, 0.0}, std::tuple{Rgb{1, 1, 1}, 1.0, 0.0}}) {
      SetColour(cr, colour);
      cairo_set_line_width(cr, line_width);
      cairo_set_dash(cr, dash, 2, offset);
      cairo_move_to(cr, frame.area.x, frame.Py(y));
      cairo_line_to(cr, frame.area.x + frame.area.width, frame.Py(y));
      cairo_stroke(cr);
    }
    cairo_set_dash(cr, nullptr, 0, 0.0);
    if (!label.empty()) {
      SetFont(cr, kTickSize_pt, true);
      SetColour(cr, {1, 1, 1});
      DrawText(cr, label, frame.area.x + frame.area.width - 3.0, frame.Py(y) - 6.0, 1.0);
    }
  }
}

void DrawHeatMap(cairo_t* cr, const HeatMap& map, double width, double height) {
  CheckGrid(map.n_x, map.n_y, map.values.size(), map.x_nodes, map.y_nodes, map.title);
  const Range x_extent = CellExtent(map.x_nodes);
  const Range y_extent = CellExtent(map.y_nodes);
  const TitleLayout title = LayOutTitle(cr, map.title, width);
  Frame frame{PlotArea(width, height, title.ExtraPt(), kColourBarWidth_pt + 62.0),
              ResolveRange(map.x, x_extent.low, x_extent.high, false),
              ResolveRange(map.y, y_extent.low, y_extent.high, false)};
  if (map.equal_aspect) frame = EqualAspect(frame);
  const Range colours = ColourRange(map.values, map.colour_min, map.colour_max);
  SurfacePtr image =
      GridImage(map.n_x, map.n_y, [&](std::size_t i0, std::size_t i1, std::size_t j0, std::size_t j1) {
        double sum = 0.0;
        int count = 0;
        for (std::size_t i = i0; i < i1; ++i) {
          for (std::size_t j = j0; j < j1; ++j) {
            const double v = map.values[i * map.n_y + j];
            if (std::isfinite(v)) {
              sum += v;
              ++count;
            }
          }
        }
        return count == 0 ? kMissingColour
                          : Viridis((sum / count - colours.low) / (colours.high - colours.low));
      });
  DrawTitle(cr, title, width);
  PaintGridImage(cr, frame, image.get(), x_extent, y_extent);
  DrawYMarks(cr, frame, map.y_marks, map.y_marks_label);
  DrawAxes(cr, frame, map.x, map.y, false);
  DrawColourBar(cr, frame.area, colours, map.colour_bar_label);
}

void DrawPathMap(cairo_t* cr, const PathMap& map, double width, double height) {
  ARCWHEEL_CHECK(map.y_points.size() == map.x_points.size() && map.values.size() == map.x_points.size())
      << "path '" << map.title << "' sizes do not match";
  double x_low = INFINITY, x_high = -INFINITY, y_low = INFINITY, y_high = -INFINITY;
  for (std::size_t k = 0; k < map.x_points.size(); ++k) {
    Extend(map.x_points[k], x_low, x_high);
    Extend(map.y_points[k], y_low, y_high);
  }
  for (const Series& overlay : map.overlays) {
    CheckSeries(overlay);
    for (std::size_t i = 0; i < overlay.x.size(); ++i) {
      Extend(overlay.x[i], x_low, x_high);
      Extend(overlay.y[i], y_low, y_high);
    }
  }
  const TitleLayout title = LayOutTitle(cr, map.title, width);
  Frame frame{PlotArea(width, height, title.ExtraPt(), kColourBarWidth_pt + 62.0),
              ResolveRange(map.x, x_low, x_high, true), ResolveRange(map.y, y_low, y_high, true)};
  if (map.equal_aspect) frame = EqualAspect(frame);
  const Range colours = ColourRange(map.values, map.colour_min, map.colour_max);
  DrawTitle(cr, title, width);
  DrawAxes(cr, frame, map.x, map.y, true);
  cairo_save(cr);
  cairo_rectangle(cr, frame.area.x, frame.area.y, frame.area.width, frame.area.height);
  cairo_clip(cr);
  cairo_set_line_width(cr, 1.2);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (std::size_t k = 1; k < map.x_points.size(); ++k) {
    const double x0 = map.x_points[k - 1], y0 = map.y_points[k - 1], x1 = map.x_points[k],
                 y1 = map.y_points[k];
    if (!std::isfinite(x0) || !std::isfinite(y0) || !std::isfinite(x1) || !std::isfinite(y1)) continue;
    SetColour(cr, Viridis((map.values[k] - colours.low) / (colours.high - colours.low)));
    cairo_move_to(cr, frame.Px(x0), frame.Py(y0));
    cairo_line_to(cr, frame.Px(x1), frame.Py(y1));
    cairo_stroke(cr);
  }
  for (const Series& overlay : map.overlays) DrawSeries(cr, frame, overlay);
  cairo_restore(cr);
  DrawColourBar(cr, frame.area, colours, map.colour_bar_label);
}

void DrawCategoryMap(cairo_t* cr, const CategoryMap& map, double width, double height) {
  CheckGrid(map.n_x, map.n_y, map.codes.size(), map.x_nodes, map.y_nodes, map.title);
  for (std::uint8_t code : map.codes)
    ARCWHEEL_CHECK(code < map.categories.size()) << "category " << int{code};
  const Range x_extent = CellExtent(map.x_nodes);
  const Range y_extent = CellExtent(map.y_nodes);
  std::vector<LegendEntry> legend;
  for (const Category& category : map.categories)
    legend.push_back({category.label, category.colour, LegendEntry::Swatch::kBox});
  const double legend_width = width - 58.0;
  const TitleLayout title = LayOutTitle(cr, map.title, width);
  const Frame frame{
      PlotArea(width, height, title.ExtraPt() + LegendRows(cr, legend, legend_width) * kLegendRow_pt, 0.0),
      ResolveRange(map.x, x_extent.low, x_extent.high, false),
      ResolveRange(map.y, y_extent.low, y_extent.high, false)};
  // Display blocks at least ~3 pt wide and tall, so that a lone flagged cell stays visible.
  const auto max_columns = static_cast<std::size_t>(std::max(1.0, frame.area.width / 3.0));
  const auto max_rows = static_cast<std::size_t>(std::max(1.0, frame.area.height / 3.0));
  // When cells are merged for display the highest code wins, so a lone missing cell still shows.
  SurfacePtr image = GridImage(
      map.n_x, map.n_y,
      [&](std::size_t i0, std::size_t i1, std::size_t j0, std::size_t j1) {
        std::uint8_t worst = 0;
        for (std::size_t i = i0; i < i1; ++i) {
          for (std::size_t j = j0; j < j1; ++j) worst = std::max(worst, map.codes[i * map.n_y + j]);
        }
        return map.categories[worst].colour;
      },
      map.coarse_display ? max_columns : kMaxImageColumns, map.coarse_display ? max_rows : kMaxImageRows);
  DrawTitle(cr, title, width);
  DrawLegend(cr, legend, frame.area.x, 18.0 + title.ExtraPt() + kLegendRow_pt / 2.0, legend_width);
  PaintGridImage(cr, frame, image.get(), x_extent, y_extent);
  DrawYMarks(cr, frame, map.y_marks, map.y_marks_label);
  DrawAxes(cr, frame, map.x, map.y, false);
}

cairo_status_t AppendToString(void* closure, const unsigned char* data, unsigned int length) {
  static_cast<std::string*>(closure)->append(reinterpret_cast<const char*>(data), length);
  return CAIRO_STATUS_SUCCESS;
}

void CheckSurface(cairo_surface_t* surface, const char* what) {
  const cairo_status_t status = cairo_surface_status(surface);
  if (status != CAIRO_STATUS_SUCCESS) {
    throw Error(ErrorCode::kIo, "reports.plot", std::string(what) + ": " + cairo_status_to_string(status));
  }
}

std::string ReplaceAll(std::string text, const std::string& from, const std::string& to) {
  std::string result;
  result.reserve(text.size() + text.size() / 16);
  std::size_t start = 0;
  for (std::size_t hit = text.find(from); hit != std::string::npos; hit = text.find(from, start)) {
    result.append(text, start, hit - start).append(to);
    start = hit + from.size();
  }
  result.append(text, start, std::string::npos);
  return result;
}

}  // namespace

Rgb SeriesColour(int index) {
  static constexpr std::array<Rgb, 7> kOkabeIto = {{{0.000, 0.447, 0.698},
                                                    {0.835, 0.369, 0.000},
                                                    {0.000, 0.620, 0.451},
                                                    {0.800, 0.475, 0.655},
                                                    {0.902, 0.624, 0.000},
                                                    {0.337, 0.706, 0.914},
                                                    {0.000, 0.000, 0.000}}};
  return kOkabeIto[static_cast<std::size_t>(index) % kOkabeIto.size()];
}

Rgb Viridis(double t) {
  // viridis at t = k / 9, k = 0..9 (#440154 ... #FDE725).
  static constexpr std::array<std::array<int, 3>, 10> kStops = {{{0x44, 0x01, 0x54},
                                                                 {0x48, 0x28, 0x78},
                                                                 {0x3E, 0x4A, 0x89},
                                                                 {0x31, 0x68, 0x8E},
                                                                 {0x26, 0x82, 0x8E},
                                                                 {0x1F, 0x9E, 0x89},
                                                                 {0x35, 0xB7, 0x79},
                                                                 {0x6D, 0xCD, 0x59},
                                                                 {0xB4, 0xDE, 0x2C},
                                                                 {0xFD, 0xE7, 0x25}}};
  if (std::isnan(t)) return kMissingColour;
  const double position = std::clamp(t, 0.0, 1.0) * (kStops.size() - 1);
  const auto k = std::min(static_cast<std::size_t>(position), kStops.size() - 2);
  const double f = position - static_cast<double>(k);
  auto channel = [&](int c) { return ((1.0 - f) * kStops[k][c] + f * kStops[k + 1][c]) / 255.0; };
  return {channel(0), channel(1), channel(2)};
}

double NiceStep(double low, double high, int max_ticks) {
  ARCWHEEL_CHECK(std::isfinite(low) && std::isfinite(high) && low < high && max_ticks >= 2)
      << "NiceStep(" << low << ", " << high << ", " << max_ticks << ")";
  const double span = high - low;
  double magnitude = std::pow(10.0, std::floor(std::log10(span / max_ticks)) - 1.0);
  // Walk up the 1-2-5 ladder until the ticks fit.
  for (;;) {
    for (double factor : {1.0, 2.0, 5.0}) {
      const double step = factor * magnitude;
      const double count = std::floor(high / step + 1e-9) - std::ceil(low / step - 1e-9) + 1.0;
      if (count <= max_ticks) return step;
    }
    magnitude *= 10.0;
  }
}

std::vector<double> NiceTicks(double low, double high, int max_ticks) {
  const double step = NiceStep(low, high, max_ticks);
  std::vector<double> ticks;
  const auto first = static_cast<long long>(std::ceil(low / step - 1e-9));
  const auto last = static_cast<long long>(std::floor(high / step + 1e-9));
  for (long long k = first; k <= last; ++k) {
    const double tick = static_cast<double>(k) * step;
    ticks.push_back(tick == 0.0 ? 0.0 : tick);  // no "-0"
  }
  return ticks;
}

std::string FormatTick(double value, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find_first_not_of("-0.") == std::string::npos) text = fmt::format("{:.{}f}", 0.0, decimals);
  // The typographic minus: a hyphen reads as a dash.
  if (text.front() == '-') text.replace(0, 1, "−");
  return text;
}

void Draw(cairo_t* cr, const Figure& figure, double width_pt, double height_pt) {
  cairo_save(cr);
  cairo_rectangle(cr, 0.0, 0.0, width_pt, height_pt);
  cairo_set_source_rgb(cr, 1.0, 1.0, 1.0);
  cairo_fill(cr);
  std::visit(
      [&](const auto& plot) {
        using T = std::decay_t<decltype(plot)>;
        if constexpr (std::is_same_v<T, LinePlot>) DrawLinePlot(cr, plot, width_pt, height_pt);
        if constexpr (std::is_same_v<T, HeatMap>) DrawHeatMap(cr, plot, width_pt, height_pt);
        if constexpr (std::is_same_v<T, CategoryMap>) DrawCategoryMap(cr, plot, width_pt, height_pt);
        if constexpr (std::is_same_v<T, PathMap>) DrawPathMap(cr, plot, width_pt, height_pt);
      },
      figure);
  cairo_restore(cr);
}

std::string RenderSvg(const Figure& figure, double width_pt, double height_pt, const std::string& id_prefix) {
  std::string svg;
  {
    SurfacePtr surface(cairo_svg_surface_create_for_stream(AppendToString, &svg, width_pt, height_pt),
                       cairo_surface_destroy);
    CheckSurface(surface.get(), "cannot create an SVG surface");
    {
      // Owned, so that a figure that throws while drawing does not keep the surface alive.
      const ContextPtr cr(cairo_create(surface.get()), cairo_destroy);
      Draw(cr.get(), figure, width_pt, height_pt);
    }
    cairo_surface_finish(surface.get());
    CheckSurface(surface.get(), "cannot draw the SVG plot");
  }
  // Inline use: drop the XML prolog and make ids unique within the HTML document.
  const std::size_t svg_start = svg.find("<svg");
  ARCWHEEL_CHECK(svg_start != std::string::npos) << "cairo wrote no <svg> element";
  svg.erase(0, svg_start);
  svg = ReplaceAll(std::move(svg), "id=\"", "id=\"" + id_prefix);
  svg = ReplaceAll(std::move(svg), "href=\"#", "href=\"#" + id_prefix);
  return ReplaceAll(std::move(svg), "url(#", "url(#" + id_prefix);
}

std::string RenderPng(const Figure& figure, double width_pt, double height_pt, double pixels_per_pt) {
  const int width_px = static_cast<int>(std::ceil(width_pt * pixels_per_pt));
  const int height_px = static_cast<int>(std::ceil(height_pt * pixels_per_pt));
  SurfacePtr surface(cairo_image_surface_create(CAIRO_FORMAT_ARGB32, width_px, height_px),
                     cairo_surface_destroy);
  CheckSurface(surface.get(), "cannot create a PNG image");
  {
    const ContextPtr cr(cairo_create(surface.get()), cairo_destroy);
    cairo_scale(cr.get(), pixels_per_pt, pixels_per_pt);
    Draw(cr.get(), figure, width_pt, height_pt);
  }
  std::string png;
  if (cairo_surface_write_to_png_stream(surface.get(), AppendToString, &png) != CAIRO_STATUS_SUCCESS) {
    throw Error(ErrorCode::kIo, "reports.plot", "cannot encode the PNG image");
  }
  return png;
}

}  // namespace arcwheel::reports::plot
