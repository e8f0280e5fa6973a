#include "polishing/error_map_io.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <opencv2/imgproc.hpp>
#include <optional>
#include <set>
#include <sstream>
#include <tuple>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/memory_budget.h"
#include "polishing/grid_csv.h"
#include "schema/grid_map.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kStage = "polishing.map";
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Largest grid any reader builds (8e8 bytes of doubles).
constexpr double kMaxNodes = 1e8;
// An error map marks a node without data with NaN; an infinity is a damaged value, never "no data".
constexpr const char* kInfinityIsDamage =
    "is not finite: a map marks no data with nan, and an infinity is a damaged value (docs/polishing.md)";

[[noreturn]] void Fail(const std::string& name, const std::string& what) {
  throw Error(ErrorCode::kBadInput, kStage, fmt::format("'{}': {}", name, what));
}

// Refuses a grid of `rows` x `columns` nodes (as `what` in the file `name` declares it) that would
// not fit the memory budget of a polish run.
void CheckMapNodes(const std::string& name, const std::string& what, double rows, double columns) {
  if (const auto problem = MemoryBudgetProblem(fmt::format("'{}': {} [{}][{}]", name, what, rows, columns),
                                               rows * columns, "map nodes", kBytesPerMapNode)) {
    throw Error(ErrorCode::kBadInput, kStage, *problem);
  }
}

[[noreturn]] void LineFail(const std::filesystem::path& path, std::size_t line, const std::string& what) {
  throw Error(ErrorCode::kBadInput, kStage, fmt::format("'{}' line {}: {}", path.string(), line, what));
}

// ---------------------------------------------------------------------------------------------
// MetroPro .dat. Layout: MetroPro Reference Guide (Zygo OMP-0347, appendix B "Data File Format"),
// as read by Gwyddion's modules/file/metropro.c and prysm's read_zygo_dat. Byte offsets of the
// big-endian header fields used here; they are the same in header formats 1, 2 and 3.
struct MetroProField {
  const char* name;
  std::size_t offset;
};
constexpr MetroProField kMagic{"magic_number", 0};               // uint32
constexpr MetroProField kHeaderFormat{"header_format", 4};       // uint16
constexpr MetroProField kHeaderSize{"header_size", 6};           // uint32
constexpr MetroProField kAcWidth{"ac_width", 52};                // uint16, intensity columns
constexpr MetroProField kAcHeight{"ac_height", 54};              // uint16, intensity rows
constexpr MetroProField kAcBuckets{"ac_n_buckets", 56};          // uint16, intensity frames
constexpr MetroProField kCnWidth{"cn_width", 68};                // uint16, phase columns
constexpr MetroProField kCnHeight{"cn_height", 70};              // uint16, phase rows
constexpr MetroProField kScaleFactor{"intf_scale_factor", 164};  // float32
constexpr MetroProField kWavelength{"wavelength_in", 168};       // float32, m
constexpr MetroProField kObliquity{"obliquity_factor", 176};     // float32
constexpr MetroProField kLateralRes{"lateral_res", 184};         // float32, m/pixel (camera_res)
constexpr MetroProField kPhaseRes{"phase_res", 218};             // uint16: 0, 1, 2
constexpr MetroProField kSign{"sign", 232};                      // uint16, != 0: data inverted

// Phase codes from 0x7FFFFFF8 up mark pixels without data.
constexpr std::int32_t kInvalidPhase = 2147483640;

struct HeaderFormat {
  std::uint32_t magic;
  std::uint16_t format;
  std::uint32_t header_size;
};
constexpr std::array<HeaderFormat, 3> kHeaderFormats = {
    {{0x881B036F, 1, 834}, {0x881B0370, 2, 834}, {0x881B0371, 3, 4096}}};

