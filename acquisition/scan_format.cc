#include "acquisition/scan_format.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <vector>

#include "core/check.h"
#include "core/error.h"

namespace arcwheel::acquisition {
namespace {

constexpr std::array<std::string_view, 2> kHdf5Extensions = {".h5", ".hdf5"};
constexpr std::array<std::string_view, 2> kCsvExtensions = {".csv", ".txt"};

constexpr std::array<ScanFormatInfo, 2> kFormats = {{
    {ScanFormat::kHdf5, "hdf5", kHdf5Extensions},
    {ScanFormat::kCsv, "csv", kCsvExtensions},
}};

std::string LowerExtension(const std::filesystem::path& path) {
  std::string extension = path.extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return extension;
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
  for (const ScanFormatInfo& info : kFormats)
    all.insert(all.end(), info.extensions.begin(), info.extensions.end());
  std::string text;
  for (size_t i = 0; i < all.size(); ++i) {
    if (i > 0) text += i + 1 == all.size() ? " or " : ", ";
    text += all[i];
  }
  return text;
}

}  // namespace arcwheel::acquisition
