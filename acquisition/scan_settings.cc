#include "acquisition/scan_settings.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <sstream>

#include "acquisition/scan_metadata_keys.h"
#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kScanSettingsStage = "acquisition.settings";
// Beside formats.md 2.1's keys: the encoder's counts per turn, for an angle column in counts.
constexpr const char* kEncoderCountsPerRev = "encoder_counts_per_rev";
// A line-profile sensor's calibrated placement (profile_scan.h, ProfilePlacement).
constexpr const char* kProfileKeys[] = {"sensor_tilt_deg", "sensor_tilt_u_deg", "sensor_axial_offset_mm",
                                        "sensor_axial_offset_u_mm"};

bool IsOutsideMetadata(std::string_view key) {
  return key == kEncoderCountsPerRev ||
         std::find_if(std::begin(kProfileKeys), std::end(kProfileKeys),
                      [&](const char* k) { return key == k; }) != std::end(kProfileKeys);
}

bool IsNumericKey(std::string_view key) {
  return IsOutsideMetadata(key) ||
         std::find_if(std::begin(kNumericMetadataKeys), std::end(kNumericMetadataKeys),
                      [&](const char* k) { return key == k; }) != std::end(kNumericMetadataKeys);
}

bool IsTextKey(std::string_view key) {
  return std::find_if(std::begin(kTextMetadataKeys), std::end(kTextMetadataKeys),
                      [&](const char* k) { return key == k; }) != std::end(kTextMetadataKeys);
}

std::optional<double> NumberOf(const ScanMetadata& m, std::string_view key) {
  if (key == "spindle_rpm") return m.spindle_rpm;
  if (key == "feed_mm_per_min") return m.feed_mm_per_min;
  if (key == "sample_period_s") return m.sample_period_s;
  if (key == "radius_sign") return m.radius_sign;
  if (key == "start_y_mm") return m.start_y_mm;
  if (key == "start_phase_deg") return m.start_phase_deg;
  if (key == "invalid_value") return m.invalid_value;
  if (key == "range_min_mm") return m.range_min_mm;
  if (key == "range_max_mm") return m.range_max_mm;
  if (key == "wheel_diameter_mm") return m.wheel_diameter_mm;
  if (key == "wheel_width_mm") return m.wheel_width_mm;
  return std::nullopt;
}

const std::string& TextOf(const ScanMetadata& m, std::string_view key) {
  if (key == "wheel_id") return m.wheel_id;
  if (key == "sensor") return m.sensor;
  if (key == "operator") return m.operator_name;
  return m.timestamp;
}

std::string Shown(double value) { return fmt::format("{:.12g}", value); }

bool SameNumber(double a, double b) { return std::abs(a - b) <= 1e-12 * std::max(std::abs(a), std::abs(b)); }

}  // namespace

std::optional<double> ScanSettingsFile::Number(std::string_view key) const {
  for (const auto& [name, value] : numbers) {
    if (name == key) return value;
  }
  return std::nullopt;
}

std::string ScanSettingsKeysText() {
  std::string text;
  for (const char* key : kNumericMetadataKeys) text += std::string(text.empty() ? "" : ", ") + key;
  text += std::string(", ") + kEncoderCountsPerRev;
  for (const char* key : kProfileKeys) text += std::string(", ") + key;
  for (const char* key : kTextMetadataKeys) text += std::string(", ") + key;
  return text;
}

