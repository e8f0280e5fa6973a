// libFuzzer target: the error-map CSV grid reader of the polishing stage. Any input must give a
// map whose node array matches its grid, or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "polishing/job.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto map = arcwheel::polishing::ReadErrorMapCsv(arcwheel::fuzz::WriteInput(data, size, "map.csv"));
    if (map.grid.nx <= 0 || map.grid.ny <= 0 || map.error_um.size() != map.grid.Nodes()) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
