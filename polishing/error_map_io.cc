// The error map's reader by format (ReadErrorMap, FormatFromExtension), and the failures every
// format's reader shares. The formats: error_map_csv.cc, error_map_metropro.cc, error_map_datx.cc,
// error_map_hdf5.cc; scattered points onto a grid: error_map_scattered.cc; pixels into the part
// frame: error_map_placement.cc.
#include "polishing/error_map_io.h"

#include <fmt/core.h>

#include <cctype>
#include <cmath>
#include <string>

#include "core/error.h"
#include "core/memory_budget.h"
#include "polishing/error_map_io_impl.h"

namespace arcwheel::polishing {

namespace internal {

void Fail(const std::string& name, const std::string& what) {
  throw Error(ErrorCode::kBadInput, kStage, fmt::format("'{}': {}", name, what));
}

void CheckMapNodes(const std::string& name, const std::string& what, double rows, double columns) {
  if (const auto problem = MemoryBudgetProblem(fmt::format("'{}': {} [{}][{}]", name, what, rows, columns),
                                               rows * columns, "map nodes", kBytesPerMapNode)) {
    throw Error(ErrorCode::kBadInput, kStage, *problem);
  }
}

}  // namespace internal

namespace {

using namespace internal;

std::string Lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

}  // namespace

ErrorMapFormat FormatFromExtension(const std::filesystem::path& path) {
  const std::string ext = Lower(path.extension().string());
  if (ext == ".csv") return ErrorMapFormat::kCsv;
  if (ext == ".dat") return ErrorMapFormat::kDat;
  if (ext == ".datx") return ErrorMapFormat::kDatx;
  if (ext == ".h5" || ext == ".hdf5") return ErrorMapFormat::kHdf5;
  Fail(path.string(), fmt::format("extension '{}' names no error-map format (.csv, .dat, .datx, .h5)", ext));
}

ErrorMap ReadErrorMap(const std::filesystem::path& path, const ErrorMapOptions& options) {
  switch (options.format) {
    case ErrorMapFormat::kDat:
      return PlaceInPartFrame(ReadMetroProDat(path), options.placement, path.string());
    case ErrorMapFormat::kDatx:
      return PlaceInPartFrame(ReadZygoDatx(path), options.placement, path.string());
    default:
      break;
  }
  const double scale = options.placement.scale;
  if (!std::isfinite(scale) || scale == 0.0) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("scale = {} must be finite and non-zero", scale));
  }
  ErrorMap map;
  if (options.format == ErrorMapFormat::kHdf5) {
    map = ReadErrorMapHdf5(path);
  } else if (options.layout == ErrorMapLayout::kScattered) {
    map = InterpolateScattered(ReadScatteredCsv(path), options.grid_spacing_mm, path.string());
  } else {
    map = ReadErrorMapCsv(path);
  }
  for (double& v : map.error_um) v *= scale;
  return map;
}

}  // namespace arcwheel::polishing
