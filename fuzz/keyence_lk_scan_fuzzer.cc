// libFuzzer target: the keyence-lk scan reader (formats.md 2.4, docs/inputs.md). Any input must either
// give a Scan that passed ValidateScan or throw arcwheel::Error; anything else (a crash, another
// exception, a sanitizer report, a hang) is a bug. The settings that the sensor's file lacks come
// from a fixed settings file, so that inputs reach the rows and the checks after them.

#include <cstddef>
#include <cstdint>
#include <string>

#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"
#include "core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const arcwheel::acquisition::ScanSettingsFile settings = arcwheel::acquisition::ParseScanSettings(
      R"({"spindle_rpm": 500, "feed_mm_per_min": 400, "sample_period_s": 0.0001})", "settings.json");
  arcwheel::acquisition::ReadOptions options;
  options.settings = &settings;
  try {
    const arcwheel::acquisition::Scan scan = arcwheel::acquisition::ParseSensorScan(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv",
        arcwheel::acquisition::ScanFormat::kKeyenceLk, options);
    if (scan.z_mm.empty()) __builtin_trap();  // ValidateScan refuses empty scans
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
