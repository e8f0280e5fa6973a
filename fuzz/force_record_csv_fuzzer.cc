// libFuzzer target: the force/torque record reader (docs/frames.md), CSV layout. Any input must
// give a record or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>

#include "core/error.h"
#include "frames/force_record_io.h"
#include "fuzz/fuzz_input.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto file = arcwheel::frames::ReadForceRecord(arcwheel::fuzz::WriteInput(data, size, "record.csv"));
    if (file.record.t_s.empty()) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
