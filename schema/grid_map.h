#pragma once
// Gridded maps of a surface error over the part frame's (x, y): the form error `arcwheel toolpath`
// predicts (prediction.h5), the residual `arcwheel polish` predicts (residual_map.h5), and any
// error map given to `arcwheel polish` as HDF5. The one place that spells their layout
// (docs/outputs.md, "Grid maps"): the writers (grinding/prediction.cc, polishing/error_map_hdf5.cc)
// and the readers (polishing's error-map reader) use these names and LocateGridMap.
//
// Layout 1.0, everything at the root:
//   /error_um [ny, nx]  float64, um, positive = material above the nominal surface (to remove),
//                       NaN = no data (outside the aperture); node (i, j) at (x0 + i dx, y0 + j dy)
//   /x_mm [nx], /y_mm [ny]  the node coordinates (for readers that want them; the attributes rule)
//   attributes x0_mm, y0_mm, dx_mm, dy_mm, schema_version ("1.0"), quantity (what the map is),
//   arcwheel_version; a writer may add datasets of the same shape (e.g. low_order_um) and
//   numeric attributes (e.g. pv_um, rms_um).
// Readers also take the two layouts written before it (read as version 1.0):
//   - polish's grid: root /error_um and the four grid attributes (a subset of 1.0);
//   - toolpath's prediction: /prediction/error_um [ny, nx] with /prediction/x_mm, /prediction/y_mm.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "core/hdf5.h"
#include "schema/version.h"

namespace arcwheel::schema::grid_map {

inline constexpr int kMajorVersion = 1;
inline constexpr int kMinorVersion = 0;
inline constexpr Version kVersion{kMajorVersion, kMinorVersion};

inline constexpr std::string_view kErrorUm = "/error_um";
inline constexpr std::string_view kXMm = "/x_mm";
inline constexpr std::string_view kYMm = "/y_mm";

inline constexpr std::string_view kRoot = "/";
inline constexpr std::string_view kX0MmAttribute = "x0_mm";
inline constexpr std::string_view kY0MmAttribute = "y0_mm";
inline constexpr std::string_view kDxMmAttribute = "dx_mm";
inline constexpr std::string_view kDyMmAttribute = "dy_mm";
inline constexpr std::string_view kSchemaVersionAttribute = "schema_version";
inline constexpr std::string_view kQuantityAttribute = "quantity";
inline constexpr std::string_view kArcwheelVersionAttribute = "arcwheel_version";
// Figures over the map's finite nodes, when the writer records them.
inline constexpr std::string_view kPvUmAttribute = "pv_um";
inline constexpr std::string_view kRmsUmAttribute = "rms_um";

// What `quantity` says in the files arcwheel writes.
inline constexpr std::string_view kPredictedFormError = "predicted form error of the ground surface";
inline constexpr std::string_view kPolishResidual = "predicted residual after polishing";
inline constexpr std::string_view kErrorMap = "error map";

// Extra datasets of the writers, [ny, nx].
inline constexpr std::string_view kLowOrderUm = "/low_order_um";  // prediction: the arc-radius part
inline constexpr std::string_view kTargetUm = "/target_um";       // polish: the removal target
inline constexpr std::string_view kRemovalUm = "/removal_um";     // polish: the predicted removal

// The prediction layout written before the grid map (read, never written).
namespace legacy_prediction {
inline constexpr std::string_view kErrorUm = "/prediction/error_um";
inline constexpr std::string_view kXMm = "/prediction/x_mm";
inline constexpr std::string_view kYMm = "/prediction/y_mm";
}  // namespace legacy_prediction

// Where a file keeps its error values and how its nodes lie. nx and ny are the dataset's shape
// (0 when it is not two-dimensional: the caller refuses that with its own message).
struct Location {
  std::string error_dataset{};
  double x0_mm = 0.0;
  double y0_mm = 0.0;
  double dx_mm = 1.0;
  double dy_mm = 1.0;
  int nx = 0;
  int ny = 0;
  std::string layout{};  // "grid map 1.0", "grid map (unversioned)" or "prediction (before the grid map)"
};

// Finds the error dataset and the grid of a file in any layout above. Throws Error{kBadInput,
// stage} naming the file and the missing or malformed dataset or attribute, or a schema version
// this reader does not read.
[[nodiscard]] Location LocateGridMap(const hdf5::File& file, std::string_view stage);

// A map to write: `error_um` and every layer are [ny * nx], row by row.
struct Content {
  double x0_mm = 0.0;
  double y0_mm = 0.0;
  double dx_mm = 1.0;
  double dy_mm = 1.0;
  int nx = 0;
  int ny = 0;
  std::vector<double> error_um{};
  std::string quantity{};
  std::vector<std::pair<std::string, std::vector<double>>> layers{};  // dataset path -> values
  std::vector<std::pair<std::string, double>> figures{};              // root numeric attributes
  std::vector<std::pair<std::string, std::string>> texts{};           // root text attributes
};

// Writes `content` into a new file at `path` (the caller stages it). Throws Error{kIo}, and
// Error{kInternal} for layers of the wrong size.
void WriteGridMap(const Content& content, const std::filesystem::path& path);

}  // namespace arcwheel::schema::grid_map