class BigEndian {
 public:
  BigEndian(std::span<const unsigned char> bytes, const std::string& name) : bytes_(bytes), name_(name) {}
  [[nodiscard]] std::uint32_t U32(const MetroProField& f) const {
    return static_cast<std::uint32_t>(Get(f, 4));
  }
  [[nodiscard]] std::uint16_t U16(const MetroProField& f) const {
    return static_cast<std::uint16_t>(Get(f, 2));
  }
  [[nodiscard]] double F32(const MetroProField& f) const {
    const auto bits = static_cast<std::uint32_t>(Get(f, 4));
    float value = 0.0f;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }
  [[nodiscard]] std::int32_t I32At(std::size_t offset) const {
    const auto bits = static_cast<std::uint32_t>(Get({"phase data", offset}, 4));
    std::int32_t value = 0;
    std::memcpy(&value, &bits, sizeof value);
    return value;
  }

 private:
  [[nodiscard]] std::uint64_t Get(const MetroProField& f, std::size_t width) const {
    if (f.offset > bytes_.size() || bytes_.size() - f.offset < width) {
      Fail(name_, fmt::format("MetroPro field '{}' at byte {} lies beyond the {}-byte file (truncated?)",
                              f.name, f.offset, bytes_.size()));
    }
    std::uint64_t v = 0;
    for (std::size_t k = 0; k < width; ++k) v = (v << 8) | bytes_[f.offset + k];
    return v;
  }
  std::span<const unsigned char> bytes_;
  const std::string& name_;
};

void FieldFail(const std::string& name, const MetroProField& f, const std::string& what) {
  Fail(name, fmt::format("MetroPro field '{}' {}", f.name, what));
}

double PositiveFinite(const BigEndian& in, const MetroProField& f, const std::string& name) {
  const double v = in.F32(f);
  if (!std::isfinite(v) || v == 0.0) FieldFail(name, f, fmt::format("= {} must be finite and non-zero", v));
  return v;
}

// ---------------------------------------------------------------------------------------------
// Zygo Mx .datx. Layout as read by ContactEngineering SurfaceTopography (IO/DATX.py) and prysm
// (io.read_zygo_datx): a surface dataset with attributes `No Data`, `Unit`, `X Converter`,
// `Y Converter`, `Z Converter`; a converter is a compound {Category, BaseUnit, Parameters}.
// Where the surface dataset is: see DatxSurfacePath.
constexpr const char* kDatxMetaData = "/MetaData";
constexpr const char* kDatxMeasurementSurface = "/Measurement/Surface";
constexpr const char* kDatxDataSurface = "/Data/Surface";

// The destination of the /MetaData row (source, link), or nothing. Two rows that disagree are
// refused: which surface is meant would be a guess.
std::optional<std::string> MetaDataLink(const std::vector<std::vector<std::string>>& rows,
                                        const std::string& source, const std::string& link,
                                        const std::string& name) {
  std::optional<std::string> destination;
  for (const std::vector<std::string>& row : rows) {
    if (row[0] != source || row[1] != link) continue;
    if (destination && *destination != row[2]) {
      Fail(name, fmt::format("{} links '{}' -> '{}' to both '{}' and '{}'", kDatxMetaData, source, link,
                             *destination, row[2]));
    }
    destination = row[2];
  }
  return destination;
}

// The surface's path as the /MetaData table names it (Root -> Measurement -> Surface -> Path, as
// MetroPro writes it and SurfaceTopography reads it), or nothing if the table does not name one.
std::optional<std::string> DatxSurfaceFromMetaData(const hdf5::File& file) {
  const std::string name = file.path().string();
  const std::vector<std::vector<std::string>> rows =
      file.ReadStringTable(kDatxMetaData, {"Source", "Link", "Destination"});
  std::string node = "Root";
  for (const char* link : {"Measurement", "Surface", "Path"}) {
    const std::optional<std::string> next = MetaDataLink(rows, node, link, name);
    if (!next) return std::nullopt;
    node = *next;
  }
  return node;
}

