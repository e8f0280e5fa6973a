// libFuzzer target: the summary.json reader of the report stage. Any input must give a summary or
// throw arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <string>

#include "core/error.h"
#include "reports/report_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::reports::ParseSummary(std::string(reinterpret_cast<const char*>(data), size),
                                          "summary.json");
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
