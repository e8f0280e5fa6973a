#pragma once
// A small CSV reader for the frames inputs (point pairs, force records, record lists): `# key: value`
// note lines and blank lines anywhere, one header row, comma-separated cells. Every error names the
// file and the line.

#include <cstddef>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace arcwheel::frames {

struct CsvTable {
  std::filesystem::path path;
  std::vector<std::string> columns;             // header names, trimmed
  std::vector<std::vector<std::string>> cells;  // one row per data line, trimmed cells
  std::vector<int> line_numbers;                // 1-based file line of each row
  std::map<std::string, std::string> notes;     // from `# key: value` lines

  // Index of the column named `name`, or nullopt.
  [[nodiscard]] std::optional<size_t> Find(std::string_view name) const;
  // Index of the column named `name`; throws Error{kBadInput, stage} naming the file if absent.
  [[nodiscard]] size_t Require(std::string_view name, std::string_view stage) const;
  // The number in row `row`, column `column`. Throws Error{kBadInput, stage} naming the file, the
  // line and the column if the cell is not a finite number.
  [[nodiscard]] double Number(size_t row, size_t column, std::string_view stage) const;
};

// Reads `path`. Throws Error{kIo} if it cannot be read and Error{kBadInput, stage} if it has no
// header, a row whose cell count differs from the header's (naming the line), or no data rows.
[[nodiscard]] CsvTable ReadCsvTable(const std::filesystem::path& path, std::string_view stage);

}  // namespace arcwheel::frames
