#pragma once
// The project's one plotting layer. A figure is a plain description (line plot, heat map,
// category map or coloured path); Draw() paints it with cairo, so the same drawing code makes the inline SVG
// of the HTML report, the vector plots of the PDF report and PNG images.
//
// Lengths are in points (1/72 inch); colours are sRGB in [0, 1]. Axis labels carry their unit,
// e.g. "phase (deg)". Ticks fall on round numbers: steps of 1, 2 or 5 times a power of ten.

#include <cairo.h>

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace arcwheel::reports::plot {

struct Rgb {
  double r = 0.0;
  double g = 0.0;
  double b = 0.0;
};

// A colour-blind safe palette (Okabe & Ito 2008) for line series, in legend order.
[[nodiscard]] Rgb SeriesColour(int index);

// The viridis perceptual colour map (van der Walt & Smith, matplotlib 2.0), tabulated at ten
// stops and interpolated linearly in sRGB. `t` is clamped to [0, 1]; 0 is dark purple, 1 yellow.
[[nodiscard]] Rgb Viridis(double t);

// Round tick positions covering [low, high]: multiples of a step 1, 2 or 5 x 10^k chosen so that
// there are at most `max_ticks` and as many as possible. Precondition: low < high, both finite.
[[nodiscard]] std::vector<double> NiceTicks(double low, double high, int max_ticks);
// The step NiceTicks uses for the same arguments.
[[nodiscard]] double NiceStep(double low, double high, int max_ticks);
// Width (points) at which the HTML reports draw a figure for a phone screen: shown about 370 px
// wide there, its 7 pt tick labels render near 9 px.
inline constexpr double kPhoneFigureWidth_pt = 280.0;
// Tick label size, the smallest text of a figure.
inline constexpr double kTickSize_pt = 7.0;

// Tick label with as many decimals as `step` needs ("0.25" for step 0.05 -> "0.25"), negative
// values with the minus sign U+2212 ("−0.25").
[[nodiscard]] std::string FormatTick(double value, double step);

struct Axis {
  std::string label;  // with the unit, e.g. "axial position y (mm)"
  // Fixed range; when absent the range is that of the data, padded by 4 % on each side.
  std::optional<double> min = std::nullopt;
  std::optional<double> max = std::nullopt;
};

struct Series {
  std::string label;  // shown in the legend when the plot has more than one series
  std::vector<double> x;
  std::vector<double> y;  // NaN breaks the line
  // Optional shaded band (e.g. y -/+ 1 sigma): both empty or both of the size of x.
  std::vector<double> band_low;
  std::vector<double> band_high;
  Rgb colour;
  bool markers = false;  // dots at the points instead of a line
  bool dashed = false;
  // Optional error bars y -/+ y_error: empty or of the size of x.
  std::vector<double> y_error = {};
  double marker_size_pt = 1.1;  // radius of the dots
};

// A shaded x interval with a label, e.g. the band of the wheel used for the fits.
struct XSpan {
  double low = 0.0;
  double high = 0.0;
  std::string label;
};

struct LinePlot {
  std::string title;
  Axis x;
  Axis y;
  std::vector<Series> series;
  std::vector<XSpan> spans;
  // Dashed vertical lines at these x values (e.g. dressings), one legend entry `x_marks_label`.
  std::vector<double> x_marks = {};
  std::string x_marks_label = {};
};

// A continuous field on a regular grid, coloured with viridis and explained by a colour bar.
struct HeatMap {
  std::string title;
  Axis x;
  Axis y;
  std::size_t n_x = 0;
  std::size_t n_y = 0;
  // Row-major [n_x, n_y]: value (i, j) at index i * n_y + j, at x_nodes[i], y_nodes[j]. NaN cells
  // are drawn grey.
  std::vector<double> values;
  std::vector<double> x_nodes;   // strictly increasing, size n_x
  std::vector<double> y_nodes;   // strictly increasing, size n_y
  std::string colour_bar_label;  // with the unit, e.g. "form error (um)"
  // Colour range; when absent, the 0.5 and 99.5 percentiles of the finite values (so that a few
  // extreme cells do not wash out the rest; cells beyond the range take the end colours).
  std::optional<double> colour_min;
  std::optional<double> colour_max;
  // One unit of x as long as one unit of y on the page (a disc stays round); the plot area
  // shrinks to keep it.
  bool equal_aspect = false;
  // Dashed lines across the map at these y values (e.g. the band used for the fits), with a label.
  std::vector<double> y_marks;
  std::string y_marks_label;
};

// A path in the plane coloured by a value along it (viridis, with a colour bar), e.g. a tool
// path coloured by speed: the segment from point k-1 to point k takes the colour of values[k].
// `overlays` are line series drawn on top (e.g. an outline), without a legend.
struct PathMap {
  std::string title;
  Axis x;
  Axis y;
  std::vector<double> x_points;
  std::vector<double> y_points;  // size of x_points
  std::vector<double> values;    // size of x_points
  std::string colour_bar_label;  // with the unit, e.g. "speed (mm/s)"
  // Colour range; when absent, the 0.5 and 99.5 percentiles of the finite values (as HeatMap).
  std::optional<double> colour_min;
  std::optional<double> colour_max;
  std::vector<Series> overlays;
  bool equal_aspect = true;
};

struct Category {
  std::string label;
  Rgb colour;
};

// A grid of categories (e.g. "no samples" / "despiked" / "ok") with a legend.
struct CategoryMap {
  std::string title;
  Axis x;
  Axis y;
  std::size_t n_x = 0;
  std::size_t n_y = 0;
  std::vector<std::uint8_t> codes;  // row-major [n_x, n_y], each an index into categories
  std::vector<double> x_nodes;
  std::vector<double> y_nodes;
  std::vector<Category> categories;
  // As HeatMap::y_marks.
  std::vector<double> y_marks;
  std::string y_marks_label;
  // Merge cells into display blocks of at least 3 x 3 pt (the worst cell of a block wins), so
  // that a lone flagged cell of a large grid is seen rather than a speck.
  bool coarse_display = false;
};

using Figure = std::variant<LinePlot, HeatMap, CategoryMap, PathMap>;

// Paints `figure` into the rectangle [0, width_pt] x [0, height_pt] of the current user space
// of `cr` (translate first to place it). Throws Error{kInternal} on malformed figures (sizes
// that do not match), which are bugs of the caller.
void Draw(cairo_t* cr, const Figure& figure, double width_pt, double height_pt);

// The figure as a standalone <svg> element (no XML prolog) for inlining in HTML. Every id in it
// starts with `id_prefix`, so several figures can share one HTML document.
[[nodiscard]] std::string RenderSvg(const Figure& figure, double width_pt, double height_pt,
                                    const std::string& id_prefix);

// The figure as PNG bytes, `pixels_per_pt` pixels per point.
[[nodiscard]] std::string RenderPng(const Figure& figure, double width_pt, double height_pt,
                                    double pixels_per_pt);

}  // namespace arcwheel::reports::plot
