#pragma once
// Spike removal (method.md A.2) on the sample sequence along the helix.
//
// kMedian (default) is burst-safe: a sample is rejected when it differs from the median of the
// 2w+1 valid samples around it by more than the threshold, so bursts of up to w consecutive
// spikes are caught (the paper's one-pass moving average leaves most of a 5-sample burst).
// Rejected samples are dropped (set to NaN): the helix spline bridges them with the samples
// around, instead of fitting invented values.
// kMovingMean is the paper's "improved moving average": a sample that differs from the mean
// of the other samples in its window by more than the threshold is replaced by that mean.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

namespace arcwheel::processing {

enum class DespikeMethod { kMedian, kMovingMean, kNone };

struct DespikeOptions {
  DespikeMethod method = DespikeMethod::kMedian;
  // Half-width w of the window, in valid samples. 1..50.
  int window_half_width = 5;
  // Rejection threshold in micrometres; <= 0 means `threshold_sigmas` times the estimated
  // noise, but at least `min_threshold_um`.
  double threshold_um = 0.0;
  double threshold_sigmas = 6.0;
  double min_threshold_um = 0.5;
  // Empty when valid, else one line per violation naming the option as `arcwheel process` spells
  // it, with its value: "--despike-sigmas = 0 violates > 0" (a field without a flag by its
  // ProcessOptions path, "despike.min_threshold_um").
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct DespikeResult {
  std::size_t rejected = 0;          // samples replaced or dropped
  double threshold_um = 0.0;         // the threshold used
  std::vector<std::size_t> indices;  // which samples (ascending)
};

// Despikes `z_mm` in place (NaN and infinities = invalid, left alone). `noise_sigma_mm` sets the
// automatic threshold.
//
// Float32 samples are judged in double from their stored values: a float scan loses exactly the
// samples that the same values widened to double would. kMedian only drops samples (NaN), so
// the two results agree sample for sample; kMovingMean's replacement means are computed in double
// and rounded to float when stored.
//
// kMedian costs a few ns per sample: the first pass does not sort windows but screens them (see
// docs/processing.md, "Despiking"), and runs on two workers for scans of 1e5 samples and more.
DespikeResult Despike(std::span<double> z_mm, double noise_sigma_mm, const DespikeOptions& options);
DespikeResult Despike(std::span<float> z_mm, double noise_sigma_mm, const DespikeOptions& options);

}  // namespace arcwheel::processing