// Where the surface dataset of a .datx is: the path /MetaData names (MetroPro's files put the
// surface at /Data/Surface/{GUID}); else /Measurement/Surface; else the only dataset under
// /Data/Surface (as prysm takes it). A path that /MetaData names but the file lacks is refused.
std::string DatxSurfacePath(const hdf5::File& file) {
  const std::string name = file.path().string();
  if (file.HasObject(kDatxMetaData)) {
    if (const std::optional<std::string> path = DatxSurfaceFromMetaData(file)) {
      if (path->empty() || path->front() != '/' || !file.HasObject(*path)) {
        Fail(name, fmt::format("{} names the surface dataset '{}', which the file does not hold",
                               kDatxMetaData, *path));
      }
      return *path;
    }
  }
  if (file.HasObject(kDatxMeasurementSurface)) return kDatxMeasurementSurface;
  const std::vector<std::string> datasets = file.DatasetNames(kDatxDataSurface);
  if (datasets.size() == 1) return std::string(kDatxDataSurface) + "/" + datasets.front();
  if (datasets.size() > 1) {
    Fail(name, fmt::format("'{}' holds {} datasets and no {} table says which is the surface",
                           kDatxDataSurface, datasets.size(), kDatxMetaData));
  }
  Fail(name,
       fmt::format("no surface dataset: neither a {} table naming one, nor '{}', nor a dataset under '{}' "
                   "(not a Zygo Mx .datx surface measurement?)",
                   kDatxMetaData, kDatxMeasurementSurface, kDatxDataSurface));
}

// Micrometres per base unit of a height, or NaN for a unit that is not a length.
double MicrometresPer(const std::string& unit) {
  if (unit == "Meters") return 1e6;
  if (unit == "MilliMeters") return 1e3;
  if (unit == "MicroMeters") return 1.0;
  if (unit == "NanoMeters") return 1e-3;
  if (unit == "Angstroms") return 1e-4;
  return kNaN;
}

double DatxAttribute(const hdf5::File& file, const std::string& surface, const std::string& attribute) {
  const std::optional<double> v = file.ReadAttributeDouble(surface, attribute);
  if (!v || !std::isfinite(*v) || *v == 0.0) {
    Fail(file.path().string(), fmt::format("{} attribute '{}' is {} (needed for heights in Fringes)", surface,
                                           attribute, v ? fmt::format("{}", *v) : std::string("missing")));
  }
  return *v;
}

// Micrometres per stored height value, from the Z converter.
double DatxHeightScaleUm(const hdf5::File& file, const std::string& surface) {
  const std::string name = file.path().string();
  const auto z = file.ReadAttributeCompound(surface, "Z Converter");
  if (!z) Fail(name, fmt::format("{} has no attribute 'Z Converter' (the height unit)", surface));
  const std::string category = z->strings.count("Category") ? z->strings.at("Category") : "";
  const std::string unit = z->strings.count("BaseUnit") ? z->strings.at("BaseUnit") : "";
  if (category != "HeightCat") {
    Fail(name,
         fmt::format("{} attribute 'Z Converter' Category = '{}' is not 'HeightCat'", surface, category));
  }
  if (unit == "Fringes") {
    // As prysm: fringes * wavelength * interferometric scale factor * obliquity factor = height.
    return 1e6 * DatxAttribute(file, surface, "Wavelength") *
           DatxAttribute(file, surface, "Interferometric Scale Factor") *
           DatxAttribute(file, surface, "Obliquity Factor");
  }
  const double um = MicrometresPer(unit);
  if (std::isnan(um)) {
    Fail(name, fmt::format("{} attribute 'Z Converter' BaseUnit = '{}' is not a length (Meters, MilliMeters, "
                           "MicroMeters, NanoMeters, Angstroms) or Fringes",
                           surface, unit));
  }
  return um;
}

// mm per pixel from an X or Y converter (Parameters[1] in m), NaN if absent or not lateral.
double DatxPixelMm(const hdf5::File& file, const std::string& surface, const std::string& converter) {
  const auto c = file.ReadAttributeCompound(surface, converter);
  if (!c || !c->strings.count("Category") || c->strings.at("Category") != "LateralCat" ||
      !c->numbers.count("Parameters")) {
    return kNaN;
  }
  const std::vector<double>& p = c->numbers.at("Parameters");
  if (p.size() < 2 || !std::isfinite(p[1]) || !(p[1] > 0.0)) return kNaN;
  return p[1] * 1e3;
}

