// libFuzzer target: the residual map CSV of a polish run, as the polish report reads it
// (reports/polish_report_inputs.h). Any input must be parsed or refused with arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "reports/polish_report_inputs.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::reports::ParseResidualMapCsv(std::string_view(reinterpret_cast<const char*>(data), size),
                                                 "residual_map.csv");
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
