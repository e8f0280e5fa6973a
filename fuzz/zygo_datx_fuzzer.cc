// libFuzzer target: the Zygo Mx .datx reader (HDF5; polishing/error_map_io.h) on in-memory file
// images. Any input must give a pixel map whose heights match its size, or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/hdf5.h"
#include "polishing/error_map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto file = arcwheel::hdf5::File::OpenImage(data, size, "fuzz.datx");
    const auto map = arcwheel::polishing::ReadZygoDatx(file);
    if (map.width <= 0 || map.height <= 0 ||
        map.height_um.size() != static_cast<size_t>(map.width) * static_cast<size_t>(map.height)) {
      __builtin_trap();
    }
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