// ---------------------------------------------------------------------------------------------
// Scattered points: triangulation by cv::Subdiv2D, interpolation in double precision.

struct Triangle {
  std::array<int, 3> v;
};

struct Triangulation {
  std::vector<Triangle> triangles;
};

std::string PointName(std::span<const ScatteredPoint> points, std::size_t k) {
  return points[k].line > 0 ? fmt::format("line {}", points[k].line) : fmt::format("point {}", k + 1);
}

void CheckSpread(std::span<const ScatteredPoint> points, const std::string& name) {
  if (points.size() < 3)
    Fail(name, fmt::format("has {} scattered points, needs at least 3 to triangulate", points.size()));
  for (const ScatteredPoint& p : points) {
    if (!std::isfinite(p.x_mm) || !std::isfinite(p.y_mm) || !std::isfinite(p.error_um)) {
      Fail(name, fmt::format("scattered point ({}, {}, {}) is not finite", p.x_mm, p.y_mm, p.error_um));
    }
  }
  // Farthest point from the first, then the largest distance off that line.
  const ScatteredPoint& a = points[0];
  std::size_t far = 0;
  double far_mm = 0.0;
  for (std::size_t k = 1; k < points.size(); ++k) {
    const double d = std::hypot(points[k].x_mm - a.x_mm, points[k].y_mm - a.y_mm);
    if (d > far_mm) far_mm = d, far = k;
  }
  double off_line_mm = 0.0;
  if (far_mm > 0.0) {
    const double ux = (points[far].x_mm - a.x_mm) / far_mm, uy = (points[far].y_mm - a.y_mm) / far_mm;
    for (const ScatteredPoint& p : points) {
      off_line_mm = std::max(off_line_mm, std::abs(ux * (p.y_mm - a.y_mm) - uy * (p.x_mm - a.x_mm)));
    }
  }
  if (!(off_line_mm > 1e-9 * far_mm)) {
    Fail(name,
         fmt::format("all {} scattered points lie on one line: no area to interpolate over", points.size()));
  }
}

Triangulation Triangulate(std::span<const ScatteredPoint> points, const std::string& name) {
  CheckSpread(points, name);
  double x_min = points[0].x_mm, x_max = x_min, y_min = points[0].y_mm, y_max = y_min;
  for (const ScatteredPoint& p : points) {
    x_min = std::min(x_min, p.x_mm), x_max = std::max(x_max, p.x_mm);
    y_min = std::min(y_min, p.y_mm), y_max = std::max(y_max, p.y_mm);
  }
  // Subdiv2D works in float inside an integer rectangle: centre the points on 0 and scale them to
  // +-1e6 in a rectangle 100 times larger, so that its outer triangle lies far from the hull.
  const double cx = 0.5 * (x_min + x_max), cy = 0.5 * (y_min + y_max);
  const double half = 0.5 * std::max(x_max - x_min, y_max - y_min);
  const double s = 1e6 / half;
  constexpr int kRect = 100'000'000;
  Triangulation t;
  try {
    cv::Subdiv2D subdivision(cv::Rect(-kRect, -kRect, 2 * kRect, 2 * kRect));
    std::vector<int> point_of_vertex;
    for (std::size_t k = 0; k < points.size(); ++k) {
      const cv::Point2f q(static_cast<float>((points[k].x_mm - cx) * s),
                          static_cast<float>((points[k].y_mm - cy) * s));
      const int vertex = subdivision.insert(q);
      if (vertex >= static_cast<int>(point_of_vertex.size()))
        point_of_vertex.resize(static_cast<std::size_t>(vertex) + 1, -1);
      if (point_of_vertex[static_cast<std::size_t>(vertex)] >= 0) {
        const auto other = static_cast<std::size_t>(point_of_vertex[static_cast<std::size_t>(vertex)]);
        Fail(name,
             fmt::format("{} ({}, {}) mm and {} ({}, {}) mm lie at one place (closer than 1e-7 of the map's "
                         "size)",
                         PointName(points, other), points[other].x_mm, points[other].y_mm,
                         PointName(points, k), points[k].x_mm, points[k].y_mm));
      }
      point_of_vertex[static_cast<std::size_t>(vertex)] = static_cast<int>(k);
    }
    std::vector<int> leading;
    subdivision.getLeadingEdgeList(leading);
    for (const int edge : leading) {
      Triangle tri{};
      int e = edge;
      bool real = true;
      for (int corner = 0; corner < 3; ++corner) {
        const int vertex = subdivision.edgeOrg(e);
        // Vertices 0-3 are Subdiv2D's own (a dummy and the outer triangle): not ours.
        if (vertex < 4 || vertex >= static_cast<int>(point_of_vertex.size()) ||
            point_of_vertex[static_cast<std::size_t>(vertex)] < 0) {
          real = false;
          break;
        }
        tri.v[static_cast<std::size_t>(corner)] = point_of_vertex[static_cast<std::size_t>(vertex)];
        e = subdivision.getEdge(e, cv::Subdiv2D::NEXT_AROUND_LEFT);
      }
      if (real && e == edge) t.triangles.push_back(tri);
    }
  } catch (const cv::Exception& e) {
    Fail(name, fmt::format("the Delaunay triangulation failed: {}", e.what()));
  }
  if (t.triangles.empty()) Fail(name, "the Delaunay triangulation holds no triangle");
  return t;
}

