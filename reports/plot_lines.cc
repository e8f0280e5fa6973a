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
#include "reports/plot_frame.h"

namespace arcwheel::reports::plot::internal {

void CheckSeries(const Series& series) {
  ARCWHEEL_CHECK(series.x.size() == series.y.size())
      << "series '" << series.label << "' x and y differ in size";
  ARCWHEEL_CHECK(series.y_error.empty() || series.y_error.size() == series.x.size())
      << "series '" << series.label << "' error bars do not match its points";
  ARCWHEEL_CHECK(series.band_low.size() == series.band_high.size() &&
                 (series.band_low.empty() || series.band_low.size() == series.x.size()))
      << "series '" << series.label << "' band does not match its points";
}

namespace {

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

}  // namespace

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

}  // namespace arcwheel::reports::plot::internal
