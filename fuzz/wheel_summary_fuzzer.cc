// libFuzzer target: the wheel summary reader of the grinding stage (summary.json of `process`, as
// `toolpath --wheel` reads it). Any input must give a wheel or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "grinding/wheel.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::grinding::ReadWheelSummary(arcwheel::fuzz::WriteInput(data, size, "summary.json"));
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
