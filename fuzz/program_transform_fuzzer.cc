// libFuzzer target: the whole-file transforms of `arcwheel transform` (toolpath CSV, G-code, PMAC).
// The first byte picks the program kind. Any input must be rewritten or refused with
// arcwheel::Error; a rewritten program keeps every line.

#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "core/error.h"
#include "frames/program_transform.h"

namespace {

const arcwheel::frames::Transform& SomeRigidTransform() {
  static const arcwheel::frames::Transform transform = [] {
    arcwheel::frames::Transform t;
    t.linear = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    t.translation_mm = Eigen::Vector3d(10.0, -2.5, 0.125);
    return t;
  }();
  return transform;
}

size_t CountLines(std::string_view text) {
  size_t n = 0;
  for (char c : text) n += c == '\n';
  return n;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size == 0) return 0;
  using arcwheel::frames::ProgramKind;
  const ProgramKind kinds[] = {ProgramKind::kToolpathCsv, ProgramKind::kGcode, ProgramKind::kPmac};
  const ProgramKind kind = kinds[data[0] % 3];
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  try {
    const auto result = arcwheel::frames::TransformProgram(text, kind, SomeRigidTransform(), "fuzz.program");
    if (CountLines(result.text) != CountLines(text)) __builtin_trap();
  } catch (const arcwheel::Error&) {
  }
  return 0;
}
