#pragma once
// What the error-map readers' sources (polishing/error_map_*.cc) share: the stage id, the failures
// they throw and the memory budget's test of a grid. Not installed.

#include <string>

#include "core/nan.h"

namespace arcwheel::polishing::internal {

inline constexpr const char* kStage = "polishing.map";
// An error map marks a node without data with NaN; an infinity is a damaged value, never "no data".
inline constexpr const char* kInfinityIsDamage =
    "is not finite: a map marks no data with nan, and an infinity is a damaged value (docs/polishing.md)";

// Throws Error{kBadInput, "polishing.map"}: `what` of the file `name`.
[[noreturn]] void Fail(const std::string& name, const std::string& what);

// Refuses a grid of `rows` x `columns` nodes (as `what` in the file `name` declares it) that would
// not fit the memory budget of a polish run.
void CheckMapNodes(const std::string& name, const std::string& what, double rows, double columns);

}  // namespace arcwheel::polishing::internal
