#pragma once
// Small statistics the report pages share.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <vector>

namespace arcwheel::reports {

// The median of the finite values (the upper one of an even count); NaN when there are none.
[[nodiscard]] inline double FiniteMedian(std::vector<double> values) {
  std::erase_if(values, [](double v) { return !std::isfinite(v); });
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

}  // namespace arcwheel::reports
