// formats.md 2.2. Parsing is by std::from_chars on a buffer holding the whole file: a 1e7-line
// scan is ~100 MB and parses in about a second.

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/scan_metadata_keys.h"
#include "acquisition/scan_reader.h"
#include "core/error.h"
#include "core/nan.h"
#include "core/text_encoding.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kCsvReaderStage = "acquisition.csv";

enum class Column { kZ, kT, kAngle, kY, kIndex };

class CsvParser {
 public:
  CsvParser(std::string path, std::string text) : path_(std::move(path)), text_(std::move(text)) {}

  Scan Parse() {
    Scan scan;
    scan.path = path_;
    // Excel writes a UTF-8 byte-order mark before the first cell.
    if (text_.starts_with("\xEF\xBB\xBF")) position_ = 3;
    ReadMetadata(scan.metadata);
    ReadHeader();
    ReadRows(scan);
    return scan;
  }

 private:
  [[noreturn]] void Refuse(const std::string& problem) const {
    throw Error(ErrorCode::kBadInput, kCsvReaderStage,
                "'" + path_ + "' line " + std::to_string(line_number_) + ": " + problem);
  }

  bool NextLine(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    const size_t end = text_.find('\n', position_);
    const size_t stop = end == std::string::npos ? text_.size() : end;
    line = std::string_view(text_).substr(position_, stop - position_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    position_ = end == std::string::npos ? text_.size() : end + 1;
    ++line_number_;
    return true;
  }

  static std::string_view Trim(std::string_view s) {
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.front()))) s.remove_prefix(1);
    while (!s.empty() && std::isspace(static_cast<unsigned char>(s.back()))) s.remove_suffix(1);
    return s;
  }

  // Blanks off both ends, but not the separator: in a tab-separated file a trailing tab ends an
  // empty last cell (an invalid sample), it is not white space.
  std::string_view TrimLine(std::string_view s) const {
    auto blank = [this](char c) { return c != separator_ && std::isspace(static_cast<unsigned char>(c)); };
    while (!s.empty() && blank(s.front())) s.remove_prefix(1);
    while (!s.empty() && blank(s.back())) s.remove_suffix(1);
    return s;
  }

  void ReadMetadata(ScanMetadata& metadata) {
    // Leading `#` lines: `# key: value`; a `#` line without a colon is a comment. A spreadsheet
    // that saved them quotes the whole line when it holds the separator.
    MetadataSetter setter(metadata);
    while (position_ < text_.size() && (text_[position_] == '#' || text_.compare(position_, 2, "\"#") == 0)) {
      std::string_view line;
      NextLine(line);
      std::string unquoted;
      if (line.starts_with('"')) {
        unquoted = Unquote(Trim(line));
        line = unquoted;
      }
      line.remove_prefix(1);
      const size_t colon = line.find(':');
      if (colon == std::string_view::npos) continue;
      try {
        const std::string key = setter.Claim(Trim(line.substr(0, colon)));
        if (!key.empty()) setter.SetText(key, Trim(line.substr(colon + 1)));
      } catch (const Error& error) {
        Refuse(error.what());
      }
    }
  }

  // RFC 4180: a cell in double quotes, "" standing for one quote inside it.
  static std::string Unquote(std::string_view cell) {
    if (cell.size() < 2 || cell.front() != '"' || cell.back() != '"') return std::string(cell);
    std::string out;
    for (size_t i = 1; i + 1 < cell.size(); ++i) {
      out += cell[i];
      if (cell[i] == '"' && cell[i + 1] == '"') ++i;
    }
    return out;
  }

  void ReadHeader() {
    std::string_view line;
    do {
      if (!NextLine(line)) Refuse("no header row (expected column names such as z_mm)");
    } while (Trim(line).empty());
    separator_ = line.find(',') != std::string_view::npos    ? ','
                 : line.find(';') != std::string_view::npos  ? ';'
                 : line.find('\t') != std::string_view::npos ? '\t'
                                                             : ',';
    const std::vector<std::string_view> names = Split(TrimLine(line));
    for (size_t j = 0; j < names.size(); ++j) {
      const std::string name = AsciiLower(Trim(names[j]));
      if (name == "z_mm")
        columns_.push_back(Column::kZ);
      else if (name == "t_s")
        columns_.push_back(Column::kT);
      else if (name == "angle_deg")
        columns_.push_back(Column::kAngle);
      else if (name == "y_mm")
        columns_.push_back(Column::kY);
      else if (j == 0 && (name.empty() || name == "unnamed: 0"))
        columns_.push_back(Column::kIndex);
      else {
        bool latin1 = false;
        Refuse("unknown column '" + AsUtf8(name, latin1) + "' (expected z_mm, t_s, angle_deg, y_mm)");
      }
    }
    for (const Column c : {Column::kZ, Column::kT, Column::kAngle, Column::kY}) {
      if (std::count(columns_.begin(), columns_.end(), c) > 1) Refuse("a column is named twice");
    }
    if (std::find(columns_.begin(), columns_.end(), Column::kZ) == columns_.end()) {
      Refuse("the header has no z_mm column");
    }
  }

  // The line's cells, unquoted (RFC 4180). A line without quotes (nearly every line of a scan) is
  // cut in place; one with quotes is unquoted into quoted_, which the views then point into.
  std::vector<std::string_view> Split(std::string_view line) {
    std::vector<std::string_view> cells;
    if (line.find('"') == std::string_view::npos) {
      size_t start = 0;
      while (true) {
        const size_t next = line.find(separator_, start);
        cells.push_back(
            line.substr(start, next == std::string_view::npos ? std::string_view::npos : next - start));
        if (next == std::string_view::npos) break;
        start = next + 1;
      }
      return cells;
    }
    quoted_.clear();
    std::vector<std::pair<size_t, size_t>> spans;  // into quoted_, which may reallocate while it grows
    size_t i = 0;
    while (true) {
      while (i < line.size() && line[i] == ' ') ++i;
      const size_t begin = quoted_.size();
      if (i < line.size() && line[i] == '"') {
        for (++i;; ++i) {
          if (i >= line.size()) Refuse("a quoted cell is not closed on its line");
          if (line[i] == '"') {
            if (i + 1 < line.size() && line[i + 1] == '"') {
              quoted_ += '"';
              ++i;
              continue;
            }
            ++i;
            break;
          }
          quoted_ += line[i];
        }
        while (i < line.size() && line[i] == ' ') ++i;
        if (i < line.size() && line[i] != separator_) Refuse("text after a quoted cell");
      } else {
        while (i < line.size() && line[i] != separator_) {
          if (line[i] == '"') Refuse("a quote inside an unquoted cell");
          quoted_ += line[i++];
        }
      }
      spans.emplace_back(begin, quoted_.size() - begin);
      if (i >= line.size()) break;
      ++i;  // the separator
    }
    for (const auto& [begin, length] : spans)
      cells.push_back(std::string_view(quoted_).substr(begin, length));
    return cells;
  }

  // Keyence-style over-range words ([+-]?F+) and ALARM mark an invalid sample.
  static bool IsAlarmWord(std::string_view cell) {
    if (cell.size() == 5 && std::equal(cell.begin(), cell.end(), "ALARM", [](char a, char b) {
          return std::toupper(static_cast<unsigned char>(a)) == b;
        })) {
      return true;
    }
    if (!cell.empty() && (cell.front() == '+' || cell.front() == '-')) cell.remove_prefix(1);
    return !cell.empty() &&
           std::all_of(cell.begin(), cell.end(), [](char c) { return c == 'F' || c == 'f'; });
  }

  static bool IsNanWord(std::string_view cell) {
    if (!cell.empty() && (cell.front() == '+' || cell.front() == '-')) cell.remove_prefix(1);
    return cell.size() == 3 && std::tolower(static_cast<unsigned char>(cell[0])) == 'n' &&
           std::tolower(static_cast<unsigned char>(cell[1])) == 'a' &&
           std::tolower(static_cast<unsigned char>(cell[2])) == 'n';
  }

  // inf, infinity (any case, signed): a float sensor's over-range reading.
  static bool IsInfinityWord(std::string_view cell) {
    if (!cell.empty() && (cell.front() == '+' || cell.front() == '-')) cell.remove_prefix(1);
    auto equals = [cell](std::string_view word) {
      return cell.size() == word.size() &&
             std::equal(cell.begin(), cell.end(), word.begin(),
                        [](char a, char b) { return std::tolower(static_cast<unsigned char>(a)) == b; });
    };
    return equals("inf") || equals("infinity");
  }

  double ParseNumber(std::string_view cell, const char* column) const {
    if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
    double value = 0.0;
    const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
    if (error != std::errc() || end != cell.data() + cell.size() || !std::isfinite(value)) {
      std::string hint;
      if (cell.find(',') != std::string_view::npos) hint = " (decimal comma? the decimal point must be '.')";
      Refuse("cannot read " + std::string(column) + " value '" + std::string(cell) + "'" + hint);
    }
    return value;
  }

  double ParseZ(std::string_view cell) const {
    if (cell.empty() || IsNanWord(cell) || IsInfinityWord(cell) || IsAlarmWord(cell)) return kNaN;
    return ParseNumber(cell, "z_mm");
  }

  void ReadRows(Scan& scan) {
    if (columns_.front() == Column::kIndex) {
      scan.metadata.notes.push_back("column 1 has no name (a row index, as pandas writes it): ignored");
    }
    const bool one_column = columns_.size() == 1;
    for (const Column c : columns_) {
      if (c == Column::kT) has_t_ = true;
      if (c == Column::kAngle) has_angle_ = true;
      if (c == Column::kY) has_y_ = true;
    }
    const size_t estimate =
        static_cast<size_t>(std::count(text_.begin() + static_cast<long>(position_), text_.end(), '\n')) + 1;
    scan.z_mm.reserve(estimate);
    if (has_t_) scan.t_s.reserve(estimate);
    if (has_angle_) scan.angle_deg.reserve(estimate);
    if (has_y_) scan.y_mm.reserve(estimate);
    std::string_view line;
    std::vector<std::string_view> cells;
    while (NextLine(line)) {
      const std::string_view trimmed = TrimLine(line);
      if (trimmed.empty()) {
        // In a one-column file a blank line is an invalid sample; trailing blank lines are not.
        if (one_column && position_ < text_.size()) scan.z_mm.push_back(kNaN);
        continue;
      }
      cells = Split(trimmed);
      if (cells.size() != columns_.size()) {
        Refuse("has " + std::to_string(cells.size()) + " cells, the header names " +
               std::to_string(columns_.size()));
      }
      for (size_t j = 0; j < cells.size(); ++j) {
        const std::string_view cell = Trim(cells[j]);
        switch (columns_[j]) {
          case Column::kZ:
            scan.z_mm.push_back(ParseZ(cell));
            break;
          case Column::kT:
            scan.t_s.push_back(ParseRequired(cell, "t_s"));
            break;
          case Column::kAngle:
            scan.angle_deg.push_back(ParseRequired(cell, "angle_deg"));
            break;
          case Column::kY:
            scan.y_mm.push_back(ParseRequired(cell, "y_mm"));
            break;
          case Column::kIndex:
            break;
        }
      }
    }
  }

  double ParseRequired(std::string_view cell, const char* column) const {
    if (cell.empty()) Refuse(std::string("empty ") + column + " cell");
    return ParseNumber(cell, column);
  }

  std::string path_;
  std::string text_;
  size_t position_ = 0;
  size_t line_number_ = 0;
  char separator_ = ',';
  std::vector<Column> columns_;
  bool has_t_ = false;
  bool has_angle_ = false;
  bool has_y_ = false;
  std::string quoted_;  // the unquoted cells of the current line, when it has quotes
};

std::string ReadWholeFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, kCsvReaderStage, "cannot open '" + path.string() + "'");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::kIo, kCsvReaderStage, "cannot read '" + path.string() + "'");
  return std::move(buffer).str();
}

}  // namespace

Scan ReadCsvScan(const std::filesystem::path& path, const ReadOptions& options) {
  return ParseCsvScan(ReadWholeFile(path), path.string(), options);
}

Scan ParseCsvScan(std::string text, const std::string& name, const ReadOptions& options) {
  CsvParser parser(name, std::move(text));
  Scan scan = parser.Parse();
  scan.read.format = "csv";
  ApplyInvalidMarkers(scan, SentinelComparison::kAsDouble);
  FinishScan(scan, options);
  return scan;
}

}  // namespace arcwheel::acquisition
