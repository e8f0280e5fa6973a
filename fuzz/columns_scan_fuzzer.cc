// libFuzzer target: the reader of any delimited file through a column map (formats.md 2.4,
// `--columns`). The input's first line is the column map, the rest the file, so that both the
// option's parser and the reader are fuzzed. Any input must either give a Scan that passed
// ValidateScan or throw arcwheel::Error; anything else is a bug.

#include <cstddef>
#include <cstdint>
#include <string>

#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"
#include "core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const arcwheel::acquisition::ScanSettingsFile settings = arcwheel::acquisition::ParseScanSettings(
      R"({"spindle_rpm": 500, "feed_mm_per_min": 400, "sample_period_s": 0.0001, "encoder_counts_per_rev": 4096})",
      "settings.json");
  const std::string input(reinterpret_cast<const char*>(data), size);
  const std::size_t newline = input.find('\n');
  if (newline == std::string::npos) return 0;
  arcwheel::acquisition::ReadOptions options;
  options.settings = &settings;
  options.columns = input.substr(0, newline);
  if (options.columns.empty()) return 0;
  try {
    const arcwheel::acquisition::Scan scan = arcwheel::acquisition::ParseSensorScan(
        input.substr(newline + 1), "fuzz.txt", arcwheel::acquisition::ScanFormat::kColumns, options);
    if (scan.z_mm.empty()) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