ScanSettingsFile ParseScanSettings(std::string_view text, const std::string& name) {
  ScanSettingsFile settings;
  settings.path = name;
  const nlohmann::json document = ParseJsonText(text, name, kScanSettingsStage, ErrorCode::kInvalidOption);
  if (!document.is_object()) {
    throw Error(
        ErrorCode::kInvalidOption, kScanSettingsStage,
        fmt::format("'{}' must hold one JSON object of settings, got {}", name, document.type_name()));
  }
  std::vector<std::string> problems;
  for (const auto& [key, value] : document.items()) {
    if (IsNumericKey(key)) {
      if (!value.is_number() || !std::isfinite(value.get<double>())) {
        problems.push_back(fmt::format("'{}' must be a number, got {}", key, JsonText(value)));
        continue;
      }
      settings.numbers.emplace_back(key, value.get<double>());
    } else if (IsTextKey(key)) {
      if (!value.is_string()) {
        problems.push_back(fmt::format("'{}' must be text, got {}", key, JsonText(value)));
        continue;
      }
      settings.texts.emplace_back(key, value.get<std::string>());
    } else {
      problems.push_back(
          fmt::format("'{}' is not a scan setting (expected {})", key, ScanSettingsKeysText()));
    }
  }
  if (!problems.empty()) {
    std::string joined;
    for (const std::string& problem : problems) joined += (joined.empty() ? "" : "; ") + problem;
    throw Error(ErrorCode::kInvalidOption, kScanSettingsStage, fmt::format("'{}': {}", name, joined));
  }
  return settings;
}

ScanSettingsFile ReadScanSettings(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, kScanSettingsStage, fmt::format("cannot open '{}'", path.string()));
  std::ostringstream buffer;
  buffer << in.rdbuf();
  return ParseScanSettings(buffer.str(), path.string());
}

void ApplyScanSettings(const ScanSettingsFile* settings, Scan& scan) {
  ScanMetadata& m = scan.metadata;
  const auto from_file = [&](std::string_view key) {
    return std::find(m.file_keys.begin(), m.file_keys.end(), key) != m.file_keys.end();
  };
  std::vector<std::pair<std::string, std::string>> sources;
  if (settings != nullptr) {
    scan.read.settings_path = settings->path;
    MetadataSetter setter(m);
    for (const auto& [key, value] : settings->numbers) {
      if (IsOutsideMetadata(key)) {
        sources.emplace_back(key, "settings");
        continue;
      }
      if (from_file(key)) {
        const double in_file = NumberOf(m, key).value_or(value);
        if (!SameNumber(in_file, value)) {
          throw Error(ErrorCode::kInvalidOption, kScanSettingsStage,
                      fmt::format("{} contradicts the scan: '{}' gives {} = {}, '{}' gives {} = {}", key,
                                  settings->path, key, Shown(value), scan.path, key, Shown(in_file)));
        }
        continue;  // the same value: the file's
      }
      setter.SetNumber(key, value);
      sources.emplace_back(key, "settings");
    }
    for (const auto& [key, value] : settings->texts) {
      if (from_file(key)) {
        const std::string& in_file = TextOf(m, key);
        if (in_file != value) {
          throw Error(ErrorCode::kInvalidOption, kScanSettingsStage,
                      fmt::format("{} contradicts the scan: '{}' gives {} = '{}', '{}' gives {} = '{}'", key,
                                  settings->path, key, value, scan.path, key, in_file));
        }
        continue;
      }
      setter.SetText(key, value);
      sources.emplace_back(key, "settings");
    }
  }
  // In formats.md order: what the file gave, what the settings gave, and the defaults in effect.
  scan.read.sources.clear();
  const auto record = [&](const std::string& key) {
    if (from_file(key)) {
      scan.read.sources.emplace_back(key, "file");
      return;
    }
    for (const auto& [name, source] : sources) {
      if (name == key) {
        scan.read.sources.emplace_back(key, source);
        return;
      }
    }
    if (key == "radius_sign" || key == "start_y_mm" || key == "start_phase_deg")
      scan.read.sources.emplace_back(key, "default");
  };
  for (const char* key : kNumericMetadataKeys) record(key);
  record(kEncoderCountsPerRev);
  for (const char* key : kProfileKeys) record(key);
  for (const char* key : kTextMetadataKeys) record(key);
}

}  // namespace arcwheel::acquisition
