#pragma once

#include <cmath>
#include <limits>

namespace arcwheel {

// A quiet NaN marks a value that was not measured or could not be estimated (a missing reading,
// an empty node), so that it propagates instead of passing for a number.
inline constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// std::isfinite as one comparison (false for NaN and +-inf), without a branch: a loop that ORs
// or sums it over many values is vectorised by GCC, one that calls std::isfinite is not.
template <typename T>
inline bool FiniteWithoutBranch(T value) {
  return std::abs(value) <= std::numeric_limits<T>::max();
}

}  // namespace arcwheel
