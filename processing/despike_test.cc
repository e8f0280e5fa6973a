// The median despiker against an independent, plain implementation of its rule (method.md A.2,
// docs/processing.md "Despiking"): every valid sample's window sorted and its median compared,
// the later passes and the restore step as documented. The fast first pass never sorts a window,
// so agreement here, on spikes, bursts, gaps, scan ends and values one ulp either side of the
// threshold, is what shows that it rejects the same samples.

#include "processing/despike.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <numbers>
#include <random>
#include <span>
#include <utility>
#include <vector>

#include "core/nan.h"

namespace arcwheel::processing {
namespace {

double SortedMedian(std::vector<double> values) {
  if (values.empty()) return kNaN;
  std::sort(values.begin(), values.end());
  const std::size_t n = values.size();
  return n % 2 == 1 ? values[n / 2] : 0.5 * (values[n / 2 - 1] + values[n / 2]);
}

// Up to w valid samples on each side of i, none further than 4w positions away, i left out.
std::vector<double> NearbyValues(const std::vector<double>& z, std::size_t i, int w) {
  std::vector<double> values;
  const auto reach = static_cast<std::ptrdiff_t>(4 * w);
  for (const int side : {-1, +1}) {
    int found = 0;
    for (std::ptrdiff_t step = 1; step <= reach && found < w; ++step) {
      const std::ptrdiff_t k = static_cast<std::ptrdiff_t>(i) + side * step;
      if (k < 0 || k >= static_cast<std::ptrdiff_t>(z.size())) break;
      if (std::isfinite(z[static_cast<std::size_t>(k)])) {
        values.push_back(z[static_cast<std::size_t>(k)]);
        ++found;
      }
    }
  }
  return values;
}

// The documented procedure, written for clarity: the indices it drops.
std::vector<std::size_t> ReferenceDespike(std::vector<double> z, int w, double threshold_mm) {
  // First pass: each valid sample against the median of the 2w+1 valid samples around it (fewer
  // at the scan's ends), however far apart they lie.
  std::vector<std::size_t> valid;
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (std::isfinite(z[i])) valid.push_back(i);
  }
  std::vector<std::size_t> newly;
  const auto half = static_cast<std::size_t>(w);
  for (std::size_t k = 0; k < valid.size(); ++k) {
    std::vector<double> window;
    for (std::size_t j = k - std::min(k, half); j <= std::min(valid.size() - 1, k + half); ++j) {
      window.push_back(z[valid[j]]);
    }
    if (std::abs(z[valid[k]] - SortedMedian(window)) > threshold_mm) newly.push_back(valid[k]);
  }
  // Later passes: the samples near those just dropped, judged again without them.
  std::vector<std::pair<std::size_t, double>> dropped;
  for (int pass = 1; !newly.empty(); ++pass) {
    for (const std::size_t i : newly) {
      dropped.emplace_back(i, z[i]);
      z[i] = kNaN;
    }
    if (pass == 8) break;
    std::vector<std::size_t> near;
    for (const std::size_t r : newly) {
      for (std::size_t i = r - std::min(r, 4 * half); i <= std::min(z.size() - 1, r + 4 * half); ++i) {
        if (i == r || !std::isfinite(z[i])) continue;
        // i is r's neighbour when fewer than w valid samples lie between them.
        std::size_t between = 0;
        for (std::size_t k = std::min(i, r) + 1; k < std::max(i, r); ++k)
          between += std::isfinite(z[k]) ? 1 : 0;
        if (between < half) near.push_back(i);
      }
    }
    std::sort(near.begin(), near.end());
    near.erase(std::unique(near.begin(), near.end()), near.end());
    std::vector<std::size_t> next;
    for (const std::size_t i : near) {
      std::vector<double> window = NearbyValues(z, i, w);
      window.push_back(z[i]);
      if (std::abs(z[i] - SortedMedian(window)) > threshold_mm) next.push_back(i);
    }
    newly = next;
  }
  // Restore: each dropped sample that agrees with the median of its kept neighbours.
  std::vector<std::size_t> rejected;
  for (const auto& [index, reading] : dropped) {
    const double median = SortedMedian(NearbyValues(z, index, w));
    if (!(std::isfinite(median) && std::abs(reading - median) <= threshold_mm)) rejected.push_back(index);
  }
  std::sort(rejected.begin(), rejected.end());
  return rejected;
}

// How many full first-pass windows have their median's distance from x (as rounded) just above
// the threshold, within `near_mm`, and how many at it or just below.
std::pair<int, int> BorderlineWindows(const std::vector<double>& z, int w, double threshold_mm,
                                      double near_mm) {
  std::vector<double> valid;
  for (const double v : z) {
    if (std::isfinite(v)) valid.push_back(v);
  }
  int above = 0, below = 0;
  const auto half = static_cast<std::size_t>(w);
  for (std::size_t k = half; k + half < valid.size(); ++k) {
    const std::vector<double> window(valid.begin() + static_cast<std::ptrdiff_t>(k - half),
                                     valid.begin() + static_cast<std::ptrdiff_t>(k + half + 1));
    const double distance = std::abs(valid[k] - SortedMedian(window));
    above += distance > threshold_mm && distance <= threshold_mm + near_mm ? 1 : 0;
    below += distance <= threshold_mm && distance >= threshold_mm - near_mm ? 1 : 0;
  }
  return {above, below};
}

DespikeOptions MedianWith(int w, double threshold_um) {
  return {.method = DespikeMethod::kMedian, .window_half_width = w, .threshold_um = threshold_um};
}

// Checks the despiker against the reference on `z` (double), and its float version on the same
// values rounded to float against the double version on those rounded values.
void ExpectSameAsReference(const std::vector<double>& z, int w, double threshold_um) {
  const double threshold_mm = threshold_um / 1000.0;
  std::vector<double> despiked = z;
  const DespikeResult result = Despike(despiked, 0.0, MedianWith(w, threshold_um));
  const std::vector<std::size_t> expected = ReferenceDespike(z, w, threshold_mm);
  ASSERT_EQ(result.indices, expected) << "w = " << w << ", " << z.size() << " samples";
  EXPECT_EQ(result.rejected, expected.size());
  for (std::size_t i = 0, e = 0; i < z.size(); ++i) {
    const bool dropped = e < expected.size() && expected[e] == i;
    if (dropped) ++e;
    if (dropped || !std::isfinite(z[i])) {
      EXPECT_TRUE(std::isnan(despiked[i])) << "sample " << i;
    } else {
      EXPECT_EQ(despiked[i], z[i]) << "sample " << i;
    }
  }

  std::vector<float> as_float(z.begin(), z.end());
  std::vector<double> widened(as_float.begin(), as_float.end());
  const std::vector<double> widened_input = widened;
  const DespikeResult by_float = Despike(std::span<float>(as_float), 0.0, MedianWith(w, threshold_um));
  const DespikeResult by_double = Despike(std::span<double>(widened), 0.0, MedianWith(w, threshold_um));
  EXPECT_EQ(by_float.indices, by_double.indices);
  EXPECT_EQ(by_double.indices, ReferenceDespike(widened_input, w, threshold_mm));
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (std::isnan(widened[i])) {
      EXPECT_TRUE(std::isnan(as_float[i])) << "sample " << i;
    } else {
      EXPECT_EQ(static_cast<double>(as_float[i]), widened[i]) << "sample " << i;
    }
  }
}

