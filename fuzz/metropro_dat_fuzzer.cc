// libFuzzer target: the Zygo MetroPro .dat reader (polishing/error_map_io.h). Any input must give
// a pixel map whose heights match its size, or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <span>

#include "core/error.h"
#include "polishing/error_map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto map =
        arcwheel::polishing::ParseMetroProDat(std::span<const unsigned char>(data, size), "fuzz.dat");
    if (map.width <= 0 || map.height <= 0 ||
        map.height_um.size() != static_cast<size_t>(map.width) * static_cast<size_t>(map.height)) {
      __builtin_trap();
    }
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
