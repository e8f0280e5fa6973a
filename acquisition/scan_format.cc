#include "acquisition/scan_format.h"

#include <fmt/core.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <fstream>
#include <vector>

#include "core/check.h"
#include "core/error.h"

namespace arcwheel::acquisition {
namespace {

constexpr std::array<std::string_view, 2> kHdf5Extensions = {".h5", ".hdf5"};
constexpr std::array<std::string_view, 2> kTextExtensions = {".csv", ".txt"};

std::string AsciiLowerCopy(std::string_view text) {
  std::string lower(text);
  std::transform(lower.begin(), lower.end(), lower.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return lower;
}

// The head's first lines, without line ends; at most `count`.
std::vector<std::string_view> HeadLines(std::string_view head, std::size_t count = 40) {
  std::vector<std::string_view> lines;
  while (!head.empty() && lines.size() < count) {
    const std::size_t end = head.find('\n');
    std::string_view line = head.substr(0, end);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back(line);
    if (end == std::string_view::npos) break;
    head.remove_prefix(end + 1);
  }
  return lines;
}

std::string_view TrimBlanks(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// formats.md 2.2: `#` metadata lines, or a header row naming z_mm.
bool SniffCsv(std::string_view head) {
  for (const std::string_view line : HeadLines(head)) {
    const std::string_view trimmed = TrimBlanks(line);
    if (trimmed.empty()) continue;
    if (trimmed.starts_with('#') || trimmed.starts_with("\"#")) return true;
    return AsciiLowerCopy(trimmed).find("z_mm") != std::string::npos;
  }
  return false;
}

// sensorTOOL's first header line names the program; its column row starts with the time columns.
bool SniffSensorTool(std::string_view head) {
  for (const std::string_view line : HeadLines(head)) {
    const std::string lower = AsciiLowerCopy(TrimBlanks(line));
    if (lower.starts_with("sensortool") || lower.starts_with("acquisition time") ||
        lower.starts_with("epoch time")) {
      return true;
    }
  }
  return false;
}

// A Keyence LK-Navigator export names the program; a raw value stream starts with a value.
bool SniffKeyenceLk(std::string_view head) {
  const std::vector<std::string_view> lines = HeadLines(head);
  for (const std::string_view line : lines) {
    if (AsciiLowerCopy(line).find("lk-navigator") != std::string::npos) return true;
  }
  for (const std::string_view line : lines) {
    const std::string_view trimmed = TrimBlanks(line);
    if (trimmed.empty()) continue;
    return IsKeyenceLkValue(trimmed.substr(0, trimmed.find_first_of(",;\t")));
  }
  return false;
}

constexpr std::array<ScanFormatInfo, 5> kFormats = {{
    {ScanFormat::kHdf5, "hdf5", kHdf5Extensions, nullptr, ""},
    {ScanFormat::kCsv, "csv", kTextExtensions, SniffCsv, "'# key: value' lines or a z_mm column"},
    {ScanFormat::kSensorTool, "sensortool", kTextExtensions, SniffSensorTool,
     "a 'sensorTOOL' line or a column row starting 'Acquisition time' or 'Epoch time (ms)'"},
    {ScanFormat::kKeyenceLk, "keyence-lk", kTextExtensions, SniffKeyenceLk,
     "an 'LK-Navigator' line or fixed-width values such as +01.2345 or -FFFFFFF"},
    {ScanFormat::kColumns, "columns", kTextExtensions, nullptr, ""},
}};

std::string LowerExtension(const std::filesystem::path& path) {
  return AsciiLowerCopy(path.extension().string());
}

std::string NamesText() {
  std::string text;
  for (std::size_t i = 0; i < kFormats.size(); ++i) {
    if (i > 0) text += i + 1 == kFormats.size() ? " or " : ", ";
    text += kFormats[i].name;
  }
  return text;
}

}  // namespace

std::span<const ScanFormatInfo> ScanFormats() { return kFormats; }

const ScanFormatInfo& InfoOf(ScanFormat format) {
  const auto* info = std::find_if(kFormats.begin(), kFormats.end(),
                                  [&](const ScanFormatInfo& f) { return f.format == format; });
  ARCWHEEL_CHECK(info != kFormats.end());
  return *info;
}

std::optional<ScanFormat> ScanFormatOfName(const std::filesystem::path& path) {
  const std::string extension = LowerExtension(path);
  for (const ScanFormatInfo& info : kFormats) {
    if (std::find(info.extensions.begin(), info.extensions.end(), extension) != info.extensions.end()) {
      return info.format;
    }
  }
  return std::nullopt;
}

ScanFormat ScanFormatOfFile(const std::filesystem::path& path, std::string_view stage) {
  if (const std::optional<ScanFormat> format = ScanFormatOfName(path)) return *format;
  throw Error(ErrorCode::kBadInput, stage,
              "'" + path.string() + "': unknown scan file type '" + path.extension().string() +
                  "' (expected " + ScanExtensionsText() + ")");
}

std::string ScanExtensionsText() {
  std::vector<std::string_view> all;
  // The sensors' layouts share the contract CSV's extensions: each extension once.
  for (const ScanFormatInfo& info : kFormats) {
    for (const std::string_view extension : info.extensions) {
      if (std::find(all.begin(), all.end(), extension) == all.end()) all.push_back(extension);
    }
  }
  std::string text;
  for (size_t i = 0; i < all.size(); ++i) {
    if (i > 0) text += i + 1 == all.size() ? " or " : ", ";
    text += all[i];
  }
  return text;
}

bool IsKeyenceLkValue(std::string_view cell) {
  // Sign and 7 characters: digits with at most one decimal point, or FFFFFFF (out of range);
  // XXXXXXXX (alarm); ------- (waiting for a value).
  if (cell.size() == 8 && std::all_of(cell.begin(), cell.end(), [](char c) { return c == 'X'; })) return true;
  if ((cell.size() == 7 || cell.size() == 8) &&
      std::all_of(cell.begin(), cell.end(), [](char c) { return c == '-'; })) {
    return true;
  }
  if (cell.size() != 8 || (cell[0] != '+' && cell[0] != '-')) return false;
  const std::string_view rest = cell.substr(1);
  if (rest == "FFFFFFF") return true;
  if (std::count(rest.begin(), rest.end(), '.') > 1) return false;
  return std::all_of(rest.begin(), rest.end(), [](char c) { return c == '.' || (c >= '0' && c <= '9'); }) &&
         std::any_of(rest.begin(), rest.end(), [](char c) { return c >= '0' && c <= '9'; });
}

ScanFormat ScanFormatNamed(std::string_view name, std::string_view stage) {
  for (const ScanFormatInfo& info : kFormats) {
    if (info.name == name) return info.format;
  }
  throw Error(ErrorCode::kInvalidOption, stage, fmt::format("--format = {} violates {}", name, NamesText()));
}

std::optional<ScanFormat> SniffScanFormat(std::string_view head) {
  if (head.starts_with("\xEF\xBB\xBF")) head.remove_prefix(3);
  for (const ScanFormatInfo& info : kFormats) {
    if (info.sniff != nullptr && info.sniff(head)) return info.format;
  }
  return std::nullopt;
}

ScanFormat ScanFormatOfContent(const std::filesystem::path& path, std::string_view forced,
                               bool has_column_map, std::string_view stage) {
  if (!forced.empty()) return ScanFormatNamed(forced, stage);
  if (has_column_map) return ScanFormat::kColumns;
  const ScanFormat by_name = ScanFormatOfFile(path, stage);
  const ScanFormatInfo& info = InfoOf(by_name);
  if (info.sniff == nullptr) return by_name;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, stage, "cannot open '" + path.string() + "'");
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<std::size_t>(in.gcount()));
  // An empty file is the contract CSV reader's to refuse ("no header row").
  if (head.find_first_not_of(" \t\r\n") == std::string::npos) return by_name;
  if (const std::optional<ScanFormat> sniffed = SniffScanFormat(head)) return *sniffed;
  std::string tried;
  for (const ScanFormatInfo& candidate : kFormats) {
    if (candidate.sniff == nullptr) continue;
    tried += fmt::format("{}{} ({})", tried.empty() ? "" : "; ", candidate.name, candidate.sniff_text);
  }
  throw Error(ErrorCode::kBadInput, stage,
              fmt::format("'{}': its header is no format arcwheel knows; tried {}. Force a reader with "
                          "--format NAME ({}), or read any delimited file with --columns z=NAME:UNIT,...",
                          path.string(), tried, NamesText()));
}

}  // namespace arcwheel::acquisition
