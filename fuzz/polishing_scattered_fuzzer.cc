// libFuzzer target: scattered x,y,z error points (CSV) and their Delaunay interpolation onto a
// grid (polishing/error_map_io.h). Any input must give a map whose node array matches its grid,
// or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "polishing/error_map_io.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto points =
        arcwheel::polishing::ReadScatteredCsv(arcwheel::fuzz::WriteInput(data, size, "points.csv"));
    const auto map = arcwheel::polishing::InterpolateScattered(points, 0.0, "points.csv");
    if (map.grid.nx <= 0 || map.grid.ny <= 0 || map.error_um.size() != map.grid.Nodes()) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
