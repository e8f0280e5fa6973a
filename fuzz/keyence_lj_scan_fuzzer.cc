// libFuzzer target: the keyence-lj line-profile reader (docs/inputs.md, "Line-profile scans"). Any input
// must either give a ProfileScan that passed ValidateProfileScan or throw arcwheel::Error; anything
// else (a crash, another exception, a sanitizer report, a hang) is a bug. The settings the layout
// lacks come from a fixed settings file, so that inputs reach the frames and the checks after them.

#include <cstddef>
#include <cstdint>
#include <string>

#include "acquisition/profile_scan.h"
#include "acquisition/scan_settings.h"
#include "core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const arcwheel::acquisition::ScanSettingsFile settings = arcwheel::acquisition::ParseScanSettings(
      R"({"spindle_rpm": 500, "sample_period_s": 0.001, "encoder_counts_per_rev": 40})", "settings.json");
  try {
    const arcwheel::acquisition::ProfileScan scan = arcwheel::acquisition::ParseProfileScan(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv",
        arcwheel::acquisition::ScanFormat::kKeyenceLj, &settings);
    if (scan.frames() == 0) __builtin_trap();  // ValidateProfileScan refuses a scan without frames
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
