// libFuzzer target: polish_summary.json, as the polish report reads it
// (reports/polish_report_inputs.h). Any input must be parsed or refused with arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "reports/polish_report_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::reports::ParsePolishSummary(std::string(reinterpret_cast<const char*>(data), size),
                                                "polish_summary.json");
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
