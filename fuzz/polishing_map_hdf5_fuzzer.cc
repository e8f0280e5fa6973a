// libFuzzer target: arcwheel's own HDF5 error-map grid (polishing/error_map_io.h) on in-memory
// file images. Any input must give a map whose node array matches its grid, or throw
// arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "core/hdf5.h"
#include "polishing/error_map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto file = arcwheel::hdf5::File::OpenImage(data, size, "fuzz_map.h5");
    const auto map = arcwheel::polishing::ReadErrorMapHdf5(file);
    if (map.grid.nx <= 0 || map.grid.ny <= 0 || map.error_um.size() != map.grid.Nodes()) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
