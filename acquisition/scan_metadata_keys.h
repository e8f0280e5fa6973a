#pragma once
// Shared by the readers: metadata keys by name, and folding invalid markers into NaN.

#include <filesystem>
#include <set>
#include <string>
#include <string_view>

#include "acquisition/scan.h"
#include "acquisition/scan_reader.h"

namespace arcwheel::acquisition {

// The numeric keys, in formats.md order.
inline constexpr const char* kNumericMetadataKeys[] = {
    "spindle_rpm",  "feed_mm_per_min",   "sample_period_s", "radius_sign",
    "start_y_mm",   "start_phase_deg",   "invalid_value",   "range_min_mm",
    "range_max_mm", "wheel_diameter_mm", "wheel_width_mm"};
inline constexpr const char* kTextMetadataKeys[] = {"wheel_id", "sensor", "operator", "timestamp"};

// Fills a ScanMetadata from a file's keys as written. Keys match formats.md 2.1 case-insensitively
// (`Radius_Sign` is radius_sign): a key that matched nothing would change the result unseen (a
// mirrored wheel, for `Radius_Sign`), so every key that is not used lands in metadata.notes, and a
// key given twice is refused. Text values are kept as valid UTF-8 (Latin-1 where they are not
// UTF-8, with a note). Errors are Error{kBadInput} naming the key but not the file: the reader adds
// where it was.
class MetadataSetter {
 public:
  explicit MetadataSetter(ScanMetadata& metadata) : metadata_(metadata) {}

  // formats.md's name for `key` (lower case); empty, and a note made, if arcwheel does not use it.
  [[nodiscard]] std::string Claim(std::string_view key);
  [[nodiscard]] static bool IsNumeric(const std::string& name);
  void SetNumber(const std::string& name, double value);
  // A numeric key's value parses as a number; a text key's is kept (as UTF-8).
  void SetText(const std::string& name, std::string_view value);

 private:
  ScanMetadata& metadata_;
  std::set<std::string> claimed_;
};

// How ApplyInvalidMarkers compares z with metadata.invalid_value.
enum class SentinelComparison {
  kAsDouble,  // z as read
  kAsFloat,   // z stored as float32: compared as float, so that a float32 sentinel matches exactly
  kDone,      // the reader already compared the stored values (integer counts before scaling)
};

// Marks as NaN every z equal to metadata.invalid_value (see SentinelComparison), not finite, or
// outside the range limits.
void ApplyInvalidMarkers(Scan& scan, SentinelComparison comparison);

// The readers' last step: merges the settings from outside the file (options.settings,
// scan_settings.h), then ValidateScan.
void FinishScan(Scan& scan, const ReadOptions& options);

// The whole file as text, for the readers of text layouts; Error{kIo, stage} naming it when it
// cannot be read.
[[nodiscard]] std::string ReadWholeFile(const std::filesystem::path& path, const std::string& stage);

}  // namespace arcwheel::acquisition