double MedianNearestNeighbour(std::span<const ScatteredPoint> points, const Triangulation& t) {
  // The nearest neighbour of a point is one of its Delaunay neighbours.
  std::vector<double> nearest(points.size(), std::numeric_limits<double>::infinity());
  for (const Triangle& tri : t.triangles) {
    for (int k = 0; k < 3; ++k) {
      const auto a = static_cast<std::size_t>(tri.v[static_cast<std::size_t>(k)]);
      const auto b = static_cast<std::size_t>(tri.v[static_cast<std::size_t>((k + 1) % 3)]);
      const double d = std::hypot(points[a].x_mm - points[b].x_mm, points[a].y_mm - points[b].y_mm);
      nearest[a] = std::min(nearest[a], d);
      nearest[b] = std::min(nearest[b], d);
    }
  }
  std::vector<double> finite;
  for (const double d : nearest) {
    if (std::isfinite(d)) finite.push_back(d);
  }
  std::nth_element(finite.begin(), finite.begin() + static_cast<std::ptrdiff_t>(finite.size() / 2),
                   finite.end());
  return finite[finite.size() / 2];
}

// Linear interpolation over one triangle onto the nodes of `map` it covers (first triangle wins
// on shared edges; the interpolant is continuous there).
void RasterTriangle(std::span<const ScatteredPoint> points, const Triangle& tri, ErrorMap& map) {
  const ScatteredPoint &a = points[static_cast<std::size_t>(tri.v[0])],
                       &b = points[static_cast<std::size_t>(tri.v[1])],
                       &c = points[static_cast<std::size_t>(tri.v[2])];
  const double den = (b.y_mm - c.y_mm) * (a.x_mm - c.x_mm) + (c.x_mm - b.x_mm) * (a.y_mm - c.y_mm);
  if (den == 0.0) return;
  const double lo_x = std::min({a.x_mm, b.x_mm, c.x_mm}), hi_x = std::max({a.x_mm, b.x_mm, c.x_mm});
  const double lo_y = std::min({a.y_mm, b.y_mm, c.y_mm}), hi_y = std::max({a.y_mm, b.y_mm, c.y_mm});
  const int i0 = std::max(0, static_cast<int>(std::ceil((lo_x - map.grid.x0_mm) / map.grid.dx_mm - 1e-9)));
  const int i1 = std::min(map.grid.nx - 1,
                          static_cast<int>(std::floor((hi_x - map.grid.x0_mm) / map.grid.dx_mm + 1e-9)));
  const int j0 = std::max(0, static_cast<int>(std::ceil((lo_y - map.grid.y0_mm) / map.grid.dy_mm - 1e-9)));
  const int j1 = std::min(map.grid.ny - 1,
                          static_cast<int>(std::floor((hi_y - map.grid.y0_mm) / map.grid.dy_mm + 1e-9)));
  // Barycentric weights may dip this far below 0 for a node on an edge (rounding).
  constexpr double kEdge = 1e-9;
  for (int j = j0; j <= j1; ++j) {
    const double y = map.grid.Y(j);
    for (int i = i0; i <= i1; ++i) {
      double& node = map.error_um[static_cast<std::size_t>(j) * map.grid.nx + i];
      if (!std::isnan(node)) continue;
      const double x = map.grid.X(i);
      const double la = ((b.y_mm - c.y_mm) * (x - c.x_mm) + (c.x_mm - b.x_mm) * (y - c.y_mm)) / den;
      const double lb = ((c.y_mm - a.y_mm) * (x - c.x_mm) + (a.x_mm - c.x_mm) * (y - c.y_mm)) / den;
      const double lc = 1.0 - la - lb;
      if (la < -kEdge || lb < -kEdge || lc < -kEdge) continue;
      node = la * a.error_um + lb * b.error_um + lc * c.error_um;
    }
  }
}

