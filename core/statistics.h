#pragma once
// The plain statistics of a few values that several stages report (per-phase fits, force records),
// and the chi-square test that two stages apply. Not for the bulk of a scan: processing/noise.cc
// has a faster median for millions of values.

#include <algorithm>
#include <cstddef>
#include <limits>
#include <numeric>
#include <span>
#include <vector>

namespace arcwheel {

// The arithmetic mean, summed in order; NaN for no values.
[[nodiscard]] inline double Mean(std::span<const double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  return std::accumulate(values.begin(), values.end(), 0.0) / static_cast<double>(values.size());
}

// The element at position n/2 of the sorted values (the upper median of an even count: an order
// statistic, one of the values); NaN for no values.
[[nodiscard]] inline double Median(std::vector<double> values) {
  if (values.empty()) return std::numeric_limits<double>::quiet_NaN();
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

// P(X >= chi2) for X chi-square distributed with `dof` degrees of freedom (Boost.Math, compiled
// once here): the p-value of a chi-square test. dof > 0 and chi2 >= 0, finite.
[[nodiscard]] double ChiSquaredUpperTail(double chi2, double dof);

}  // namespace arcwheel
