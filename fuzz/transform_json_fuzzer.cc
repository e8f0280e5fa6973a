// libFuzzer target: a transform JSON file (docs/frames.md) as `transform apply`, `frame` and
// `headcenter` read it. Any input must give a transform or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string_view>

#include "core/error.h"
#include "core/json_text.h"
#include "frames/transform_json.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  try {
    const auto json = arcwheel::ParseJsonText(std::string_view(reinterpret_cast<const char*>(data), size),
                                              "fuzz.json", "fuzz");
    (void)arcwheel::frames::TransformFromJson(json, "fuzz.json");
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
