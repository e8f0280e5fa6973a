// libFuzzer target: the grinding job parser (docs/grinding.md). Any input must give a validated job
// or throw arcwheel::Error. A job that names a wheel summary reads it relative to a folder that
// holds none, so the summary reader is fuzzed by its own target.

#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>

#include "core/error.h"
#include "fuzz/fuzz_input.h"
#include "grinding/job.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    (void)arcwheel::grinding::ParseJob(std::string(reinterpret_cast<const char*>(data), size),
                                       arcwheel::fuzz::WorkFolder() / "job.json", std::nullopt);
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
