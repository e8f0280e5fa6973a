#pragma once
// The geometry of a regular grid of the part frame's (x, y), shared by every gridded quantity
// (surface heights, error maps): node (i, j) lies at (x0 + i dx, y0 + j dy), and values on the
// grid are stored row by row, value[j * nx + i].

#include <cstddef>

namespace arcwheel::surfaces {

struct GridSpec {
  double x0_mm = 0.0;  // x of column 0
  double y0_mm = 0.0;  // y of row 0
  double dx_mm = 1.0;  // spacing between columns, > 0
  double dy_mm = 1.0;  // spacing between rows, > 0
  int nx = 0;          // columns
  int ny = 0;          // rows
  [[nodiscard]] double X(int i) const { return x0_mm + i * dx_mm; }
  [[nodiscard]] double Y(int j) const { return y0_mm + j * dy_mm; }
  // Position of node (i, j) in a row-by-row array of values.
  [[nodiscard]] std::size_t Index(int i, int j) const { return static_cast<std::size_t>(j) * nx + i; }
  [[nodiscard]] std::size_t Nodes() const {
    return static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny);
  }
};

}  // namespace arcwheel::surfaces
