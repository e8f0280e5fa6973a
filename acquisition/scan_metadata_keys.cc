#include "acquisition/scan_metadata_keys.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <iterator>
#include <limits>
#include <type_traits>

#include "acquisition/scan_settings.h"
#include "core/error.h"
#include "core/nan.h"
#include "core/parallel.h"
#include "core/text_encoding.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kScanMetadataKeysStage = "acquisition";

double ParseValue(const std::string& key, std::string_view text) {
  const std::string_view written = text;
  while (!text.empty() && (text.front() == ' ' || text.front() == '\t')) text.remove_prefix(1);
  while (!text.empty() && (text.back() == ' ' || text.back() == '\t')) text.remove_suffix(1);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double number = 0.0;
  const auto [end, error] = std::from_chars(text.data(), text.data() + text.size(), number);
  if (text.empty() || error != std::errc() || end != text.data() + text.size()) {
    bool latin1 = false;
    throw Error(ErrorCode::kBadInput, kScanMetadataKeysStage,
                "metadata '" + key + "' is not a number: '" + AsUtf8(written, latin1) + "'");
  }
  return number;
}

bool IsOneOf(const std::string& name, const auto& keys) {
  return std::find_if(std::begin(keys), std::end(keys), [&](const char* k) { return name == k; }) !=
         std::end(keys);
}

}  // namespace

std::string MetadataSetter::Claim(std::string_view key) {
  std::string name = AsciiLower(key);
  if (!IsOneOf(name, kNumericMetadataKeys) && !IsOneOf(name, kTextMetadataKeys)) {
    bool latin1 = false;
    metadata_.notes.push_back("metadata key '" + AsUtf8(key, latin1) +
                              "' is not one arcwheel reads (formats.md 2.1): ignored");
    return {};
  }
  if (!claimed_.insert(name).second) {
    throw Error(ErrorCode::kBadInput, kScanMetadataKeysStage,
                "metadata '" + name + "' is given twice (keys match case-insensitively)");
  }
  metadata_.file_keys.push_back(name);
  return name;
}

bool MetadataSetter::IsNumeric(const std::string& name) { return IsOneOf(name, kNumericMetadataKeys); }

void MetadataSetter::SetNumber(const std::string& name, double value) {
  ScanMetadata& m = metadata_;
  if (name == "spindle_rpm")
    m.spindle_rpm = value;
  else if (name == "feed_mm_per_min")
    m.feed_mm_per_min = value;
  else if (name == "sample_period_s")
    m.sample_period_s = value;
  else if (name == "radius_sign")
    m.radius_sign = value;
  else if (name == "start_y_mm")
    m.start_y_mm = value;
  else if (name == "start_phase_deg")
    m.start_phase_deg = value;
  else if (name == "invalid_value")
    m.invalid_value = value;
  else if (name == "range_min_mm")
    m.range_min_mm = value;
  else if (name == "range_max_mm")
    m.range_max_mm = value;
  else if (name == "wheel_diameter_mm")
    m.wheel_diameter_mm = value;
  else if (name == "wheel_width_mm")
    m.wheel_width_mm = value;
  else
    throw Error(ErrorCode::kInternal, kScanMetadataKeysStage, "metadata '" + name + "' is not numeric");
}

void MetadataSetter::SetText(const std::string& name, std::string_view value) {
  if (IsNumeric(name)) return SetNumber(name, ParseValue(name, value));
  bool latin1 = false;
  std::string text = AsUtf8(value, latin1);
  if (latin1) metadata_.notes.push_back("metadata '" + name + "' is not valid UTF-8: read as Latin-1");
  ScanMetadata& m = metadata_;
  if (name == "wheel_id")
    m.wheel_id = std::move(text);
  else if (name == "sensor")
    m.sensor = std::move(text);
  else if (name == "operator")
    m.operator_name = std::move(text);
  else if (name == "timestamp")
    m.timestamp = std::move(text);
  else
    throw Error(ErrorCode::kInternal, kScanMetadataKeysStage, "metadata '" + name + "' is not text");
}

