// formats.md 2.4: the sensors' own files (docs/inputs.md shows each layout). One reader of delimited
// text does the rows of every layout; each layout only finds its column row, reads its header lines
// and says which column holds which quantity, in which unit, and which invalid markers it knows.
// Numbers are parsed by std::from_chars on a buffer holding the whole file, as the contract CSV
// reader does; a decimal comma is turned into a point in a small copy of the cell first.

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstring>
#include <fstream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/scan_format.h"
#include "acquisition/scan_metadata_keys.h"
#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"
#include "core/check.h"
#include "core/error.h"
#include "core/nan.h"
#include "core/text_encoding.h"
#include "core/text_lines.h"

namespace arcwheel::acquisition {
namespace {

enum class Quantity { kZ, kT, kAngle, kY };
constexpr std::array<const char*, 4> kQuantityNames = {"z", "t", "angle", "y"};

// Invalid markers, by kind (summary.json's input.invalid_markers).
enum class Marker { kEmpty, kNan, kOutOfRangeHigh, kOutOfRangeLow, kAlarm, kWaiting };
constexpr std::array<const char*, 6> kMarkerNames = {
    "empty", "nan", "out_of_range_high", "out_of_range_low", "alarm", "waiting"};

std::string Lower(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

// A header cell as the tools quote it: "Distance1 (mm)".
std::string_view Unquote(std::string_view s) {
  s = TrimBlanks(s);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = s.substr(1, s.size() - 2);
  return TrimBlanks(s);
}

std::vector<std::string_view> SplitCells(std::string_view line, char separator) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  while (true) {
    const std::size_t next = line.find(separator, start);
    cells.push_back(
        line.substr(start, next == std::string_view::npos ? std::string_view::npos : next - start));
    if (next == std::string_view::npos) break;
    start = next + 1;
  }
  // A trailing separator ends no further column.
  if (cells.size() > 1 && TrimBlanks(cells.back()).empty()) cells.pop_back();
  return cells;
}

char SeparatorOf(std::string_view line) {
  if (line.find(';') != std::string_view::npos) return ';';
  if (line.find('\t') != std::string_view::npos) return '\t';
  return ',';
}

// The unit written in a header after the name: "Distance1 (mm)", "OUT1[mm]"; empty when none.
std::string UnitInHeader(std::string_view header) {
  const std::size_t open = header.find_last_of("([");
  if (open == std::string_view::npos) return "";
  const std::size_t close = header.find_first_of(")]", open);
  if (close == std::string_view::npos) return "";
  return std::string(TrimBlanks(header.substr(open + 1, close - open - 1)));
}

// The divisor from `unit` to the contract's unit of `quantity` (mm, s, deg): dividing by an exact
// power of ten gives the double nearest the value in the contract's unit. Empty when the unit is not
// one of that quantity. "counts" (angle) is scaled by the caller, from encoder_counts_per_rev.
std::optional<double> ScaleOf(Quantity quantity, const std::string& unit) {
  const std::string u = Lower(unit);
  switch (quantity) {
    case Quantity::kZ:
    case Quantity::kY:
      if (u == "mm") return 1.0;
      if (u == "um" || u == "\xC2\xB5m" || u == "\xCE\xBCm") return 1e3;
      if (u == "nm") return 1e6;
      return std::nullopt;
    case Quantity::kT:
      if (u == "s") return 1.0;
      if (u == "ms") return 1e3;
      if (u == "us" || u == "\xC2\xB5s" || u == "\xCE\xBCs") return 1e6;
      return std::nullopt;
    case Quantity::kAngle:
      if (u == "deg" || u == "\xC2\xB0") return 1.0;
      return std::nullopt;
  }
  return std::nullopt;
}

const char* UnitsOf(Quantity quantity) {
  switch (quantity) {
    case Quantity::kZ:
    case Quantity::kY:
      return "mm, um or nm";
    case Quantity::kT:
      return "s, ms or us";
    case Quantity::kAngle:
      return "deg or counts";
  }
  return "";
}

// One column of the layout: which quantity it holds, where, and how to read it.
struct ColumnSpec {
  Quantity quantity = Quantity::kZ;
  std::string header;  // as the column row writes it; for --columns, the name asked for
  std::size_t index = 0;
  std::string unit;
  double factor = 1.0;  // value in the contract's unit = value as written * factor / divisor
  double divisor = 1.0;
  bool clock_time = false;  // hh:mm:ss[.,]fff (sensorTOOL's acquisition time as a time of day)
};

// `--columns` parsed: quantity, header name, unit ("" = the header's own, else the quantity's).
struct ColumnRequest {
  Quantity quantity;
  std::string name;
  std::string unit;
};

std::optional<Quantity> QuantityNamed(std::string_view name) {
  for (std::size_t i = 0; i < kQuantityNames.size(); ++i) {
    if (name == kQuantityNames[i]) return static_cast<Quantity>(i);
  }
  return std::nullopt;
}

std::vector<ColumnRequest> ParseColumnsOption(std::string_view text, std::vector<std::string>* problems) {
  std::vector<ColumnRequest> requests;
  std::size_t start = 0;
  while (start <= text.size()) {
    const std::size_t comma = text.find(',', start);
    const std::string_view item = TrimBlanks(
        text.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    start = comma == std::string_view::npos ? text.size() + 1 : comma + 1;
    const std::size_t equals = item.find('=');
    const std::optional<Quantity> quantity =
        equals == std::string_view::npos ? std::nullopt : QuantityNamed(TrimBlanks(item.substr(0, equals)));
    if (!quantity) {
      problems->push_back(
          fmt::format("--columns = '{}' violates QUANTITY=NAME[:UNIT] with QUANTITY z, t, angle or y", item));
      continue;
    }
    std::string_view rest = item.substr(equals + 1);
    std::string unit;
    if (const std::size_t colon = rest.rfind(':'); colon != std::string_view::npos) {
      unit = std::string(TrimBlanks(rest.substr(colon + 1)));
      rest = rest.substr(0, colon);
      if (!ScaleOf(*quantity, unit) && !(*quantity == Quantity::kAngle && Lower(unit) == "counts")) {
        problems->push_back(fmt::format("--columns = '{}' violates a unit of {}: {}", item,
                                        kQuantityNames[static_cast<std::size_t>(*quantity)],
                                        UnitsOf(*quantity)));
      }
    }
    const std::string_view name = Unquote(rest);
    if (name.empty()) problems->push_back(fmt::format("--columns = '{}' names no column", item));
    if (std::any_of(requests.begin(), requests.end(),
                    [&](const ColumnRequest& r) { return r.quantity == *quantity; })) {
      problems->push_back(
          fmt::format("--columns names {} twice", kQuantityNames[static_cast<std::size_t>(*quantity)]));
    }
    requests.push_back({*quantity, std::string(name), unit});
  }
  if (problems->empty() && std::none_of(requests.begin(), requests.end(),
                                        [](const ColumnRequest& r) { return r.quantity == Quantity::kZ; })) {
    problems->push_back("--columns names no z column (z=NAME[:UNIT])");
  }
  return requests;
}

const char* DefaultUnit(Quantity quantity) {
  switch (quantity) {
    case Quantity::kT:
      return "s";
    case Quantity::kAngle:
      return "deg";
    default:
      return "mm";
  }
}

class SensorParser {
 public:
  SensorParser(std::string path, std::string text, ScanFormat format, const ReadOptions& options)
      : path_(std::move(path)),
        text_(std::move(text)),
        format_(format),
        options_(options),
        stage_(std::string("acquisition.") + std::string(InfoOf(format).name)) {}

  Scan Parse() {
    Scan scan;
    scan.path = path_;
    scan.read.format = std::string(InfoOf(format_).name);
    if (std::string_view(text_).starts_with("\xEF\xBB\xBF")) position_ = 3;
    switch (format_) {
      case ScanFormat::kSensorTool:
        ReadSensorToolHeader(scan.metadata);
        break;
      case ScanFormat::kKeyenceLk:
        ReadKeyenceHeader(scan.metadata);
        break;
      default:
        ReadColumnsHeader();
        break;
    }
    if (!options_.columns.empty() && format_ != ScanFormat::kColumns) ApplyColumnsOption();
    if (!unused_keys_.empty()) {
      scan.metadata.notes.push_back(fmt::format("header lines not used: {}", unused_keys_));
    }
    ReadRows(scan);
    return scan;
  }

 private:
  [[noreturn]] void Refuse(std::size_t line, const std::string& problem) const {
    throw Error(ErrorCode::kBadInput, stage_, fmt::format("'{}' line {}: {}", path_, line, problem));
  }
  [[noreturn]] void RefuseFile(const std::string& problem) const {
    throw Error(ErrorCode::kBadInput, stage_, fmt::format("'{}': {}", path_, problem));
  }

  bool NextLine(std::string_view& line) {
    if (position_ >= text_.size()) return false;
    const std::size_t end = text_.find('\n', position_);
    const std::size_t stop = end == std::string::npos ? text_.size() : end;
    line = std::string_view(text_).substr(position_, stop - position_);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    position_ = end == std::string::npos ? text_.size() : end + 1;
    ++line_number_;
    return true;
  }

  static std::string Utf8(std::string_view text) {
    bool latin1 = false;
    return AsUtf8(text, latin1);
  }

  void NoteUnused(std::string_view key) {
    if (TrimBlanks(key).empty()) return;
    unused_keys_ += (unused_keys_.empty() ? "'" : ", '") + Utf8(TrimBlanks(key)) + "'";
  }

  // A header line's number and unit, as in "Measuring rate;20 kHz", "Measuring rate;20;kHz" or
  // "Sampling cycle,50us"; returns the period in seconds.
  std::optional<double> PeriodOf(const std::vector<std::string_view>& cells) const {
    std::string text;
    for (std::size_t i = 1; i < cells.size(); ++i) text += std::string(TrimBlanks(cells[i])) + " ";
    std::string_view rest = TrimBlanks(text);
    std::size_t digits = 0;
    while (digits < rest.size() && (std::isdigit(static_cast<unsigned char>(rest[digits])) ||
                                    rest[digits] == '.' || rest[digits] == ',')) {
      ++digits;
    }
    std::string number(rest.substr(0, digits));
    std::replace(number.begin(), number.end(), ',', '.');
    double value = 0.0;
    const auto [end, error] = std::from_chars(number.data(), number.data() + number.size(), value);
    if (number.empty() || error != std::errc() || end != number.data() + number.size() || !(value > 0.0)) {
      return std::nullopt;
    }
    // Divided by exact powers of ten, so that "100 us" is the double nearest 1e-4 s, as "0.0001" is.
    const std::string unit = Lower(TrimBlanks(rest.substr(digits)));
    if (unit == "hz") return 1.0 / value;
    if (unit == "khz") return 1.0 / (value * 1e3);
    if (unit == "mhz") return 1.0 / (value * 1e6);
    if (unit == "s") return value;
    if (unit == "ms") return value / 1e3;
    if (unit == "us" || unit == "\xC2\xB5s" || unit == "\xCE\xBCs") return value / 1e6;
    return std::nullopt;
  }

  void SetPeriod(ScanMetadata& metadata, const std::vector<std::string_view>& cells) {
    const std::optional<double> period = PeriodOf(cells);
    if (!period) {
      std::string written;
      for (std::size_t i = 1; i < cells.size(); ++i)
        written += std::string(i > 1 ? " " : "") + std::string(TrimBlanks(cells[i]));
      Refuse(line_number_,
             fmt::format("'{}' is not a rate or period arcwheel reads ('{}'; e.g. 20 kHz, 50 us)",
                         Utf8(TrimBlanks(cells[0])), Utf8(written)));
    }
    MetadataSetter setter(metadata);
    (void)setter.Claim("sample_period_s");
    setter.SetNumber("sample_period_s", *period);
  }

  void SetSensor(ScanMetadata& metadata, std::string_view value) {
    MetadataSetter setter(metadata);
    (void)setter.Claim("sensor");
    setter.SetText("sensor", Unquote(value));
  }

  // Reads the column row just read into header_cells_ and separator_.
  void TakeColumnRow(std::string_view line) {
    separator_ = SeparatorOf(line);
    header_cells_.clear();
    for (const std::string_view cell : SplitCells(line, separator_))
      header_cells_.emplace_back(Unquote(cell));
    header_line_ = line_number_;
  }

  std::optional<std::size_t> FindHeader(const auto& matches) const {
    for (std::size_t j = 0; j < header_cells_.size(); ++j) {
      if (matches(Lower(header_cells_[j]))) return j;
    }
    return std::nullopt;
  }

  // The column at `index` as `quantity`, its unit from the header (or `default_unit`).
  void Use(Quantity quantity, std::size_t index, const std::string& default_unit) {
    ColumnSpec spec;
    spec.quantity = quantity;
    spec.index = index;
    spec.header = header_cells_[index];
    spec.unit = UnitInHeader(spec.header);
    if (spec.unit.empty()) spec.unit = default_unit;
    SetScale(spec, header_line_);
    columns_.erase(std::remove_if(columns_.begin(), columns_.end(),
                                  [&](const ColumnSpec& c) { return c.quantity == quantity; }),
                   columns_.end());
    columns_.push_back(spec);
  }

  void SetScale(ColumnSpec& spec, std::size_t line) const {
    if (spec.quantity == Quantity::kAngle && Lower(spec.unit) == "counts") {
      const std::optional<double> counts =
          options_.settings != nullptr ? options_.settings->Number("encoder_counts_per_rev") : std::nullopt;
      if (!counts || !(*counts > 0.0)) {
        Refuse(line, fmt::format("column '{}' holds encoder counts: give \"encoder_counts_per_rev\" in "
                                 "--scan-settings SETTINGS.json",
                                 Utf8(spec.header)));
      }
      spec.factor = 360.0;
      spec.divisor = *counts;
      return;
    }
    const std::optional<double> divisor = ScaleOf(spec.quantity, spec.unit);
    if (!divisor) {
      Refuse(line,
             fmt::format("column '{}': unit '{}' is not one of {} ({})", Utf8(spec.header), Utf8(spec.unit),
                         kQuantityNames[static_cast<std::size_t>(spec.quantity)], UnitsOf(spec.quantity)));
    }
    spec.divisor = *divisor;
  }

  // sensorTOOL: header lines `key;value[;unit]` up to the column row, which starts with
  // `Acquisition time` or `Epoch time (ms)` or names a `Distance` column.
  void ReadSensorToolHeader(ScanMetadata& metadata) {
    std::string_view line;
    while (true) {
      if (!NextLine(line))
        RefuseFile("no column row (expected e.g. 'Acquisition time;Epoch time (ms);Distance1 (mm)')");
      const std::string_view trimmed = TrimBlanks(line);
      if (trimmed.empty()) continue;
      const std::string lower = Lower(trimmed);
      const char separator = SeparatorOf(trimmed);
      const std::vector<std::string_view> cells = SplitCells(trimmed, separator);
      const std::string first = Lower(Unquote(cells[0]));
      const bool column_row = first.starts_with("acquisition time") || first.starts_with("epoch time") ||
                              std::any_of(cells.begin(), cells.end(), [](std::string_view c) {
                                return Lower(Unquote(c)).starts_with("distance");
                              });
      if (column_row) {
        TakeColumnRow(trimmed);
        break;
      }
      if (first == "sensor" && cells.size() > 1) {
        SetSensor(metadata, cells[1]);
      } else if ((first == "measuring rate" || first == "sampling rate") && cells.size() > 1) {
        SetPeriod(metadata, cells);
      } else if (!first.starts_with("sensortool")) {
        NoteUnused(Unquote(cells[0]));
      }
    }
    const auto z = FindHeader([](const std::string& h) { return h.starts_with("distance"); });
    if (!z && options_.columns.empty()) {
      Refuse(header_line_, "the column row names no 'Distance' column (expected e.g. 'Distance1 (mm)')");
    }
    if (z) Use(Quantity::kZ, *z, "mm");
    // The acquisition time resolves the samples; the epoch time (whole milliseconds) only when
    // the sensor samples slower than 1 kHz.
    if (const auto t = FindHeader([](const std::string& h) { return h.starts_with("acquisition time"); })) {
      Use(Quantity::kT, *t, "s");
    } else if (const auto epoch =
                   FindHeader([](const std::string& h) { return h.starts_with("epoch time"); })) {
      Use(Quantity::kT, *epoch, "ms");
    }
  }

  // Keyence LK: LK-Navigator's export (`key,value` header lines, then a column row naming OUT1) or
  // a raw stream of fixed-width values, one line each (OUT1 first when a line holds several).
  void ReadKeyenceHeader(ScanMetadata& metadata) {
    std::string_view line;
    while (true) {
      const std::size_t before = position_;
      const std::size_t line_before = line_number_;
      if (!NextLine(line)) RefuseFile("no values");
      const std::string_view trimmed = TrimBlanks(line);
      if (trimmed.empty()) continue;
      const char separator = SeparatorOf(trimmed);
      const std::vector<std::string_view> cells = SplitCells(trimmed, separator);
      if (IsKeyenceLkValue(TrimBlanks(cells[0]))) {
        // A raw stream: this line is the first value.
        position_ = before;
        line_number_ = line_before;
        separator_ = separator;
        header_cells_.assign(cells.size(), "");
        header_cells_[0] = "OUT1";
        header_line_ = line_number_ + 1;
        Use(Quantity::kZ, 0, "mm");
        return;
      }
      const std::string first = Lower(Unquote(cells[0]));
      const bool column_row = std::any_of(cells.begin(), cells.end(), [](std::string_view c) {
        return Lower(Unquote(c)).starts_with("out");
      });
      if (column_row) {
        TakeColumnRow(trimmed);
        break;
      }
      if ((first == "model" || first == "sensor" || first == "sensor head") && cells.size() > 1) {
        SetSensor(metadata, cells[1]);
      } else if ((first == "sampling cycle" || first == "sampling frequency") && cells.size() > 1) {
        SetPeriod(metadata, cells);
      } else if (first.find("lk-navigator") == std::string::npos) {
        NoteUnused(Unquote(cells[0]));
      }
    }
    const auto z = FindHeader([](const std::string& h) { return h.starts_with("out"); });
    Use(Quantity::kZ, *z, "mm");
    if (const auto t = FindHeader([](const std::string& h) { return h.starts_with("time"); })) {
      Use(Quantity::kT, *t, "s");
    }
  }

  // Any delimited file: the column row is the first line that names every column of --columns.
  void ReadColumnsHeader() {
    if (options_.columns.empty()) {
      RefuseFile("the columns reader needs --columns z=NAME[:UNIT],... to know which column holds what");
    }
    std::vector<std::string> problems;
    const std::vector<ColumnRequest> requests = ParseColumnsOption(options_.columns, &problems);
    if (!problems.empty()) throw Error(ErrorCode::kInvalidOption, stage_, JoinProblems(problems));
    std::string_view line;
    while (NextLine(line)) {
      const std::string_view trimmed = TrimBlanks(line);
      if (trimmed.empty()) continue;
      std::vector<std::string> cells;
      for (const std::string_view cell : SplitCells(trimmed, SeparatorOf(trimmed)))
        cells.emplace_back(Unquote(cell));
      const bool names_all = std::all_of(requests.begin(), requests.end(), [&](const ColumnRequest& r) {
        return std::find(cells.begin(), cells.end(), r.name) != cells.end();
      });
      if (names_all) {
        TakeColumnRow(trimmed);
        ApplyColumnsOption();
        return;
      }
    }
    std::string names;
    for (const ColumnRequest& r : requests) names += (names.empty() ? "'" : ", '") + Utf8(r.name) + "'";
    RefuseFile(fmt::format("no line names the columns {} (--columns); column names match exactly", names));
  }

  // --columns over the layout's own choice (or as the whole of it, for `columns`).
  void ApplyColumnsOption() {
    std::vector<std::string> problems;
    const std::vector<ColumnRequest> requests = ParseColumnsOption(options_.columns, &problems);
    if (!problems.empty()) throw Error(ErrorCode::kInvalidOption, stage_, JoinProblems(problems));
    for (const ColumnRequest& request : requests) {
      const auto found = std::find(header_cells_.begin(), header_cells_.end(), request.name);
      if (found == header_cells_.end()) {
        std::string names;
        for (const std::string& h : header_cells_) names += (names.empty() ? "'" : ", '") + Utf8(h) + "'";
        Refuse(header_line_,
               fmt::format("no column '{}' (--columns {}=...); the column row names {}", Utf8(request.name),
                           kQuantityNames[static_cast<std::size_t>(request.quantity)], names));
      }
      const std::size_t index = static_cast<std::size_t>(found - header_cells_.begin());
      Use(request.quantity, index, request.unit.empty() ? DefaultUnit(request.quantity) : request.unit);
      if (!request.unit.empty()) {
        ColumnSpec& spec = columns_.back();
        spec.unit = request.unit;
        SetScale(spec, header_line_);
      }
    }
  }

  // A reading that is no number: the marker it is, or empty when the layout knows no such marker.
  std::optional<Marker> MarkerOf(std::string_view cell) const {
    if (cell.empty()) return Marker::kEmpty;
    if (Lower(cell) == "nan") return Marker::kNan;
    if (format_ == ScanFormat::kSensorTool) return std::nullopt;
    const auto all = [&](std::string_view s, char c) {
      return !s.empty() && std::all_of(s.begin(), s.end(), [c](char x) { return x == c; });
    };
    if ((cell.front() == '+' || cell.front() == '-') && cell.size() > 1 && all(cell.substr(1), 'F')) {
      return cell.front() == '+' ? Marker::kOutOfRangeHigh : Marker::kOutOfRangeLow;
    }
    if (all(cell, 'X')) return Marker::kAlarm;
    if (cell.size() >= 2 && all(cell, '-')) return Marker::kWaiting;
    return std::nullopt;
  }

  std::string KnownMarkersText() const {
    return format_ == ScanFormat::kSensorTool ? "an empty cell or nan"
                                              : "an empty cell, nan, +FFFFFFF, -FFFFFFF, XXXXXXXX or -------";
  }

  // A number as the tools write it: a leading '+', a decimal comma where ',' separates no cells.
  bool ParseNumber(std::string_view cell, double& value) const {
    if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
    const char* begin = cell.data();
    const char* end = cell.data() + cell.size();
    char buffer[64];
    if (separator_ != ',' && cell.size() < sizeof buffer && std::memchr(begin, ',', cell.size()) != nullptr) {
      std::memcpy(buffer, begin, cell.size());
      std::replace(buffer, buffer + cell.size(), ',', '.');
      begin = buffer;
      end = buffer + cell.size();
    }
    const auto [stop, error] = std::from_chars(begin, end, value);
    return error == std::errc() && stop == end && std::isfinite(value);
  }

  // hh:mm:ss[.,]fff as seconds since midnight.
  bool ParseClock(std::string_view cell, double& seconds) const {
    const std::size_t c1 = cell.find(':');
    const std::size_t c2 = c1 == std::string_view::npos ? c1 : cell.find(':', c1 + 1);
    if (c2 == std::string_view::npos) return false;
    int hours = 0, minutes = 0;
    const auto [h_end, h_error] = std::from_chars(cell.data(), cell.data() + c1, hours);
    const auto [m_end, m_error] = std::from_chars(cell.data() + c1 + 1, cell.data() + c2, minutes);
    double s = 0.0;
    if (h_error != std::errc() || h_end != cell.data() + c1 || m_error != std::errc() ||
        m_end != cell.data() + c2 || !ParseNumber(cell.substr(c2 + 1), s)) {
      return false;
    }
    seconds = hours * 3600.0 + minutes * 60.0 + s;
    return true;
  }

  void ReadRows(Scan& scan) {
    std::size_t last_index = 0;
    for (const ColumnSpec& c : columns_) last_index = std::max(last_index, c.index);
    // Which spec each cell index feeds (-1: none), so that a row is cut once, left to right, and
    // cells no quantity uses are not parsed.
    std::vector<int> role(last_index + 1, -1);
    for (std::size_t k = 0; k < columns_.size(); ++k) role[columns_[k].index] = static_cast<int>(k);
    std::vector<std::vector<double>*> targets;
    for (const ColumnSpec& c : columns_) {
      switch (c.quantity) {
        case Quantity::kZ:
          targets.push_back(&scan.z_mm);
          break;
        case Quantity::kT:
          targets.push_back(&scan.t_s);
          break;
        case Quantity::kAngle:
          targets.push_back(&scan.angle_deg);
          break;
        case Quantity::kY:
          targets.push_back(&scan.y_mm);
          break;
      }
    }
    const std::size_t estimate = static_cast<std::size_t>(std::count(
                                     text_.begin() + static_cast<long>(position_), text_.end(), '\n')) +
                                 1;
    for (std::vector<double>* target : targets) target->reserve(estimate);
    std::array<std::size_t, kMarkerNames.size()> marker_counts{};
    std::array<std::size_t, kMarkerNames.size()> marker_order{};
    std::size_t markers_seen = 0;
    double previous_time = -std::numeric_limits<double>::infinity();
    std::size_t time_ties = 0;
    std::string_view line;
    while (NextLine(line)) {
      if (TrimBlanks(line).empty()) continue;
      std::size_t start = 0;
      std::size_t index = 0;
      while (index <= last_index) {
        if (start > line.size()) {
          Refuse(line_number_, fmt::format("has {} cells; column '{}' is cell {}", index,
                                           Utf8(header_cells_[last_index]), last_index + 1));
        }
        const std::size_t next = line.find(separator_, start);
        const std::size_t stop = next == std::string_view::npos ? line.size() : next;
        const int k = role[index];
        if (k >= 0) {
          const ColumnSpec& spec = columns_[static_cast<std::size_t>(k)];
          const std::string_view cell = TrimBlanks(line.substr(start, stop - start));
          double value = 0.0;
          bool parsed = spec.clock_time ? ParseClock(cell, value) : ParseNumber(cell, value);
          if (!parsed && spec.quantity == Quantity::kT && !spec.clock_time && ParseClock(cell, value)) {
            columns_[static_cast<std::size_t>(k)].clock_time = parsed = true;
          }
          if (parsed) {
            value = value * spec.factor / spec.divisor;
          } else if (spec.quantity == Quantity::kZ) {
            const std::optional<Marker> marker = MarkerOf(cell);
            if (!marker) {
              Refuse(line_number_, fmt::format("column '{}': '{}' is neither a number nor an invalid marker "
                                               "this format knows ({})",
                                               Utf8(spec.header), Utf8(cell), KnownMarkersText()));
            }
            const auto m = static_cast<std::size_t>(*marker);
            if (marker_counts[m]++ == 0) marker_order[markers_seen++] = m;
            value = kNaN;
          } else {
            Refuse(line_number_,
                   fmt::format("column '{}': '{}' is not a number", Utf8(spec.header), Utf8(cell)));
          }
          if (spec.quantity == Quantity::kT) {
            if (value < previous_time) {
              Refuse(line_number_, fmt::format("column '{}': the time goes backwards ({} after {} s)",
                                               Utf8(spec.header), value, previous_time));
            }
            if (value == previous_time) ++time_ties;
            previous_time = value;
          }
          targets[static_cast<std::size_t>(k)]->push_back(value);
        }
        start = stop + 1;
        ++index;
      }
    }
    for (std::size_t i = 0; i < markers_seen; ++i) {
      const std::size_t m = marker_order[i];
      scan.read.invalid_markers.emplace_back(kMarkerNames[m], marker_counts[m]);
    }
    if (markers_seen > 0) {
      std::string counts;
      for (const auto& [kind, count] : scan.read.invalid_markers)
        counts += fmt::format("{}{} {}", counts.empty() ? "" : ", ", kind, count);
      scan.metadata.notes.push_back(fmt::format("invalid samples by marker: {}", counts));
    }
    for (const ColumnSpec& c : columns_) {
      scan.read.columns.push_back({kQuantityNames[static_cast<std::size_t>(c.quantity)], Utf8(c.header),
                                   c.clock_time ? "hh:mm:ss" : c.unit});
    }
    if (!scan.t_s.empty()) {
      // Times count from the first sample (formats.md 1); an epoch time would otherwise spend the
      // double's digits on the date.
      const double t0 = scan.t_s.front();
      for (double& t : scan.t_s) t -= t0;
      if (time_ties > 0) {
        const auto t_column = std::find_if(columns_.begin(), columns_.end(),
                                           [](const ColumnSpec& c) { return c.quantity == Quantity::kT; });
        scan.metadata.notes.push_back(fmt::format(
            "column '{}' repeats a time {} times (it resolves less than the sampling): not used; the times "
            "are the sample period's",
            Utf8(t_column->header), time_ties));
        scan.t_s.clear();
        scan.t_s.shrink_to_fit();
        scan.read.columns.erase(
            std::remove_if(scan.read.columns.begin(), scan.read.columns.end(),
                           [](const ScanReadRecord::Column& c) { return c.quantity == "t"; }),
            scan.read.columns.end());
      }
    }
  }

  std::string path_;
  std::string text_;
  ScanFormat format_;
  const ReadOptions& options_;
  std::string stage_;
  std::size_t position_ = 0;
  std::size_t line_number_ = 0;
  char separator_ = ';';
  std::vector<std::string> header_cells_;
  std::size_t header_line_ = 0;
  std::vector<ColumnSpec> columns_;
  std::string unused_keys_;
};

}  // namespace

std::string ReadWholeFile(const std::filesystem::path& path, const std::string& stage) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, stage, "cannot open '" + path.string() + "'");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::kIo, stage, "cannot read '" + path.string() + "'");
  return std::move(buffer).str();
}

std::vector<std::string> ColumnsOptionProblems(std::string_view columns) {
  std::vector<std::string> problems;
  if (!columns.empty()) (void)ParseColumnsOption(columns, &problems);
  return problems;
}

Scan ParseSensorScan(std::string text, const std::string& name, ScanFormat format,
                     const ReadOptions& options) {
  ARCWHEEL_CHECK(format == ScanFormat::kSensorTool || format == ScanFormat::kKeyenceLk ||
                 format == ScanFormat::kColumns);
  SensorParser parser(name, std::move(text), format, options);
  Scan scan = parser.Parse();
  ApplyInvalidMarkers(scan, SentinelComparison::kAsDouble);
  FinishScan(scan, options);
  return scan;
}

Scan ReadSensorScan(const std::filesystem::path& path, ScanFormat format, const ReadOptions& options) {
  const std::string stage = std::string("acquisition.") + std::string(InfoOf(format).name);
  return ParseSensorScan(ReadWholeFile(path, stage), path.string(), format, options);
}

}  // namespace arcwheel::acquisition
