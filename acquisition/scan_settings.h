#pragma once
// formats.md 2.4: a scan's settings from outside its file (`process --scan-settings SETTINGS.json`).
// A sensor's own export carries the readings but rarely the spindle speed, the feed, the sample
// period or the start position; the settings file supplies them. It fills what the file does not
// give and never overrides what it does: a key the file also gives with another value is refused,
// naming both.
//
// SETTINGS.json is one JSON object whose keys are the attribute names of formats.md 2.1
// (`spindle_rpm`, `feed_mm_per_min`, `sample_period_s`, `radius_sign`, `start_y_mm`,
// `start_phase_deg`, `wheel_diameter_mm`, `wheel_width_mm`, `invalid_value`, `range_min_mm`,
// `range_max_mm`: numbers; `wheel_id`, `sensor`, `operator`, `timestamp`: text) and
// `encoder_counts_per_rev` (a number, for an angle column read in encoder counts):
//
//   {"spindle_rpm": 500, "feed_mm_per_min": 100, "start_y_mm": -11, "wheel_id": "W-0815"}

#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "acquisition/scan.h"

namespace arcwheel::acquisition {

struct ScanSettingsFile {
  std::string path;  // for messages and the record
  // The numeric and text keys as given, in formats.md order.
  std::vector<std::pair<std::string, double>> numbers;
  std::vector<std::pair<std::string, std::string>> texts;

  // The value of a numeric key, if the file gives it.
  [[nodiscard]] std::optional<double> Number(std::string_view key) const;
};

// Every key a settings file may hold, in formats.md order, for messages: "spindle_rpm, ...".
[[nodiscard]] std::string ScanSettingsKeysText();

// Reads SETTINGS.json. Throws Error{kIo} when it cannot be read, and Error{kInvalidOption,
// "acquisition.settings"} naming the file and every problem (not one JSON object, a key that is
// not a setting, a number that is not a finite number, a text that is not a string).
[[nodiscard]] ScanSettingsFile ReadScanSettings(const std::filesystem::path& path);
// The same from text in memory; `name` stands for the file in messages.
[[nodiscard]] ScanSettingsFile ParseScanSettings(std::string_view text, const std::string& name);

// Merges `settings` into scan.metadata: each key the file did not give (metadata.file_keys) is
// set; a key the file gave with another value (numbers compared to 1e-12 relative, texts exactly)
// throws Error{kInvalidOption, "acquisition.settings"} naming the key, both values and both files.
// Records in scan.read where each setting in effect came from ("file", "settings" or, for
// radius_sign, start_y_mm and start_phase_deg, "default"). `settings` may be null (no file).
void ApplyScanSettings(const ScanSettingsFile* settings, Scan& scan);

}  // namespace arcwheel::acquisition
