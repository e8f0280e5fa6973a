// libFuzzer target: the wheel_map.h5 reader of the report stage. Any input must give a map whose
// arrays match its axes, or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "reports/report_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::reports::ReadWheelMap(arcwheel::fuzz::WriteInput(data, size, "wheel_map.h5"));
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
