// Error maps from CSV: a grid of `x_mm,y_mm,error_um` rows (polishing/grid_csv.h), or scattered
// points for InterpolateScattered.
#include <fmt/core.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "polishing/error_map_io.h"
#include "polishing/error_map_io_impl.h"
#include "polishing/grid_csv.h"

namespace arcwheel::polishing {
namespace {

using namespace internal;

[[noreturn]] void LineFail(const std::filesystem::path& path, std::size_t line, const std::string& what) {
  throw Error(ErrorCode::kBadInput, kStage, fmt::format("'{}' line {}: {}", path.string(), line, what));
}

}  // namespace

ErrorMap ReadErrorMapCsv(const std::filesystem::path& path) {
  CsvGrid grid = ReadCsvGrid(path, "error_um", kStage);
  CheckMapNodes(path.string(), "the grid of its rows", grid.ny, grid.nx);
  for (std::size_t k = 0; k < grid.values.size(); ++k) {
    if (std::isinf(grid.values[k]))
      LineFail(path, grid.lines[k], fmt::format("error_um = {} {}", grid.values[k], kInfinityIsDamage));
  }
  ErrorMap map;
  map.grid.x0_mm = grid.x0_mm;
  map.grid.y0_mm = grid.y0_mm;
  map.grid.dx_mm = grid.dx_mm;
  map.grid.dy_mm = grid.dy_mm;
  map.grid.nx = grid.nx;
  map.grid.ny = grid.ny;
  map.error_um = std::move(grid.values);
  return map;
}

std::vector<ScatteredPoint> ReadScatteredCsv(const std::filesystem::path& path) {
  std::vector<ScatteredPoint> points;
  for (const CsvTriple& n : ReadCsvTriples(path, "error_um", kStage)) {
    if (!std::isfinite(n.value))
      LineFail(path, n.line, "error_um must be finite (leave a scattered point out instead)");
    points.push_back({n.x_mm, n.y_mm, n.value, n.line});
  }
  return points;
}

}  // namespace arcwheel::polishing
