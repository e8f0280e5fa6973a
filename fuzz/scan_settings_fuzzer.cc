// libFuzzer target: the scan settings file (formats.md 2.4, `--scan-settings`). Any input must
// either give settings or throw arcwheel::Error; anything else is a bug.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "acquisition/scan_settings.h"
#include "core/error.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::acquisition::ParseScanSettings(
        std::string_view(reinterpret_cast<const char*>(data), size), "settings.json");
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