// Heights along the helix over an arc-profile wheel (mm): the arc's sag as the sensor moves
// across it, one turn of runout every `per_turn` samples, and white noise.
std::vector<double> NoisyArc(std::size_t n, double noise_mm, std::mt19937& rng, std::size_t per_turn = 2000) {
  std::normal_distribution<double> noise(0.0, noise_mm);
  std::vector<double> z(n);
  const double radius_mm = 40.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double across_mm = -10.0 + 20.0 * static_cast<double>(i) / static_cast<double>(n);
    const double turn = static_cast<double>(i) / static_cast<double>(per_turn);
    z[i] = std::sqrt(radius_mm * radius_mm - across_mm * across_mm) - 35.0 +
           0.003 * std::sin(2.0 * std::numbers::pi * turn) + noise(rng);
  }
  return z;
}

// Adds isolated spikes and bursts of 2..burst_max samples, up or down, and gaps of NaN.
void Damage(std::vector<double>& z, std::mt19937& rng, double spike_rate, double burst_rate, int burst_max,
            double gap_rate, int gap_max) {
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  std::uniform_real_distribution<double> height_mm(0.005, 0.2);
  std::uniform_int_distribution<int> burst_length(2, burst_max), gap_length(1, gap_max);
  for (std::size_t i = 0; i < z.size(); ++i) {
    const double u = unit(rng);
    const double sign = unit(rng) < 0.5 ? -1.0 : 1.0;
    if (u < spike_rate) {
      z[i] += sign * height_mm(rng);
    } else if (u < spike_rate + burst_rate) {
      const double h = sign * height_mm(rng);
      for (int k = burst_length(rng); k > 0 && i < z.size(); --k, ++i) z[i] += h * (0.8 + 0.4 * unit(rng));
    } else if (u < spike_rate + burst_rate + gap_rate) {
      for (int k = gap_length(rng); k > 0 && i < z.size(); --k, ++i) z[i] = kNaN;
    }
  }
}

