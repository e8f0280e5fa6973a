#include "frames/csv_table.h"

#include <fmt/core.h>

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/text_lines.h"

namespace arcwheel::frames {
namespace {

std::vector<std::string> SplitCells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) cells.push_back(std::string(TrimBlanks(cell)));
  if (!line.empty() && line.back() == ',') cells.emplace_back();
  return cells;
}

void ReadNote(const std::string& line, CsvTable& table) {
  const std::string body(TrimBlanks(std::string_view(line).substr(1)));
  const auto colon = body.find(':');
  if (colon == std::string::npos) return;
  table.notes[std::string(TrimBlanks(std::string_view(body).substr(0, colon)))] =
      std::string(TrimBlanks(std::string_view(body).substr(colon + 1)));
}

}  // namespace

std::optional<size_t> CsvTable::Find(std::string_view name) const {
  for (size_t i = 0; i < columns.size(); ++i) {
    if (columns[i] == name) return i;
  }
  return std::nullopt;
}

size_t CsvTable::Require(std::string_view name, std::string_view stage) const {
  if (const auto index = Find(name)) return *index;
  std::string header;
  for (const auto& column : columns) header += (header.empty() ? "" : ",") + column;
  throw Error(ErrorCode::kBadInput, stage,
              fmt::format("'{}' has no column '{}' (header: {})", path.string(), name, header));
}

double CsvTable::Number(size_t row, size_t column, std::string_view stage) const {
  const std::string& cell = cells[row][column];
  double value = 0.0;
  const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  if (error != std::errc() || end != cell.data() + cell.size() || cell.empty() || !std::isfinite(value)) {
    throw Error(ErrorCode::kBadInput, stage,
                fmt::format("'{}' line {}, column '{}': '{}' is not a finite number", path.string(),
                            line_numbers[row], columns[column], cell));
  }
  return value;
}

CsvTable ReadCsvTable(const std::filesystem::path& path, std::string_view stage) {
  std::ifstream file(path);
  if (!file) throw Error(ErrorCode::kIo, stage, fmt::format("cannot open '{}'", path.string()));
  CsvTable table;
  table.path = path;
  std::string line;
  int line_number = 0;
  while (std::getline(file, line)) {
    ++line_number;
    const std::string trimmed(TrimBlanks(line));
    if (trimmed.empty()) continue;
    if (trimmed.front() == '#') {
      ReadNote(trimmed, table);
      continue;
    }
    std::vector<std::string> cells = SplitCells(trimmed);
    if (table.columns.empty()) {
      table.columns = std::move(cells);
      continue;
    }
    if (cells.size() != table.columns.size()) {
      throw Error(ErrorCode::kBadInput, stage,
                  fmt::format("'{}' line {}: {} cells, but the header has {} columns", path.string(),
                              line_number, cells.size(), table.columns.size()));
    }
    table.cells.push_back(std::move(cells));
    table.line_numbers.push_back(line_number);
  }
  if (file.bad()) throw Error(ErrorCode::kIo, stage, fmt::format("cannot read '{}'", path.string()));
  if (table.columns.empty())
    throw Error(ErrorCode::kBadInput, stage, fmt::format("'{}' has no header row", path.string()));
  if (table.cells.empty())
    throw Error(ErrorCode::kBadInput, stage, fmt::format("'{}' has no data rows", path.string()));
  return table;
}

}  // namespace arcwheel::frames