namespace {

// Below this many readings the pass is too short to share.
constexpr std::size_t kParallelFrom = std::size_t{1} << 22;

// The least T at or above `bound` and the greatest T at or below it: for every T value z,
// double(z) >= bound exactly when z >= AtLeast<T>(bound), and double(z) <= bound exactly when
// z <= AtMost<T>(bound) (NaN stays NaN, and compares false either way). A float sensor's readings
// are thus compared with a range given in double without widening each of them.
template <typename T>
T AtLeast(double bound) {
  const T rounded = static_cast<T>(bound);
  return static_cast<double>(rounded) < bound ? std::nextafter(rounded, std::numeric_limits<T>::infinity())
                                              : rounded;
}
template <typename T>
T AtMost(double bound) {
  const T rounded = static_cast<T>(bound);
  return static_cast<double>(rounded) > bound ? std::nextafter(rounded, -std::numeric_limits<T>::infinity())
                                              : rounded;
}

// Replaces with NaN every reading that `is_sentinel` matches, that is not finite, or that lies
// outside [low, high] (the readings' values against the range's, compared exactly, in the
// readings' own type: AtLeast, AtMost). Written without branches inside a block so that the
// compiler vectorizes it: this pass touches every sample of the scan. A block is written only when
// it holds an invalid reading that is not NaN already: readings mapped from the file
// (hdf5::SharedArrays) are copied page by page as they are written, and a scan's invalid readings
// are mostly the NaN its sensor wrote off the rim.
template <typename T, typename IsSentinel>
void MarkInvalid(std::span<T> readings, double low, double high, IsSentinel is_sentinel) {
  constexpr T kNaN = std::numeric_limits<T>::quiet_NaN();
  const T least = AtLeast<T>(low);
  const T greatest = AtMost<T>(high);
  const auto valid = [&](T z) {
    const bool finite = FiniteWithoutBranch(z);  // false for a float sensor's over-range +-Inf too
    const bool sentinel = is_sentinel(z);
    return !sentinel & finite & (z >= least) & (z <= greatest);
  };
  constexpr std::size_t kBlock = 1024;
  const auto mark = [&](std::size_t first_block, std::size_t end_block) {
    for (std::size_t b = first_block; b < end_block; ++b) {
      const std::size_t start = b * kBlock;
      const std::span<T> block = readings.subspan(start, std::min(kBlock, readings.size() - start));
      unsigned to_mark = 0;
      for (const T z : block) to_mark |= static_cast<unsigned>(!valid(z) & (z == z));
      if (to_mark == 0) continue;
      for (T& z : block) z = valid(z) ? z : kNaN;
    }
  };
  // A large scan's first pass over its pages (the file's, mapped) is the reading's largest part:
  // the two halves on both cores.
  const std::size_t blocks = (readings.size() + kBlock - 1) / kBlock;
  if (readings.size() < kParallelFrom) return mark(0, blocks);
  RunOnWorkers(2, [&](int worker) {
    mark(blocks * static_cast<std::size_t>(worker) / 2, blocks * static_cast<std::size_t>(worker + 1) / 2);
  });
}

}  // namespace

void ApplyInvalidMarkers(Scan& scan, SentinelComparison comparison) {
  const ScanMetadata& m = scan.metadata;
  const double low = m.range_min_mm.value_or(-std::numeric_limits<double>::infinity());
  const double high = m.range_max_mm.value_or(std::numeric_limits<double>::infinity());
  const bool has_sentinel = m.invalid_value.has_value() && comparison != SentinelComparison::kDone;
  const double sentinel = m.invalid_value.value_or(0.0);
  VisitReadings(scan, [&](auto& column) {
    const std::span readings(column);
    if (!has_sentinel) {
      MarkInvalid(readings, low, high, [](auto) { return false; });
    } else if (comparison == SentinelComparison::kAsFloat) {
      const float sentinel_float = static_cast<float>(sentinel);
      MarkInvalid(readings, low, high, [=](auto z) { return static_cast<float>(z) == sentinel_float; });
    } else {
      MarkInvalid(readings, low, high, [=](auto z) { return static_cast<double>(z) == sentinel; });
    }
  });
}

void FinishScan(Scan& scan, const ReadOptions& options) {
  ApplyScanSettings(options.settings, scan);
  ValidateScan(scan);
}

}  // namespace arcwheel::acquisition
