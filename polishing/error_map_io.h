#pragma once
// Error-map readers of the polishing stage (stage id `polishing.map`): a CSV grid, a scattered
// x,y,z CSV interpolated onto a grid, arcwheel's own HDF5 grid, Zygo MetroPro `.dat` and Zygo Mx
// `.datx`. All end in the same ErrorMap (polishing/removal_target.h): a regular grid of the part
// frame's (x, y) in mm, error in um, positive = material to remove, NaN = no data.
//
// Interferometer maps come as pixels. They are read into a PixelMap (heights per pixel, lateral
// resolution if the file has one) and placed in the part frame by PlaceInPartFrame:
//   1. camera frame: u = (i - ci) px_mm to the right, v = (cj - j) py_mm upwards, for column i and
//      row j with (ci, cj) the centre pixel. Both Zygo formats store row 0 at the top of the camera
//      image (Gwyddion's metropro.c and prysm's readers draw it there), so v is counted upwards
//      to keep (u, v) right-handed as the picture on the instrument's screen shows the part;
//   2. flip: "x" negates u, "y" negates v (e.g. a map taken through a fold mirror);
//   3. rotation: counter-clockwise by 0, 90, 180 or 270 degrees;
//   4. translation: the centre pixel lands on centre_mm (default the part origin);
//   5. error_um = scale * height_um. Positive height (material standing high) is material to
//      remove, so the natural default is scale = +1; use -1 for a map of removal depth or of
//      depth below nominal.
// Every failure throws Error{kBadInput, "polishing.map"} naming the file and the field, line or
// dataset; Error{kIo} if a file cannot be read.

#include <array>
#include <cmath>
#include <cstddef>
#include <filesystem>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/hdf5.h"
#include "polishing/removal_target.h"
#include "schema/grid_map.h"

