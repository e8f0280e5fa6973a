// libFuzzer target: the Zygo Mx .datx reader (HDF5; polishing/error_map_io.h) as the command line
// runs it, from a file: read first in a child process (core/hdf5.h), so that a crash or hang inside
// libhdf5 1.10.8 itself becomes a refusal. Any input must give a pixel map whose heights match its
// size, or throw arcwheel::Error. (Library faults in the child are not what this target looks
// for; run the in-memory variant below by hand, ARCWHEEL_FUZZ_DATX_IN_MEMORY=1, to see them.)

#include <cstddef>
#include <cstdint>
#include <cstdlib>

#include "core/error.h"
#include "core/hdf5.h"
#include "fuzz/fuzz_input.h"
#include "polishing/error_map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool in_memory = std::getenv("ARCWHEEL_FUZZ_DATX_IN_MEMORY") != nullptr;
  try {
    const auto map =
        in_memory
            ? arcwheel::polishing::ReadZygoDatx(arcwheel::hdf5::File::OpenImage(data, size, "fuzz.datx"))
            : arcwheel::polishing::ReadZygoDatx(arcwheel::fuzz::WriteInput(data, size, "fuzz.datx"));
    if (map.width <= 0 || map.height <= 0 ||
        map.height_um.size() != static_cast<size_t>(map.width) * static_cast<size_t>(map.height)) {
      __builtin_trap();
    }
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
