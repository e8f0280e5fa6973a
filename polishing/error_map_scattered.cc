// Scattered error-map points onto a regular grid: a Delaunay triangulation (qhull, as
// scipy.spatial.Delaunay makes it) and linear interpolation within each triangle.
#include <fmt/core.h>
#include <libqhull_r/qhull_ra.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <span>
#include <string>
#include <vector>

#include "core/error.h"
#include "polishing/error_map_io.h"
#include "polishing/error_map_io_impl.h"

namespace arcwheel::polishing {
namespace {

using namespace internal;

// Scattered points: triangulation by qhull, interpolation in double precision.

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

// qhull's messages, kept in memory for an error's text.
class MessageBuffer {
 public:
  MessageBuffer() : file_(open_memstream(&text_, &size_)) {}
  ~MessageBuffer() {
    if (file_ != nullptr) std::fclose(file_);
    std::free(text_);
  }
  MessageBuffer(const MessageBuffer&) = delete;
  MessageBuffer& operator=(const MessageBuffer&) = delete;

  [[nodiscard]] FILE* file() const { return file_; }
  [[nodiscard]] std::string Text() {
    if (file_ != nullptr) std::fflush(file_);
    std::string text = text_ != nullptr ? std::string(text_, size_) : std::string();
    const std::size_t end = text.find_last_not_of(" \n");
    return end == std::string::npos ? text : text.substr(0, end + 1);
  }

 private:
  char* text_ = nullptr;
  std::size_t size_ = 0;
  FILE* file_;
};

// One qhull computation, freed however it ends.
class Qhull {
 public:
  Qhull() { qh_zero(&qh_, nullptr); }
  ~Qhull() {
    int current_long = 0, total_long = 0;
    qh_freeqhull(&qh_, !qh_ALL);
    qh_memfreeshort(&qh_, &current_long, &total_long);
  }
  Qhull(const Qhull&) = delete;
  Qhull& operator=(const Qhull&) = delete;

  qhT* get() { return &qh_; }

 private:
  qhT qh_;
};

// The point nearest to points[k] other than itself (the message for points at one place).
std::size_t NearestOther(std::span<const ScatteredPoint> points, std::size_t k) {
  std::size_t nearest = k == 0 ? 1 : 0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t j = 0; j < points.size(); ++j) {
    if (j == k) continue;
    const double d = std::hypot(points[j].x_mm - points[k].x_mm, points[j].y_mm - points[k].y_mm);
    if (d < best) best = d, nearest = j;
  }
  return nearest;
}

[[noreturn]] void FailAtOnePlace(std::span<const ScatteredPoint> points, std::size_t a, std::size_t b,
                                 const std::string& name) {
  Fail(name, fmt::format("{} ({}, {}) mm and {} ({}, {}) mm lie at one place (closer than 1e-7 of the map's "
                         "size)",
                         PointName(points, std::min(a, b)), points[std::min(a, b)].x_mm,
                         points[std::min(a, b)].y_mm, PointName(points, std::max(a, b)),
                         points[std::max(a, b)].x_mm, points[std::max(a, b)].y_mm));
}

// Two points closer than 1e-7 of the map's size make a triangle of no use (and qhull drops an exact
// repeat): refused, naming both. The nearest neighbour of a point is one of its Delaunay
// neighbours, so the triangles' edges and the points qhull left out are all that need a look.
void CheckNoTwoAtOnePlace(std::span<const ScatteredPoint> points, const Triangulation& t,
                          const std::string& name) {
  double x_min = points[0].x_mm, x_max = x_min, y_min = points[0].y_mm, y_max = y_min;
  for (const ScatteredPoint& p : points) {
    x_min = std::min(x_min, p.x_mm), x_max = std::max(x_max, p.x_mm);
    y_min = std::min(y_min, p.y_mm), y_max = std::max(y_max, p.y_mm);
  }
  const double apart_mm = 1e-7 * std::max(x_max - x_min, y_max - y_min);
  std::vector<char> is_vertex(points.size(), 0);
  for (const Triangle& tri : t.triangles) {
    for (std::size_t c = 0; c < 3; ++c) {
      const auto a = static_cast<std::size_t>(tri.v[c]), b = static_cast<std::size_t>(tri.v[(c + 1) % 3]);
      is_vertex[a] = 1;
      if (std::hypot(points[a].x_mm - points[b].x_mm, points[a].y_mm - points[b].y_mm) < apart_mm)
        FailAtOnePlace(points, a, b, name);
    }
  }
  for (std::size_t k = 0; k < points.size(); ++k)
    if (is_vertex[k] == 0) FailAtOnePlace(points, k, NearestOther(points, k), name);
}

Triangulation Triangulate(std::span<const ScatteredPoint> points, const std::string& name) {
  CheckSpread(points, name);
  std::vector<coordT> coordinates;
  coordinates.reserve(2 * points.size());
  for (const ScatteredPoint& p : points) coordinates.insert(coordinates.end(), {p.x_mm, p.y_mm});
  // scipy.spatial.Delaunay's options in two dimensions: Delaunay (d) of the points scaled to the
  // unit box (Qbb), near-coincident points kept aside (Qc), a point at infinity for cocircular
  // input (Qz), wide facets allowed (Q12), the output triangulated (Qt).
  char options[] = "qhull d Qbb Qc Qz Q12 Qt";
  MessageBuffer messages;
  Qhull qhull;
  qhT* qh = qhull.get();
  const int code = qh_new_qhull(qh, 2, static_cast<int>(points.size()), coordinates.data(), False, options,
                                nullptr, messages.file());
  if (code != 0) Fail(name, fmt::format("the Delaunay triangulation failed: {}", messages.Text()));
  Triangulation t;
  facetT* facet = nullptr;
  FORALLfacets {
    if (facet->upperdelaunay) continue;
    Triangle tri{};
    std::size_t corner = 0;
    bool ours = true;  // each corner one of the points (not Qz's point at infinity)
    vertexT* vertex = nullptr;
    vertexT** vertexp = nullptr;
    FOREACHvertex_(facet->vertices) {
      const int id = qh_pointid(qh, vertex->point);
      ours = ours && id >= 0 && id < static_cast<int>(points.size());
      if (corner < 3) tri.v[corner] = id;
      ++corner;
    }
    if (corner == 3 && ours) t.triangles.push_back(tri);
  }
  if (t.triangles.empty()) Fail(name, "the Delaunay triangulation holds no triangle");
  CheckNoTwoAtOnePlace(points, t, name);
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

}  // namespace

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

}  // namespace arcwheel::polishing
