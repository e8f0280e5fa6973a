#pragma once
// Two numeric columns of a small CSV chosen by their header names, for the commands that read
// point lists (`fit circle`, `roundness`). Comment lines (#) before the header are skipped; cells
// are separated by commas, semicolons or tabs.

#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace arcwheel::cli {

struct TwoColumns {
  std::string first_name, second_name;  // the pair of column names that was read
  std::vector<double> first, second;
  std::vector<std::size_t> line;  // 1-based file line of each row, for messages
};

// Reads the first pair of `choices` whose two names the header has. Throws Error{kIo, stage} if
// the file cannot be opened, Error{kBadInput, stage} naming the file and line for a header
// without any pair, a row with another number of cells than the header, or a cell that is not a
// finite number.
[[nodiscard]] TwoColumns ReadTwoColumns(const std::string& path, std::string_view stage,
                                        const std::vector<std::pair<std::string, std::string>>& choices);

}  // namespace arcwheel::cli
