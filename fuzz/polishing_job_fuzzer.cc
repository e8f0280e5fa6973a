// libFuzzer target: the polishing job reader (docs/polishing.md). The job is fuzzed next to a fixed,
// valid error map (`map.csv`, which a job names by "error_map": {"file": "map.csv"}); the map
// readers are fuzzed by their own targets. Any input must give a validated job or throw
// arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "polishing/job.h"

namespace {

void WriteFixedMap() {
  std::string map = "x_mm,y_mm,error_um\n";
  for (int j = -2; j <= 2; ++j) {
    for (int i = -2; i <= 2; ++i) {
      map += std::to_string(10 * i) + "," + std::to_string(10 * j) + "," +
             std::to_string(0.01 * (i * i + j)) + "\n";
    }
  }
  arcwheel::fuzz::WriteFile("map.csv", map.data(), map.size());
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const bool map_written = (WriteFixedMap(), true);
  (void)map_written;
  try {
    (void)arcwheel::polishing::ReadPolishJob(arcwheel::fuzz::WriteInput(data, size, "job.json"));
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