namespace arcwheel::polishing {

// Bytes a polish run holds per node of its error map (the map, the target, the predicted removal
// and residual, the residual CSV; measured, docs/polishing.md "Sizes"). Every reader refuses a grid
// whose nodes would need more than the memory budget (core/memory_budget.h), from the file's header
// or shape, before the values are read.
inline constexpr double kBytesPerMapNode = 160.0;

// Heights per camera pixel: height_um[j * width + i] for column i, row j (row 0 = top of the
// camera image), NaN = no data. Pixel sizes are NaN when the file does not give them.
struct PixelMap {
  int width = 0;
  int height = 0;
  std::vector<double> height_um{};
  double pixel_x_mm = std::numeric_limits<double>::quiet_NaN();
  double pixel_y_mm = std::numeric_limits<double>::quiet_NaN();
};

// How a PixelMap is placed in the part frame (steps 1-5 above).
struct MapPlacement {
  // Lateral resolution (mm per pixel, > 0) replacing the file's; NaN = use the file's.
  double pixel_mm = std::numeric_limits<double>::quiet_NaN();
  // Centre pixel (column, row; fractions allowed). NaN = centre of the valid-data bounding box.
  double centre_column = std::numeric_limits<double>::quiet_NaN();
  double centre_row = std::numeric_limits<double>::quiet_NaN();
  // Where the centre pixel lands in the part frame (mm).
  double centre_x_mm = 0.0;
  double centre_y_mm = 0.0;
  // Counter-clockwise rotation: 0, 90, 180 or 270.
  int rotation_deg = 0;
  enum class Flip { kNone, kX, kY };
  Flip flip = Flip::kNone;
  // error_um = scale * height_um; finite and != 0.
  double scale = 1.0;
};

// Places a pixel map in the part frame. Throws Error{kBadInput, "polishing.map"} naming `name`
// if no pixel has data or there is no lateral resolution (neither in the file nor pixel_mm), and
// Error{kInvalidOption} for a rotation other than a multiple of 90 degrees or a zero scale.
[[nodiscard]] ErrorMap PlaceInPartFrame(const PixelMap& pixels, const MapPlacement& placement,
                                        const std::string& name);

// The default centre pixel: the centre (column, row) of the bounding box of the pixels with data.
// Throws Error{kBadInput, "polishing.map"} naming `name` if no pixel has data.
[[nodiscard]] std::array<double, 2> ValidDataCentrePx(const PixelMap& pixels, const std::string& name);

// Zygo MetroPro `.dat` (header formats 1, 2 and 3) from its bytes; `name` stands for the file in
// messages. Height (m) = phase * intf_scale_factor * obliquity_factor * wavelength_in / R, R =
// 4096, 32768 or 131072 for phase_res 0, 1, 2, negated when `sign` is set; phase codes >=
// 0x7FFFFFF8 are no data. Every size and offset is checked against the byte count.
[[nodiscard]] PixelMap ParseMetroProDat(std::span<const unsigned char> bytes, const std::string& name);
[[nodiscard]] PixelMap ReadMetroProDat(const std::filesystem::path& path);

// Zygo Mx `.datx` (HDF5): the surface dataset [rows][columns], its `No Data` value,
// `Z Converter` (HeightCat; base unit Meters, MilliMeters, MicroMeters, NanoMeters or Angstroms,
// or Fringes with the dataset's `Wavelength` (m), `Interferometric Scale Factor` and
// `Obliquity Factor`), and `X Converter` / `Y Converter` (LateralCat, Parameters[1] = m/pixel).
// The surface is the dataset the /MetaData table names (Root -> Measurement -> Surface -> Path,
// as MetroPro writes it), else /Measurement/Surface, else the only dataset under /Data/Surface.
// NaN and the `No Data` value have no data; any other non-finite value is refused, naming its
// [row][column].
[[nodiscard]] PixelMap ReadZygoDatx(const hdf5::File& file);
[[nodiscard]] PixelMap ReadZygoDatx(const std::filesystem::path& path);

// arcwheel's HDF5 grid map (schema/grid_map.h, docs/outputs.md "Grid maps"): dataset `error_um`
// [ny][nx] (float64, NaN = no data, an infinity refused) and root attributes `x0_mm`, `y0_mm`,
// `dx_mm`, `dy_mm`: node (i, j) lies at (x0 + i dx, y0 + j dy). Also reads the layouts written
// before it: the same without `schema_version`, and a prediction.h5 with `/prediction/error_um`,
// `/prediction/x_mm`, `/prediction/y_mm`. So `arcwheel toolpath`'s prediction.h5 and
// `arcwheel polish`'s residual_map.h5 are error maps as they are.
[[nodiscard]] ErrorMap ReadErrorMapHdf5(const hdf5::File& file);
[[nodiscard]] ErrorMap ReadErrorMapHdf5(const std::filesystem::path& path);
// Writes that layout (quantity "error map"). Throws Error{kIo}.
void WriteErrorMapHdf5(const ErrorMap& map, const std::filesystem::path& path);
// The grid map of `map`, saying what it is in `quantity`, for writers that add layers or figures.
[[nodiscard]] schema::grid_map::Content GridMapContent(const ErrorMap& map, std::string_view quantity);

// Reads an error map CSV: a header `x_mm,y_mm,error_um`, then one node of a regular grid per row
// (any order; missing nodes and `nan` have no data). Throws Error{kIo} if unreadable and
// Error{kBadInput, "polishing.map"} naming the file and line of anything malformed or infinite.
[[nodiscard]] ErrorMap ReadErrorMapCsv(const std::filesystem::path& path);

struct ScatteredPoint {
  double x_mm = 0.0;
  double y_mm = 0.0;
  double error_um = 0.0;
  std::size_t line = 0;  // line of the CSV it came from, for messages; 0 = not from a file
};

// Reads scattered points from a CSV with the header `x_mm,y_mm,error_um` (finite values only,
// `#` comment lines). Throws Error{kBadInput, "polishing.map"} naming the file and line.
[[nodiscard]] std::vector<ScatteredPoint> ReadScatteredCsv(const std::filesystem::path& path);

// Linear interpolation of scattered points over their Delaunay triangulation (as MATLAB's
// griddata 'linear'): nodes at whole multiples of `grid_spacing_mm` inside the points' bounding
// box; nodes outside the convex hull have no data. grid_spacing_mm <= 0 or NaN selects the median
// distance from a point to its nearest neighbour. Throws Error{kBadInput, "polishing.map"}
// naming `name` for fewer than 3 points, all points on one line, two points at one place, or a
// grid of more than 1e7 nodes or 1e4 per point.
[[nodiscard]] ErrorMap InterpolateScattered(std::span<const ScatteredPoint> points, double grid_spacing_mm,
                                            const std::string& name);

// The median nearest-neighbour distance of the points (the default grid spacing above).
[[nodiscard]] double MedianNearestNeighbourMm(std::span<const ScatteredPoint> points,
                                              const std::string& name);

enum class ErrorMapFormat { kCsv, kDat, kDatx, kHdf5 };
enum class ErrorMapLayout { kGrid, kScattered };

struct ErrorMapOptions {
  ErrorMapFormat format = ErrorMapFormat::kCsv;
  // CSV only: a grid, or scattered points to interpolate.
  ErrorMapLayout layout = ErrorMapLayout::kGrid;
  // Scattered only: grid spacing (mm); <= 0 = median nearest-neighbour distance.
  double grid_spacing_mm = 0.0;
  // dat / datx: placement in the part frame. Only `scale` applies to the other formats.
  MapPlacement placement{};
};

// The format a file's extension implies: .csv, .dat, .datx, .h5 / .hdf5 (any case). Throws
// Error{kBadInput, "polishing.map"} for any other extension.
[[nodiscard]] ErrorMapFormat FormatFromExtension(const std::filesystem::path& path);

// Reads any of the formats above into an ErrorMap (scale applied).
[[nodiscard]] ErrorMap ReadErrorMap(const std::filesystem::path& path, const ErrorMapOptions& options);

}  // namespace arcwheel::polishing
