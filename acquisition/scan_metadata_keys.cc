#include "acquisition/scan_metadata_keys.h"

#include <charconv>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace arcwheel::acquisition {
namespace {

double ParseValue(const std::string& key, const std::string& value) {
  std::string_view text(value);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double number = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (error != std::errc() || end != text.data() + text.size()) {
    throw Error(ErrorCode::kBadInput, "acquisition", "metadata '" + key + "' is not a number: '" + value + "'");
  }
  return number;
}

}  // namespace

bool SetNumericMetadata(ScanMetadata& m, const std::string& key, double value) {
  if (key == "spindle_rpm") m.spindle_rpm = value;
  else if (key == "feed_mm_per_min") m.feed_mm_per_min = value;
  else if (key == "sample_period_s") m.sample_period_s = value;
  else if (key == "radius_sign") m.radius_sign = value;
  else if (key == "start_y_mm") m.start_y_mm = value;
  else if (key == "start_phase_deg") m.start_phase_deg = value;
  else if (key == "invalid_value") m.invalid_value = value;
  else if (key == "range_min_mm") m.range_min_mm = value;
  else if (key == "range_max_mm") m.range_max_mm = value;
  else if (key == "wheel_diameter_mm") m.wheel_diameter_mm = value;
  else if (key == "wheel_width_mm") m.wheel_width_mm = value;
  else return false;
  return true;
}

void SetMetadata(ScanMetadata& m, const std::string& key, const std::string& value) {
  if (key == "wheel_id") m.wheel_id = value;
  else if (key == "sensor") m.sensor = value;
  else if (key == "operator") m.operator_name = value;
  else if (key == "timestamp") m.timestamp = value;
  else if (IsNumericMetadataKey(key)) SetNumericMetadata(m, key, ParseValue(key, value));
}

bool IsNumericMetadataKey(const std::string& key) {
  ScanMetadata probe;
  return SetNumericMetadata(probe, key, 0.0);
}

void ApplyInvalidMarkers(Scan& scan, bool compare_as_float) {
  const ScanMetadata& m = scan.metadata;
  const double low = m.range_min_mm.value_or(-std::numeric_limits<double>::infinity());
  const double high = m.range_max_mm.value_or(std::numeric_limits<double>::infinity());
  const bool has_sentinel = m.invalid_value.has_value();
  const double sentinel = m.invalid_value.value_or(0.0);
  const float sentinel_float = static_cast<float>(sentinel);
  for (double& z : scan.z_mm) {
    const bool is_sentinel = has_sentinel && (compare_as_float ? static_cast<float>(z) == sentinel_float : z == sentinel);
    // +-Inf is a float sensor's over-range reading: an invalid sample, like NaN.
    if (is_sentinel || !std::isfinite(z) || !(z >= low && z <= high)) z = std::numeric_limits<double>::quiet_NaN();
  }
}

}  // namespace arcwheel::acquisition