TEST(MedianDespiker, DropsTheSamplesTheReferenceDropsOnIsolatedSpikes) {
  std::mt19937 rng(11);
  std::vector<double> z = NoisyArc(20000, 0.3e-3, rng);
  Damage(z, rng, 0.01, 0.0, 2, 0.0, 1);
  ExpectSameAsReference(z, 5, 1.8);
}

TEST(MedianDespiker, DropsTheSamplesTheReferenceDropsOnBurstsBesideSpikesAndGaps) {
  for (const int w : {1, 2, 5, 9}) {
    std::mt19937 rng(static_cast<std::uint32_t>(100 + w));
    std::vector<double> z = NoisyArc(20000, 0.3e-3, rng);
    Damage(z, rng, 0.01, 0.005, 2 * w + 2, 0.005, 40);
    ExpectSameAsReference(z, w, 1.8);
  }
}

TEST(MedianDespiker, DropsTheSamplesTheReferenceDropsWithAWideWindow) {
  std::mt19937 rng(7);
  std::vector<double> z = NoisyArc(6000, 0.3e-3, rng);
  Damage(z, rng, 0.02, 0.01, 60, 0.002, 200);
  ExpectSameAsReference(z, 50, 1.8);
}

TEST(MedianDespiker, AgreesWithTheReferenceOnTwoWorkersAcrossTheSplitAndBlockEdges) {
  // 2.4e5 samples: judged as two halves; dense damage puts spikes and gaps on many block edges.
  std::mt19937 rng(5);
  std::vector<double> z = NoisyArc(240000, 0.3e-3, rng);
  Damage(z, rng, 0.005, 0.002, 7, 0.002, 40);
  for (std::size_t i = 120000 - 6; i < 120000 + 3; ++i) z[i] += 0.05;  // a burst across the split
  ExpectSameAsReference(z, 5, 1.8);
}

TEST(MedianDespiker, AgreesWithTheReferenceOneUlpEitherSideOfTheThreshold) {
  // Readings drawn from a few levels: a base and the base plus or minus the threshold, each moved
  // by up to 3 ulps, so that many windows' medians lie within an ulp of x +- threshold and the
  // count above or below is exactly w or w+1. Ties everywhere, and NaN gaps.
  const double threshold_um = 1.0;
  const double threshold_mm = threshold_um / 1000.0;
  for (const double base : {1.0, 17.25, -3.0e-3}) {
    std::vector<double> levels;
    for (const double offset : {-threshold_mm, 0.0, threshold_mm}) {
      double level = base + offset;
      for (int k = 0; k < 3; ++k) level = std::nextafter(level, -1e9);
      for (int k = 0; k < 7; ++k, level = std::nextafter(level, 1e9)) levels.push_back(level);
    }
    std::mt19937 rng(23);
    std::uniform_int_distribution<std::size_t> pick(0, levels.size() - 1);
    std::uniform_real_distribution<double> unit(0.0, 1.0);
    const double level_ulp_mm =
        std::nextafter(std::abs(base) + threshold_mm, 1e9) - (std::abs(base) + threshold_mm);
    for (const int w : {1, 2, 5}) {
      std::vector<double> z(30000);
      for (double& v : z) v = unit(rng) < 0.02 ? kNaN : levels[pick(rng)];
      const auto [just_above, just_below] = BorderlineWindows(z, w, threshold_mm, 8 * level_ulp_mm);
      EXPECT_GT(just_above, 100) << "base " << base << ", w = " << w;
      EXPECT_GT(just_below, 100) << "base " << base << ", w = " << w;
      ExpectSameAsReference(z, w, threshold_um);
    }
  }
}

