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
namespace {

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

}  // namespace

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

}  // namespace arcwheel::reports::plot::internal
