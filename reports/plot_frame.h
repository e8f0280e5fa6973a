#pragma once
// What the files of the plotting layer share (reports/plot.h is the interface): the frame of a
// plot, its axes, title and legend, and the painters of each kind of figure.

#include <cairo.h>

#include <cstddef>
#include <memory>
#include <string>
#include <vector>

#include "reports/plot.h"

namespace arcwheel::reports::plot::internal {

inline constexpr const char* kFont = "DejaVu Sans";
inline constexpr double kTitleSize_pt = 10.0;
inline constexpr double kLabelSize_pt = 8.0;
inline constexpr double kLegendRow_pt = 13.0;
inline constexpr double kColourBarWidth_pt = 10.0;

// Display resolution of a heat map: larger grids are averaged down in blocks, which keeps the
// embedded image small without hiding anything a reader can see at page size.
inline constexpr std::size_t kMaxImageColumns = 720;
inline constexpr std::size_t kMaxImageRows = 480;
inline const Rgb kMissingColour{0.80, 0.80, 0.80};
inline const Rgb kInk{0.15, 0.15, 0.15};
inline const Rgb kGrid{0.88, 0.88, 0.88};
inline const Rgb kMarkColour{0.60, 0.10, 0.45};

// Owners of cairo objects.
using SurfacePtr = std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)>;
using ContextPtr = std::unique_ptr<cairo_t, decltype(&cairo_destroy)>;

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

void SetColour(cairo_t* cr, const Rgb& colour, double alpha = 1.0);

void SetFont(cairo_t* cr, double size_pt, bool bold = false);

double TextWidth(cairo_t* cr, const std::string& text);

// Writes `text` with its anchor at (x, y): align_x 0 left, 0.5 centre, 1 right; the baseline is
// placed so that the text's middle is at y. `angle_rad` turns it about the anchor.
void DrawText(cairo_t* cr, const std::string& text, double x, double y, double align_x,
              double angle_rad = 0.0);

Range Padded(double low, double high);

void Extend(double value, double& low, double& high);

Range ResolveRange(const Axis& axis, double data_low, double data_high, bool pad);

// Lays out title, legend rows and axes inside width x height: `extra_top_pt` below a one-line title
// (further title lines, legend rows), `right_pt` kept free on the right.
Rect PlotArea(double width, double height, double extra_top_pt, double right_pt);

// A title that fits the figure's width: on one line at 10 pt, else shrunk down to 8.5 pt, else
// wrapped at spaces at 8.5 pt (a phone's narrow figure).
struct TitleLayout {
  std::vector<std::string> lines;
  double size_pt = kTitleSize_pt;
  // Height beyond the one line PlotArea always leaves.
  [[nodiscard]] double ExtraPt() const { return static_cast<double>(lines.size() - 1) * (size_pt + 2.0); }
};

TitleLayout LayOutTitle(cairo_t* cr, const std::string& title, double width);

void DrawTitle(cairo_t* cr, const TitleLayout& title, double width);

// At least three ticks, so that a small plot (a map half a page wide) still shows a scale on
// both sides of zero.
int MaxTicks(double length_pt, double spacing_pt);

void DrawAxes(cairo_t* cr, const Frame& frame, const Axis& x_axis, const Axis& y_axis, bool grid);

struct LegendEntry {
  std::string label;
  Rgb colour;
  enum class Swatch { kLine, kDashed, kDot, kBox } swatch = Swatch::kLine;
};

double LegendEntryWidth(cairo_t* cr, const LegendEntry& entry);

// Rows the legend takes when wrapped to `width` (0 without entries).
int LegendRows(cairo_t* cr, const std::vector<LegendEntry>& entries, double width);

// Entries left to right from (x, y), wrapped onto further rows at `width`.
void DrawLegend(cairo_t* cr, const std::vector<LegendEntry>& entries, double x, double y, double width);

// Checks (ARCWHEEL_CHECK) that a series' x, y, error bars and band match in size (plot_lines.cc).
void CheckSeries(const Series& series);
// Draws a series as its style says, with its band and error bars (plot_lines.cc).
void DrawSeries(cairo_t* cr, const Frame& frame, const Series& series);

// The painters of each kind of figure (plot_lines.cc, plot_maps.cc).
void DrawLinePlot(cairo_t* cr, const LinePlot& plot, double width, double height);
void DrawHeatMap(cairo_t* cr, const HeatMap& map, double width, double height);
void DrawPathMap(cairo_t* cr, const PathMap& map, double width, double height);
void DrawCategoryMap(cairo_t* cr, const CategoryMap& map, double width, double height);

}  // namespace arcwheel::reports::plot::internal
