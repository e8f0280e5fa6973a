#include "reports/plot_frame.h"

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

namespace arcwheel::reports::plot::internal {

void SetColour(cairo_t* cr, const Rgb& colour, double alpha) {
  cairo_set_source_rgba(cr, colour.r, colour.g, colour.b, alpha);
}

void SetFont(cairo_t* cr, double size_pt, bool bold) {
  cairo_select_font_face(cr, kFont, CAIRO_FONT_SLANT_NORMAL,
                         bold ? CAIRO_FONT_WEIGHT_BOLD : CAIRO_FONT_WEIGHT_NORMAL);
  cairo_set_font_size(cr, size_pt);
}

double TextWidth(cairo_t* cr, const std::string& text) {
  cairo_text_extents_t extents;
  cairo_text_extents(cr, text.c_str(), &extents);
  return extents.x_advance;
}

void DrawText(cairo_t* cr, const std::string& text, double x, double y, double align_x, double angle_rad) {
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

Rect PlotArea(double width, double height, double extra_top_pt, double right_pt) {
  constexpr double kLeft = 50.0;
  constexpr double kBottom = 30.0;
  const double top = 18.0 + extra_top_pt;
  return {kLeft, top, std::max(10.0, width - kLeft - right_pt - 8.0), std::max(10.0, height - top - kBottom)};
}

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

double LegendEntryWidth(cairo_t* cr, const LegendEntry& entry) {
  SetFont(cr, kLabelSize_pt);
  return 18.0 + TextWidth(cr, entry.label) + 14.0;
}

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

}  // namespace arcwheel::reports::plot::internal
