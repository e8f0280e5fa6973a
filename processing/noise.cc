#include "processing/noise.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include "core/parallel.h"

namespace arcwheel::processing {
namespace {

// Finite doubles mapped to unsigned integers of the same order (-0 just below +0).
std::uint64_t OrderKey(double value) {
  const auto bits = std::bit_cast<std::uint64_t>(value);
  return (bits >> 63) != 0 ? ~bits : bits | (std::uint64_t{1} << 63);
}

// The middle one of the finite values value_at(m), m in [0, n) (the element nth_element puts at
// count / 2), without holding them all: a pass counts them in a histogram of their top bits, a
// second keeps only those of the slab that holds the middle one, and only the slab is selected in.
// An order statistic is one value whatever finds it; NaN when none is finite. (A vector of a
// million differences cost some 2,000 fresh pages, a tenth of a 1e6-sample scan's processing.)
template <typename ValueAt>
double MiddleOf(std::size_t n, const ValueAt& value_at, std::size_t& count) {
  constexpr int kBits = 16;
  const auto slab_of = [](double v) { return static_cast<std::size_t>(OrderKey(v) >> (64 - kBits)); };
  std::vector<std::uint32_t> histogram(std::size_t{1} << kBits, 0);
  count = 0;
  for (std::size_t m = 0; m < n; ++m) {
    const double v = value_at(m);
    if (!std::isfinite(v)) continue;
    ++histogram[slab_of(v)];
    ++count;
  }
  if (count == 0) return std::numeric_limits<double>::quiet_NaN();
  const std::size_t k = count / 2;
  std::size_t below = 0;
  std::size_t slab = 0;
  while (below + histogram[slab] <= k) below += histogram[slab++];
  std::vector<double> in_slab;
  in_slab.reserve(histogram[slab]);
  for (std::size_t m = 0; m < n; ++m) {
    const double v = value_at(m);
    if (std::isfinite(v) && slab_of(v) == slab) in_slab.push_back(v);
  }
  const auto middle = in_slab.begin() + static_cast<long>(k - below);
  std::nth_element(in_slab.begin(), middle, in_slab.end());
  return *middle;
}

// 1.4826 * MAD / sqrt(6) of the finite differences(m), m in [0, n); 0 for fewer than 10.
template <typename Differences>
double SigmaOfDifferences(std::size_t n, const Differences& differences) {
  std::size_t count = 0;
  const double center = MiddleOf(n, differences, count);
  if (count < 10) return 0.0;
  // 1.4826 * MAD estimates sigma for Gaussian data.
  const double mad = MiddleOf(
      n, [&](std::size_t m) { return std::abs(differences(m) - center); }, count);
  return 1.4826 * mad / std::sqrt(6.0);
}

template <typename T>
double NoiseSigmaMm(std::span<const T> z) {
  if (z.size() < 3) return 0.0;
  // The differences at i = 1, 1 + stride, ... while i + 1 < z.size().
  const std::size_t stride = std::max<std::size_t>(1, z.size() / 1'000'000);
  const std::size_t n = (z.size() - 2 + stride - 1) / stride;
  const auto difference = [&](std::size_t m) {
    const std::size_t i = 1 + m * stride;
    return double{z[i - 1]} - 2.0 * double{z[i]} + double{z[i + 1]};
  };
  if (stride == 1) return SigmaOfDifferences(n, difference);
  // A longer scan's differences lie a cache line or more apart over all its pages: gathered once,
  // not read there in each of the four passes (which took 0.1 s more at 1e8 samples).
  // Each half of them on a core of its own: a gather of 10^6 lines is bound by the memory's latency.
  std::vector<double> gathered(n);
  RunOnWorkers(2, [&](int half) {
    const std::size_t from = half == 0 ? 0 : n / 2, to = half == 0 ? n / 2 : n;
    for (std::size_t m = from; m < to; ++m) gathered[m] = difference(m);
  });
  return SigmaOfDifferences(n, [&](std::size_t m) { return gathered[m]; });
}

}  // namespace

double EstimateNoiseSigmaMm(std::span<const double> z_mm) { return NoiseSigmaMm(z_mm); }
double EstimateNoiseSigmaMm(std::span<const float> z_mm) { return NoiseSigmaMm(z_mm); }

}  // namespace arcwheel::processing
