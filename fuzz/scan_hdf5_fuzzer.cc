// libFuzzer target: the HDF5 scan reader (formats.md 2.1) on in-memory file images. Any input
// must give a validated Scan or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "acquisition/scan_reader.h"
#include "core/error.h"
#include "core/hdf5.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto file = arcwheel::hdf5::File::OpenImage(data, size, "fuzz.h5");
    const arcwheel::acquisition::Scan scan = arcwheel::acquisition::ReadHdf5Scan(file);
    if (scan.z_mm.empty()) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
