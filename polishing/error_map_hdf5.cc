// Error maps in arcwheel's own HDF5 grid map (schema/grid_map.h): read and written.
#include <fmt/core.h>

#include <cmath>
#include <cstddef>
#include <filesystem>
#include <string>
#include <string_view>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "polishing/error_map_io.h"
#include "polishing/error_map_io_impl.h"
#include "schema/grid_map.h"

namespace arcwheel::polishing {
namespace {

using namespace internal;

// Largest grid any reader builds (8e8 bytes of doubles).
constexpr double kMaxNodes = 1e8;

}  // namespace

ErrorMap ReadErrorMapHdf5(const hdf5::File& file) {
  const std::string name = file.path().string();
  // Any grid-map layout: arcwheel's grid map, the older polish grid, a prediction.h5 of before.
  const schema::grid_map::Location at = schema::grid_map::LocateGridMap(file, kStage);
  const std::string dataset = at.error_dataset.substr(1);
  if (at.nx == 0 || at.ny == 0 || static_cast<double>(at.nx) * static_cast<double>(at.ny) > kMaxNodes)
    Fail(name, fmt::format("dataset '{}' must be [ny][nx] with 1 .. 1e8 nodes", dataset));
  CheckMapNodes(name, fmt::format("dataset '{}'", dataset), at.ny, at.nx);
  ErrorMap map;
  map.grid = {
      .x0_mm = at.x0_mm, .y0_mm = at.y0_mm, .dx_mm = at.dx_mm, .dy_mm = at.dy_mm, .nx = at.nx, .ny = at.ny};
  map.error_um = file.ReadDoubles(at.error_dataset);
  const auto nx = static_cast<std::size_t>(at.nx);
  for (std::size_t k = 0; k < map.error_um.size(); ++k) {
    if (std::isinf(map.error_um[k])) {
      Fail(name, fmt::format("dataset '{}' value [{}][{}] = {} {}", dataset, k / nx, k % nx, map.error_um[k],
                             kInfinityIsDamage));
    }
  }
  return map;
}

ErrorMap ReadErrorMapHdf5(const std::filesystem::path& path) {
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadErrorMapHdf5(hdf5::File::OpenReadOnly(path)); });
  return ReadErrorMapHdf5(hdf5::File::OpenReadOnly(path));
}

void WriteErrorMapHdf5(const ErrorMap& map, const std::filesystem::path& path) {
  OutputSet outputs;
  const std::filesystem::path temporary = outputs.Stage(path);
  schema::grid_map::WriteGridMap(GridMapContent(map, schema::grid_map::kErrorMap), temporary);
  outputs.Commit();
}

schema::grid_map::Content GridMapContent(const ErrorMap& map, std::string_view quantity) {
  return {.x0_mm = map.grid.x0_mm,
          .y0_mm = map.grid.y0_mm,
          .dx_mm = map.grid.dx_mm,
          .dy_mm = map.grid.dy_mm,
          .nx = map.grid.nx,
          .ny = map.grid.ny,
          .error_um = map.error_um,
          .quantity = std::string(quantity)};
}

}  // namespace arcwheel::polishing