std::string Lower(std::string s) {
  for (char& ch : s) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
  return s;
}

std::vector<unsigned char> ReadBytes(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot open '{}'", path.string()));
  std::vector<unsigned char> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (in.bad()) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot read '{}'", path.string()));
  return bytes;
}

}  // namespace

// ---------------------------------------------------------------------------------------------

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

PixelMap ParseMetroProDat(std::span<const unsigned char> bytes, const std::string& name) {
  const BigEndian in(bytes, name);
  const std::uint32_t magic = in.U32(kMagic);
  const auto format = std::find_if(kHeaderFormats.begin(), kHeaderFormats.end(),
                                   [&](const HeaderFormat& f) { return f.magic == magic; });
  if (format == kHeaderFormats.end()) {
    FieldFail(
        name, kMagic,
        fmt::format("= 0x{:08X} is not a MetroPro .dat magic number (0x881B036F, 0x881B0370, 0x881B0371)",
                    magic));
  }
  const std::uint16_t header_format = in.U16(kHeaderFormat);
  if (header_format != format->format) {
    FieldFail(name, kHeaderFormat,
              fmt::format("= {} does not match magic number 0x{:08X} (format {})", header_format, magic,
                          format->format));
  }
  const std::uint32_t header_size = in.U32(kHeaderSize);
  if (header_size != format->header_size) {
    FieldFail(name, kHeaderSize,
              fmt::format("= {} is not the {} bytes of header format {}", header_size, format->header_size,
                          format->format));
  }
  if (header_size > bytes.size()) {
    FieldFail(name, kHeaderSize,
              fmt::format("= {} bytes lies beyond the {}-byte file (truncated?)", header_size, bytes.size()));
  }
  // Sizes in 64 bits: three 16-bit factors cannot overflow.
  const std::uint64_t intensity_bytes = 2ull * in.U16(kAcWidth) * in.U16(kAcHeight) * in.U16(kAcBuckets);
  const std::uint64_t phase_offset = header_size + intensity_bytes;
  if (phase_offset > bytes.size()) {
    Fail(name, fmt::format("MetroPro fields 'ac_width' x 'ac_height' x 'ac_n_buckets' = {} x {} x {} declare "
                           "{} intensity bytes "
                           "after the {}-byte header, beyond the {}-byte file (truncated?)",
                           in.U16(kAcWidth), in.U16(kAcHeight), in.U16(kAcBuckets), intensity_bytes,
                           header_size, bytes.size()));
  }
  PixelMap map;
  map.width = in.U16(kCnWidth);
  map.height = in.U16(kCnHeight);
  if (map.width == 0 || map.height == 0) {
    Fail(name, fmt::format("MetroPro fields 'cn_width' x 'cn_height' = {} x {}: the file holds no phase data",
                           map.width, map.height));
  }
  const std::uint64_t phase_bytes =
      4ull * static_cast<std::uint64_t>(map.width) * static_cast<std::uint64_t>(map.height);
  if (bytes.size() - phase_offset < phase_bytes) {
    Fail(name,
         fmt::format(
             "MetroPro fields 'cn_width' x 'cn_height' = {} x {} declare {} phase bytes from byte {}, beyond "
             "the {}-byte file (truncated?)",
             map.width, map.height, phase_bytes, phase_offset, bytes.size()));
  }
  CheckMapNodes(name, "phase data 'cn_height' x 'cn_width'", map.height, map.width);
  const std::uint16_t phase_res = in.U16(kPhaseRes);
  static constexpr std::array<double, 3> kResolution = {4096.0, 32768.0, 131072.0};
  if (phase_res >= kResolution.size())
    FieldFail(name, kPhaseRes, fmt::format("= {} is not 0, 1 or 2", phase_res));
  const double wavelength_m = in.F32(kWavelength);
  if (!(wavelength_m > 0.0 && std::isfinite(wavelength_m)))
    FieldFail(name, kWavelength, fmt::format("= {} m must be > 0", wavelength_m));
  double um_per_count = 1e6 * PositiveFinite(in, kScaleFactor, name) * PositiveFinite(in, kObliquity, name) *
                        wavelength_m / kResolution[phase_res];
  if (in.U16(kSign) != 0) um_per_count = -um_per_count;
  const double lateral_m = in.F32(kLateralRes);
  if (lateral_m > 0.0 && std::isfinite(lateral_m)) map.pixel_x_mm = map.pixel_y_mm = lateral_m * 1e3;
  map.height_um.resize(static_cast<std::size_t>(map.width) * static_cast<std::size_t>(map.height));
  for (std::size_t k = 0; k < map.height_um.size(); ++k) {
    const std::int32_t code = in.I32At(static_cast<std::size_t>(phase_offset) + 4 * k);
    map.height_um[k] = code >= kInvalidPhase ? kNaN : um_per_count * code;
  }
  return map;
}

