#pragma once
// Shared by the readers: metadata keys by name, and folding invalid markers into NaN.

#include <string>

#include "acquisition/scan.h"

namespace arcwheel::acquisition {

// Sets the field named `key` (formats.md 2.1 attribute names) from its text. Unknown keys are
// ignored (files carry other notes); a known numeric key whose value does not parse throws
// Error{kBadInput} naming the key.
void SetMetadata(ScanMetadata& metadata, const std::string& key, const std::string& value);
// Sets a numeric field by name; false (and nothing set) if `key` is not a numeric key.
bool SetNumericMetadata(ScanMetadata& metadata, const std::string& key, double value);
[[nodiscard]] bool IsNumericMetadataKey(const std::string& key);

// The numeric keys, in formats.md order.
inline constexpr const char* kNumericMetadataKeys[] = {
    "spindle_rpm", "feed_mm_per_min", "sample_period_s", "radius_sign", "start_y_mm", "start_phase_deg",
    "invalid_value", "range_min_mm", "range_max_mm", "wheel_diameter_mm", "wheel_width_mm"};
inline constexpr const char* kTextMetadataKeys[] = {"wheel_id", "sensor", "operator", "timestamp"};

// Marks as NaN every z equal to metadata.invalid_value (compared as float when the file stores
// float32, so that a float32 sentinel matches exactly) or outside the range limits.
void ApplyInvalidMarkers(Scan& scan, bool compare_as_float);

}  // namespace arcwheel::acquisition
