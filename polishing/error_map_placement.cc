// Interferometer pixel maps placed in the part frame (polishing/error_map_io.h, steps 1-5).
#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <string>

#include "core/error.h"
#include "polishing/error_map_io.h"
#include "polishing/error_map_io_impl.h"

namespace arcwheel::polishing {
using namespace internal;

ErrorMap PlaceInPartFrame(const PixelMap& pixels, const MapPlacement& placement, const std::string& name) {
  if (pixels.width <= 0 || pixels.height <= 0 ||
      pixels.height_um.size() !=
          static_cast<std::size_t>(pixels.width) * static_cast<std::size_t>(pixels.height)) {
    Fail(name, fmt::format("pixel map of {} x {} pixels holds {} values", pixels.width, pixels.height,
                           pixels.height_um.size()));
  }
  const int quarter_turns = placement.rotation_deg / 90;
  if (placement.rotation_deg % 90 != 0 || quarter_turns < 0 || quarter_turns > 3) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("rotation_deg = {} is not 0, 90, 180 or 270", placement.rotation_deg));
  }
  if (!std::isfinite(placement.scale) || placement.scale == 0.0) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("scale = {} must be finite and non-zero", placement.scale));
  }
  if (!std::isnan(placement.pixel_mm) && !(placement.pixel_mm > 0.0 && std::isfinite(placement.pixel_mm))) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("pixel_mm = {} must be > 0", placement.pixel_mm));
  }
  const double px = std::isnan(placement.pixel_mm) ? pixels.pixel_x_mm : placement.pixel_mm;
  const double py = std::isnan(placement.pixel_mm) ? pixels.pixel_y_mm : placement.pixel_mm;
  if (!(px > 0.0 && std::isfinite(px) && py > 0.0 && std::isfinite(py))) {
    Fail(name, "gives no lateral resolution: set error_map.pixel_mm (mm per pixel)");
  }
  const std::array<double, 2> centre = ValidDataCentrePx(pixels, name);
  const double ci = std::isnan(placement.centre_column) ? centre[0] : placement.centre_column;
  const double cj = std::isnan(placement.centre_row) ? centre[1] : placement.centre_row;
  if (!std::isfinite(ci) || !std::isfinite(cj)) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("centre pixel ({}, {}) must be finite", ci, cj));
  }
  // Pixel (i, j) -> part frame, steps 1-4 of error_map_io.h.
  auto place = [&](int i, int j) {
    double u = (i - ci) * px, v = (cj - j) * py;
    if (placement.flip == MapPlacement::Flip::kX) u = -u;
    if (placement.flip == MapPlacement::Flip::kY) v = -v;
    for (int k = 0; k < quarter_turns; ++k) std::tie(u, v) = std::make_pair(-v, u);
    return std::array<double, 2>{u + placement.centre_x_mm, v + placement.centre_y_mm};
  };
  const bool swapped = quarter_turns % 2 == 1;
  ErrorMap map;
  map.grid.nx = swapped ? pixels.height : pixels.width;
  map.grid.ny = swapped ? pixels.width : pixels.height;
  map.grid.dx_mm = swapped ? py : px;
  map.grid.dy_mm = swapped ? px : py;
  map.grid.x0_mm = std::numeric_limits<double>::infinity();
  map.grid.y0_mm = std::numeric_limits<double>::infinity();
  for (const int i : {0, pixels.width - 1}) {
    for (const int j : {0, pixels.height - 1}) {
      const auto p = place(i, j);
      map.grid.x0_mm = std::min(map.grid.x0_mm, p[0]);
      map.grid.y0_mm = std::min(map.grid.y0_mm, p[1]);
    }
  }
  map.error_um.assign(static_cast<std::size_t>(map.grid.nx) * static_cast<std::size_t>(map.grid.ny), kNaN);
  for (int j = 0; j < pixels.height; ++j) {
    for (int i = 0; i < pixels.width; ++i) {
      const double h = pixels.height_um[static_cast<std::size_t>(j) * pixels.width + i];
      if (!std::isfinite(h)) continue;
      const auto p = place(i, j);
      const auto I = static_cast<std::size_t>(std::lround((p[0] - map.grid.x0_mm) / map.grid.dx_mm));
      const auto J = static_cast<std::size_t>(std::lround((p[1] - map.grid.y0_mm) / map.grid.dy_mm));
      map.error_um[J * static_cast<std::size_t>(map.grid.nx) + I] = placement.scale * h;
    }
  }
  return map;
}

std::array<double, 2> ValidDataCentrePx(const PixelMap& pixels, const std::string& name) {
  int i_min = pixels.width, i_max = -1, j_min = pixels.height, j_max = -1;
  for (int j = 0; j < pixels.height; ++j) {
    for (int i = 0; i < pixels.width; ++i) {
      if (!std::isfinite(pixels.height_um[static_cast<std::size_t>(j) * pixels.width + i])) continue;
      i_min = std::min(i_min, i), i_max = std::max(i_max, i);
      j_min = std::min(j_min, j), j_max = std::max(j_max, j);
    }
  }
  if (i_max < 0) Fail(name, fmt::format("no pixel of the {} x {} map has data", pixels.width, pixels.height));
  return {0.5 * (i_min + i_max), 0.5 * (j_min + j_max)};
}

}  // namespace arcwheel::polishing