PixelMap ReadMetroProDat(const std::filesystem::path& path) {
  const std::vector<unsigned char> bytes = ReadBytes(path);
  return ParseMetroProDat(bytes, path.string());
}

PixelMap ReadZygoDatx(const hdf5::File& file) {
  const std::string name = file.path().string();
  const std::string surface = DatxSurfacePath(file);
  const std::vector<hsize_t> shape = file.Shape(surface);
  if (shape.size() != 2 || shape[0] == 0 || shape[1] == 0 || shape[0] > 1u << 20 || shape[1] > 1u << 20) {
    std::string dims;
    for (const hsize_t d : shape) dims += (dims.empty() ? "" : " x ") + std::to_string(d);
    Fail(name, fmt::format("dataset '{}' has shape [{}], needs [rows][columns]", surface, dims));
  }
  CheckMapNodes(name, fmt::format("dataset '{}'", surface), static_cast<double>(shape[0]),
                static_cast<double>(shape[1]));
  const H5T_class_t element = file.ElementClass(surface);
  if (element != H5T_FLOAT && element != H5T_INTEGER)
    Fail(name, fmt::format("dataset '{}' is not numeric", surface));
  const double um = DatxHeightScaleUm(file, surface);
  const std::optional<double> no_data = file.ReadAttributeDouble(surface, "No Data");
  PixelMap map;
  map.height = static_cast<int>(shape[0]);
  map.width = static_cast<int>(shape[1]);
  map.pixel_x_mm = DatxPixelMm(file, surface, "X Converter");
  map.pixel_y_mm = DatxPixelMm(file, surface, "Y Converter");
  map.height_um = file.ReadDoubles(surface);
  // No data: the file's `No Data` value (MetroPro writes the largest double; a file whose
  // marker is infinity marks its gaps with it) or NaN. Any other value that is not finite, or
  // whose height overflows, is damage.
  for (std::size_t k = 0; k < map.height_um.size(); ++k) {
    double& v = map.height_um[k];
    if (std::isnan(v) || (no_data && v == *no_data)) {
      v = kNaN;
      continue;
    }
    const double height_um = v * um;
    if (!std::isfinite(height_um)) {
      Fail(name,
           fmt::format("dataset '{}' value [{}][{}] = {} is not a finite height (its No Data value is {})",
                       surface, k / shape[1], k % shape[1], v,
                       no_data ? fmt::format("{}", *no_data) : std::string("not given")));
    }
    v = height_um;
  }
  return map;
}

