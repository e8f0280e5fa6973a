#include "processing/noise.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace arcwheel::processing {
namespace {

double Median(std::vector<double>& values) {
  const auto middle = values.begin() + static_cast<long>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

template <typename T>
double NoiseSigmaMm(std::span<const T> z) {
  if (z.size() < 3) return 0.0;
  const std::size_t stride = std::max<std::size_t>(1, z.size() / 1'000'000);
  std::vector<double> d;
  d.reserve(z.size() / stride + 1);
  for (std::size_t i = 1; i + 1 < z.size(); i += stride) {
    const double value = double{z[i - 1]} - 2.0 * double{z[i]} + double{z[i + 1]};
    if (std::isfinite(value)) d.push_back(value);
  }
  if (d.size() < 10) return 0.0;
  const double center = Median(d);
  for (double& value : d) value = std::abs(value - center);
  // 1.4826 * MAD estimates sigma for Gaussian data.
  return 1.4826 * Median(d) / std::sqrt(6.0);
}

}  // namespace

double EstimateNoiseSigmaMm(std::span<const double> z_mm) { return NoiseSigmaMm(z_mm); }
double EstimateNoiseSigmaMm(std::span<const float> z_mm) { return NoiseSigmaMm(z_mm); }

}  // namespace arcwheel::processing