TEST(MedianDespiker, JudgesAFewSamplesAtTheDifferenceThatRoundsToTheThreshold) {
  // A flat run at 1.0 with isolated samples 1.0 + d for d around the threshold: the rule compares
  // the rounded difference, so a sample whose difference rounds to exactly the threshold stays.
  const double threshold_mm = 1.0 / 1000.0;
  std::vector<double> z(400, 1.0);
  std::vector<std::size_t> expected;
  double above = 1.0 + threshold_mm, below = 1.0 - threshold_mm;
  for (int k = 0; k < 4; ++k) {
    above = std::nextafter(above, 0.0);
    below = std::nextafter(below, 2.0);
  }
  for (std::size_t i = 20; i + 20 < z.size(); i += 20) {
    const bool up = (i / 20) % 2 == 0;
    double& level = up ? above : below;
    z[i] = level;
    if (std::abs(level - 1.0) > threshold_mm) expected.push_back(i);
    level = std::nextafter(level, up ? 2.0 : 0.0);
  }
  ASSERT_GT(expected.size(), 3U);  // the sweep crosses the threshold on both sides
  ASSERT_LT(expected.size(), 14U);
  std::vector<double> despiked = z;
  EXPECT_EQ(Despike(despiked, 0.0, MedianWith(5, 1.0)).indices, expected);
  ExpectSameAsReference(z, 5, 1.0);
}

TEST(MedianDespiker, AgreesWithTheReferenceAtTheScanEndsAndOnShortScans) {
  std::mt19937 rng(3);
  for (std::size_t n = 0; n <= 24; ++n) {
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<double> z = NoisyArc(n, 0.3e-3, rng);
      Damage(z, rng, 0.15, 0.1, 4, 0.1, 3);
      ExpectSameAsReference(z, 5, 1.8);
    }
  }
  std::vector<double> ends = NoisyArc(500, 0.3e-3, rng);
  for (const std::size_t i : {0, 1, 2, 497, 499}) ends[i] += 0.05;
  ExpectSameAsReference(ends, 5, 1.8);
  ExpectSameAsReference(std::vector<double>(50, kNaN), 5, 1.8);
}

TEST(MedianDespiker, TreatsInfinitiesAsInvalidSamples) {
  std::vector<double> z(300, 2.0);
  z[100] = std::numeric_limits<double>::infinity();
  z[101] = -std::numeric_limits<double>::infinity();
  z[150] = 2.5;
  std::vector<double> despiked = z;
  EXPECT_EQ(Despike(despiked, 0.0, MedianWith(5, 1.0)).indices, std::vector<std::size_t>{150});
  EXPECT_EQ(despiked[100], z[100]);
  EXPECT_EQ(despiked[101], z[101]);
}

TEST(MovingMeanDespiker, FloatScanIsJudgedAsItsValuesWidenedToDouble) {
  std::mt19937 rng(9);
  std::vector<double> z = NoisyArc(150000, 0.3e-3, rng);
  Damage(z, rng, 0.002, 0.0, 2, 0.001, 20);
  std::vector<float> as_float(z.begin(), z.end());
  std::vector<double> widened(as_float.begin(), as_float.end());
  const DespikeOptions options{.method = DespikeMethod::kMovingMean, .threshold_um = 1.8};
  const DespikeResult by_float = Despike(std::span<float>(as_float), 0.0, options);
  const DespikeResult by_double = Despike(std::span<double>(widened), 0.0, options);
  ASSERT_EQ(by_float.indices, by_double.indices);
  EXPECT_GT(by_float.rejected, 200U);
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (std::isnan(widened[i])) {
      EXPECT_TRUE(std::isnan(as_float[i])) << "sample " << i;
    } else {
      EXPECT_EQ(as_float[i], static_cast<float>(widened[i])) << "sample " << i;  // the mean, rounded
    }
  }
}

}  // namespace
}  // namespace arcwheel::processing
