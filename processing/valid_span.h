#pragma once
// The part of a scan between its first and its last finite reading (a dropout at either end is
// NaN): what the helix spline and the map take, from the same rule.

#include <cmath>
#include <cstddef>
#include <span>
#include <utility>

namespace arcwheel::processing {

// The first and one past the last finite reading; {size, size} when none is finite.
template <typename T>
std::pair<std::size_t, std::size_t> ValidSpan(std::span<const T> readings) {
  std::size_t first = 0;
  while (first < readings.size() && !std::isfinite(static_cast<double>(readings[first]))) ++first;
  std::size_t last = readings.size();
  while (last > first && !std::isfinite(static_cast<double>(readings[last - 1]))) --last;
  return {first, last};
}

}  // namespace arcwheel::processing
