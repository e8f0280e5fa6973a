#include "polishing/grid_csv.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <limits>
#include <set>
#include <sstream>
#include <string>

#include "core/error.h"

namespace arcwheel::polishing {
namespace {

// Largest grid read (8e8 bytes of doubles).
constexpr double kMaxGridNodes = 1e8;

[[noreturn]] void LineFail(std::string_view stage, const std::filesystem::path& path, std::size_t line,
                           const std::string& what) {
  throw Error(ErrorCode::kBadInput, stage, fmt::format("'{}' line {}: {}", path.string(), line, what));
}

// Index of `v` on a grid of spacing d from v0, or -1 if it is not within 1e-6 d of a node.
int GridIndex(double v, double v0, double d) {
  const double u = (v - v0) / d;
  const double r = std::round(u);
  return std::abs(u - r) <= 1e-6 ? static_cast<int>(r) : -1;
}

double MedianGap(const std::set<double>& values) {
  std::vector<double> gaps;
  for (auto it = std::next(values.begin()); it != values.end(); ++it) gaps.push_back(*it - *std::prev(it));
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
  return gaps[gaps.size() / 2];
}

}  // namespace

std::vector<CsvTriple> ReadCsvTriples(const std::filesystem::path& path, std::string_view value_column,
                                      std::string_view stage) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::kIo, stage, fmt::format("cannot open '{}'", path.string()));
  const std::string header = fmt::format("x_mm,y_mm,{}", value_column);
  std::vector<CsvTriple> rows;
  std::string text;
  std::size_t line = 0;
  bool has_header = false;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    if (text.empty() || text[0] == '#') continue;
    if (!has_header) {
      if (text != header) LineFail(stage, path, line, fmt::format("header '{}' is not '{}'", text, header));
      has_header = true;
      continue;
    }
    std::stringstream cells(text);
    std::string cell;
    double v[3];
    int count = 0;
    while (std::getline(cells, cell, ',')) {
      if (count == 3) LineFail(stage, path, line, "has more than 3 values");
      char* end = nullptr;
      v[count] = std::strtod(cell.c_str(), &end);
      if (cell.empty() || *end != '\0')
        LineFail(stage, path, line, fmt::format("'{}' is not a number", cell));
      ++count;
    }
    if (count != 3) LineFail(stage, path, line, fmt::format("has {} values, needs {}", count, header));
    if (!std::isfinite(v[0]) || !std::isfinite(v[1]))
      LineFail(stage, path, line, "x_mm and y_mm must be finite");
    rows.push_back({v[0], v[1], v[2], line});
  }
  if (in.bad()) throw Error(ErrorCode::kIo, stage, fmt::format("cannot read '{}'", path.string()));
  if (!has_header) LineFail(stage, path, line, fmt::format("no header '{}'", header));
  return rows;
}

CsvGrid ReadCsvGrid(const std::filesystem::path& path, std::string_view value_column,
                    std::string_view stage) {
  const std::vector<CsvTriple> rows = ReadCsvTriples(path, value_column, stage);
  CsvGrid grid;
  grid.last_line = rows.empty() ? 1 : rows.back().line;
  if (rows.size() < 2) LineFail(stage, path, grid.last_line, "the grid needs at least two nodes");
  std::set<double> xs, ys;
  for (const CsvTriple& r : rows) xs.insert(r.x_mm), ys.insert(r.y_mm);
  grid.x0_mm = *xs.begin();
  grid.y0_mm = *ys.begin();
  grid.dx_mm = xs.size() > 1 ? MedianGap(xs) : 1.0;
  grid.dy_mm = ys.size() > 1 ? MedianGap(ys) : 1.0;
  const double nx = std::round((*xs.rbegin() - grid.x0_mm) / grid.dx_mm) + 1.0;
  const double ny = std::round((*ys.rbegin() - grid.y0_mm) / grid.dy_mm) + 1.0;
  if (!(nx * ny <= kMaxGridNodes)) LineFail(stage, path, grid.last_line, "the grid would exceed 1e8 nodes");
  // A measured map fills most of its grid; a few rows spanning a vast grid are not a grid at all.
  if (nx * ny > 64.0 * static_cast<double>(rows.size()) + 4096.0) {
    LineFail(
        stage, path, grid.last_line,
        fmt::format("{} nodes spread over a grid of {} x {}: not the nodes of one regular grid (scattered "
                    "points? set error_map.layout to scattered)",
                    rows.size(), nx, ny));
  }
  grid.nx = static_cast<int>(nx);
  grid.ny = static_cast<int>(ny);
  grid.values.assign(static_cast<std::size_t>(grid.nx) * static_cast<std::size_t>(grid.ny),
                     std::numeric_limits<double>::quiet_NaN());
  grid.lines.assign(grid.values.size(), 0);
  for (const CsvTriple& r : rows) {
    const int i = GridIndex(r.x_mm, grid.x0_mm, grid.dx_mm), j = GridIndex(r.y_mm, grid.y0_mm, grid.dy_mm);
    if (i < 0 || j < 0 || i >= grid.nx || j >= grid.ny) {
      LineFail(stage, path, r.line,
               fmt::format("({}, {}) mm is not on the regular grid of spacing {} x {} mm", r.x_mm, r.y_mm,
                           grid.dx_mm, grid.dy_mm));
    }
    const std::size_t index =
        static_cast<std::size_t>(j) * static_cast<std::size_t>(grid.nx) + static_cast<std::size_t>(i);
    if (grid.lines[index] != 0)
      LineFail(stage, path, r.line, fmt::format("({}, {}) mm appears twice", r.x_mm, r.y_mm));
    grid.lines[index] = r.line;
    grid.values[index] = r.value;
  }
  return grid;
}

}  // namespace arcwheel::polishing
