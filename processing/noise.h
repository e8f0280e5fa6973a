#pragma once
// Per-sample measurement noise of a scan, from the data itself.

#include <span>

namespace arcwheel::processing {

// Robust 1-sigma noise (mm) from second differences of consecutive valid samples along the
// helix: d = z[i-1] - 2 z[i] + z[i+1] has variance 6 sigma^2 for white noise, and the smooth
// wheel contributes almost nothing at one sample's spacing. MAD-based, so spikes do not
// inflate it. Uses at most ~1e6 differences (evenly spread). Returns 0 for fewer than 10 triples.
[[nodiscard]] double EstimateNoiseSigmaMm(std::span<const double> z_mm);
[[nodiscard]] double EstimateNoiseSigmaMm(std::span<const float> z_mm);

}  // namespace arcwheel::processing