PixelMap ReadZygoDatx(const std::filesystem::path& path) {
  hdf5::ReadFirstInChildProcess(path, [&] { (void)ReadZygoDatx(hdf5::File::OpenReadOnly(path)); });
  return ReadZygoDatx(hdf5::File::OpenReadOnly(path));
}

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

double MedianNearestNeighbourMm(std::span<const ScatteredPoint> points, const std::string& name) {
  return MedianNearestNeighbour(points, Triangulate(points, name));
}

ErrorMap InterpolateScattered(std::span<const ScatteredPoint> points, double grid_spacing_mm,
                              const std::string& name) {
  const Triangulation t = Triangulate(points, name);
  const double d = (grid_spacing_mm > 0.0 && std::isfinite(grid_spacing_mm))
                       ? grid_spacing_mm
                       : MedianNearestNeighbour(points, t);
  double x_min = points[0].x_mm, x_max = x_min, y_min = points[0].y_mm, y_max = y_min;
  for (const ScatteredPoint& p : points) {
    x_min = std::min(x_min, p.x_mm), x_max = std::max(x_max, p.x_mm);
    y_min = std::min(y_min, p.y_mm), y_max = std::max(y_max, p.y_mm);
  }
  // Nodes at whole multiples of d: maps of one part line up whatever their point sets.
  const double k_x0 = std::ceil(x_min / d - 1e-9), k_x1 = std::floor(x_max / d + 1e-9);
  const double k_y0 = std::ceil(y_min / d - 1e-9), k_y1 = std::floor(y_max / d + 1e-9);
  const double nodes = (k_x1 - k_x0 + 1.0) * (k_y1 - k_y0 + 1.0);
  // At most 1e7 nodes (a 3000 x 3000 map) and 1e4 per point: a stray point far from the others
  // would otherwise make a grid of tens of millions of empty nodes.
  const double most_nodes = std::min(1e7, 1e4 * static_cast<double>(points.size()));
  if (!(nodes <= most_nodes) || k_x1 < k_x0 || k_y1 < k_y0) {
    Fail(name,
         fmt::format(
             "a grid of spacing {} mm over [{}, {}] x [{}, {}] mm would hold {} nodes, more than {} for {} "
             "points (a stray point? or set error_map.grid_spacing_mm)",
             d, x_min, x_max, y_min, y_max, nodes, most_nodes, points.size()));
  }
  CheckMapNodes(name, fmt::format("the grid of spacing {} mm", d), k_y1 - k_y0 + 1.0, k_x1 - k_x0 + 1.0);
  ErrorMap map;
  map.grid.dx_mm = map.grid.dy_mm = d;
  map.grid.x0_mm = k_x0 * d;
  map.grid.y0_mm = k_y0 * d;
  map.grid.nx = static_cast<int>(k_x1 - k_x0 + 1.0);
  map.grid.ny = static_cast<int>(k_y1 - k_y0 + 1.0);
  map.error_um.assign(static_cast<std::size_t>(map.grid.nx) * static_cast<std::size_t>(map.grid.ny), kNaN);
  for (const Triangle& tri : t.triangles) RasterTriangle(points, tri, map);
  return map;
}

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
