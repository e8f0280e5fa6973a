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
#include "core/number_format.h"
#include "reports/plot_frame.h"

namespace arcwheel::reports::plot {
namespace {

using namespace internal;

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
  std::string text = ShowFixed(value, decimals);
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
