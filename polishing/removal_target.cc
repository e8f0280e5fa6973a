#include "polishing/removal_target.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kRemovalTargetStage = "polishing.target";

void CheckGrid(const ErrorMap& map) {
  if (map.grid.nx < 1 || map.grid.ny < 1 || !(map.grid.dx_mm > 0.0) || !(map.grid.dy_mm > 0.0) ||
      map.error_um.size() != static_cast<std::size_t>(map.grid.nx) * map.grid.ny) {
    throw Error(ErrorCode::kInvalidOption, kRemovalTargetStage,
                fmt::format("error map grid {} x {} nodes, spacing {} x {} mm with {} values is "
                            "malformed",
                            map.grid.nx, map.grid.ny, map.grid.dx_mm, map.grid.dy_mm, map.error_um.size()));
  }
}

}  // namespace

MapStatistics StatisticsInAperture(const ErrorMap& map, const surfaces::Aperture& aperture) {
  double lo = std::numeric_limits<double>::infinity(), hi = -lo, sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int j = 0; j < map.grid.ny; ++j) {
    for (int i = 0; i < map.grid.nx; ++i) {
      const double v = map.At(i, j);
      if (!std::isfinite(v) || !aperture.Contains(map.grid.X(i), map.grid.Y(j))) continue;
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      sum += v;
      ++n;
    }
  }
  if (n == 0) return {};
  const double mean = sum / n;
  for (int j = 0; j < map.grid.ny; ++j) {
    for (int i = 0; i < map.grid.nx; ++i) {
      const double v = map.At(i, j);
      if (std::isfinite(v) && aperture.Contains(map.grid.X(i), map.grid.Y(j)))
        sum2 += (v - mean) * (v - mean);
    }
  }
  return {hi - lo, std::sqrt(sum2 / n), n};
}

ErrorMap RemovalTarget(const ErrorMap& error, const surfaces::Aperture& aperture,
                       const RemovalTargetOptions& options) {
  CheckGrid(error);
  if (!(options.uniform_layer_um >= 0.0) || !std::isfinite(options.uniform_layer_um)) {
    throw Error(ErrorCode::kInvalidOption, kRemovalTargetStage,
                fmt::format("uniform_layer_um = {} violates >= 0", options.uniform_layer_um));
  }
  double minimum = std::numeric_limits<double>::infinity();
  for (int j = 0; j < error.grid.ny; ++j) {
    for (int i = 0; i < error.grid.nx; ++i) {
      if (std::isfinite(error.At(i, j)) && aperture.Contains(error.grid.X(i), error.grid.Y(j))) {
        minimum = std::min(minimum, error.At(i, j));
      }
    }
  }
  if (!std::isfinite(minimum)) {
    throw Error(
        ErrorCode::kBadInput, kRemovalTargetStage,
        fmt::format("empty aperture: no error-map node with data lies inside {}", aperture.Describe()));
  }
  ErrorMap target = error;
  for (int j = 0; j < error.grid.ny; ++j) {
    for (int i = 0; i < error.grid.nx; ++i) {
      double& v = target.error_um[static_cast<std::size_t>(j) * error.grid.nx + i];
      v = std::isfinite(v) && aperture.Contains(error.grid.X(i), error.grid.Y(j))
              ? v - minimum + options.uniform_layer_um
              : std::numeric_limits<double>::quiet_NaN();
    }
  }
  return target;
}

double PolynomialProfileSagMm(std::span<const double> c, double y_mm) {
  if (c.size() < 2 || c[0] != 0.0 || !(c[1] > 0.0)) {
    throw Error(ErrorCode::kBadInput, kRemovalTargetStage,
                "the profile y^2 = sum c_i x^i needs c_0 = 0 and c_1 > 0 (a vertex at the origin)");
  }
  const double y2 = y_mm * y_mm;
  auto value = [&](double x) {
    double v = 0.0;
    for (std::size_t i = c.size(); i-- > 0;) v = v * x + c[i];
    return v - y2;
  };
  auto slope = [&](double x) {
    double v = 0.0;
    for (std::size_t i = c.size(); i-- > 1;) v = v * x + static_cast<double>(i) * c[i];
    return v;
  };
  // The vertex sphere (radius c_1 / 2) as the start: within a few iterations of the root.
  const double r0 = c[1] / 2.0;
  double x = std::abs(y_mm) < r0 ? r0 - std::sqrt(r0 * r0 - y2) : y2 / c[1];
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double d = slope(x);
    if (!(d > 0.0)) break;
    const double step = value(x) / d;
    x -= step;
    if (std::abs(step) <= 1e-12) {  // 1 pm: far below any figure we report
      return x;
    }
  }
  throw Error(ErrorCode::kBadInput, kRemovalTargetStage,
              fmt::format("the profile has no sag through the vertex at radius {} mm", y_mm));
}

double SphereSagMm(double radius_mm, double y_mm) {
  return radius_mm - std::sqrt(radius_mm * radius_mm - y_mm * y_mm);
}

std::vector<std::string> RemovalTargetOptions::Problems() const {
  if (uniform_layer_um >= 0.0) return {};
  return {fmt::format("removal_target.uniform_layer_um = {} violates >= 0", uniform_layer_um)};
}

}  // namespace arcwheel::polishing
