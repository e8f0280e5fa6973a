#include "cli/columns_csv.h"

#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <optional>
#include <sstream>

#include "core/error.h"

namespace arcwheel::cli {
namespace {

std::vector<std::string> SplitCells(const std::string& line) {
  const char separator = line.find(',') != std::string::npos   ? ','
                         : line.find(';') != std::string::npos ? ';'
                                                               : '\t';
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, separator)) {
    const auto begin = cell.find_first_not_of(" \t\r");
    const auto end = cell.find_last_not_of(" \t\r");
    cells.push_back(begin == std::string::npos ? "" : cell.substr(begin, end - begin + 1));
  }
  return cells;
}

std::optional<std::size_t> ColumnOf(const std::vector<std::string>& header, const std::string& name) {
  for (std::size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return i;
  }
  return std::nullopt;
}

std::string MissingColumns(const std::string& path, const std::vector<std::string>& header,
                           const std::vector<std::pair<std::string, std::string>>& choices) {
  if (choices.size() == 1) {
    const std::string& missing = ColumnOf(header, choices[0].first) ? choices[0].second : choices[0].first;
    return fmt::format("'{}': the header has no column '{}'", path, missing);
  }
  std::string names;
  for (std::size_t i = 0; i < choices.size(); ++i) {
    names += fmt::format("{}{},{}",
                         i == 0                    ? ""
                         : i + 1 == choices.size() ? " or "
                                                   : ", ",
                         choices[i].first, choices[i].second);
  }
  return fmt::format("'{}': the header names neither pair of columns {}", path, names);
}

}  // namespace

TwoColumns ReadTwoColumns(const std::string& path, std::string_view stage,
                          const std::vector<std::pair<std::string, std::string>>& choices) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::kIo, stage, "cannot open '" + path + "'");
  std::string line;
  std::size_t number = 0;
  std::vector<std::string> header;
  while (std::getline(in, line)) {
    ++number;
    if (line.empty() || line[0] == '#') continue;
    header = SplitCells(line);
    break;
  }
  TwoColumns columns;
  std::size_t first = 0, second = 0;
  bool found = false;
  for (const auto& [first_name, second_name] : choices) {
    const auto a = ColumnOf(header, first_name);
    const auto b = ColumnOf(header, second_name);
    if (!a || !b) continue;
    first = *a, second = *b, found = true;
    columns.first_name = first_name, columns.second_name = second_name;
    break;
  }
  if (!found) throw Error(ErrorCode::kBadInput, stage, MissingColumns(path, header, choices));
  while (std::getline(in, line)) {
    ++number;
    if (line.find_first_not_of(" \t\r") == std::string::npos) continue;
    const std::vector<std::string> cells = SplitCells(line);
    if (cells.size() != header.size()) {
      throw Error(ErrorCode::kBadInput, stage,
                  fmt::format("'{}' line {}: {} cells, the header names {}", path, number, cells.size(),
                              header.size()));
    }
    for (const std::size_t column : {first, second}) {
      double value = 0;
      const std::string& cell = cells[column];
      const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
      if (error != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value)) {
        throw Error(
            ErrorCode::kBadInput, stage,
            fmt::format("'{}' line {}: cannot read {} value '{}'", path, number, header[column], cell));
      }
      (column == first ? columns.first : columns.second).push_back(value);
    }
    columns.line.push_back(number);
  }
  return columns;
}

}  // namespace arcwheel::cli
