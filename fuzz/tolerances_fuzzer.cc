// libFuzzer target: the report tolerance file (reports/tolerances.h). Any input must give
// tolerances or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "reports/tolerances.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto tolerances = arcwheel::reports::ParseTolerances(
        std::string(reinterpret_cast<const char*>(data), size), "tol.json");
    for (const auto& [key, limit] : tolerances.limits) {
      if (limit.min && limit.max && *limit.min > *limit.max) __builtin_trap();
    }
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
