// libFuzzer target: a transform JSON file (docs/frames.md) as `transform --apply` and `headcenter`
// read it. Invalid JSON is the parser's documented error; everything else must give a transform
// or throw arcwheel::Error.

#include <cstddef>
#include <cstdint>
#include <nlohmann/json.hpp>
#include <string>

#include "core/error.h"
#include "frames/transform_json.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  nlohmann::json json;
  try {
    json = nlohmann::json::parse(reinterpret_cast<const char*>(data), reinterpret_cast<const char*>(data) + size);
  } catch (const nlohmann::json::parse_error&) {
    return 0;
  }
  try {
    (void)arcwheel::frames::TransformFromJson(json, "fuzz.json");
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
