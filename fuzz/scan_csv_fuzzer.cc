// libFuzzer target: the CSV scan reader (formats.md 2.2). Any input must either give a Scan that
// passed ValidateScan or throw arcwheel::Error; anything else (a crash, another exception, a
// sanitizer report, a hang) is a bug.

#include <cstddef>
#include <cstdint>
#include <string>

#include "acquisition/scan_reader.h"
#include "core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const arcwheel::acquisition::Scan scan = arcwheel::acquisition::ParseCsvScan(
        std::string(reinterpret_cast<const char*>(data), size), "fuzz.csv");
    if (scan.z_mm.empty()) __builtin_trap();  // ValidateScan refuses empty scans
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
