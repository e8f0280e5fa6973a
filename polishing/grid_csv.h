#pragma once
// A regular (x, y) grid written as CSV rows `x_mm,y_mm,<value>` (the error map and the measured
// removal function share it): `#` comment lines and blank lines anywhere, one header row, then one
// node per row in any order. The spacing along each axis is the median gap between the distinct
// coordinates, so a stray off-grid node is reported as such rather than taken for the spacing.

#include <cstddef>
#include <filesystem>
#include <string_view>
#include <vector>

namespace arcwheel::polishing {

struct CsvGrid {
  double x0_mm = 0.0, y0_mm = 0.0;
  double dx_mm = 1.0, dy_mm = 1.0;  // 1 along an axis with a single coordinate
  int nx = 0, ny = 0;
  std::vector<double> values;      // [j * nx + i]; NaN where no row gives the node (or it says nan)
  std::vector<std::size_t> lines;  // [j * nx + i]: the file line of the node, 0 where no row gives it
  std::size_t last_line = 0;       // the file's last data line, for messages about the whole grid
};

// One `x_mm,y_mm,<value_column>` row of a CSV, as read.
struct CsvTriple {
  double x_mm = 0.0, y_mm = 0.0, value = 0.0;
  std::size_t line = 0;
};

// The rows of such a CSV. Throws Error{kIo} if unreadable and Error{kBadInput, stage} naming the
// file and line for a wrong header, a cell that is not a number, a wrong cell count or a
// non-finite coordinate. The value may be `nan`.
[[nodiscard]] std::vector<CsvTriple> ReadCsvTriples(const std::filesystem::path& path,
                                                    std::string_view value_column, std::string_view stage);

// The rows placed on their grid. Also throws Error{kBadInput, stage} for fewer than two nodes, a
// node off the grid or given twice (naming its line), or a grid of more than 1e8 nodes.
[[nodiscard]] CsvGrid ReadCsvGrid(const std::filesystem::path& path, std::string_view value_column,
                                  std::string_view stage);

}  // namespace arcwheel::polishing
