#pragma once
// The ISO 16610-21 Gaussian profile filter: the mean line of a profile, whose amplitude
// transmission at wavelength lambda (or harmonic k) is
//   a1/a0 = exp(-pi (alpha lambda_c / lambda)^2) = exp(-pi (alpha k / k_c)^2),  alpha = sqrt(ln 2 / pi),
// exactly 50 % at the cut-off. (Public tools have shipped this filter with the kernel too wide: a
// kernel of standard deviation lambda_c / (2 pi) passes 61 % at the cut-off. Tests check the
// transmission, not the code.)
//
// Closed profiles (roundness): the periodic filter, applied to the Fourier coefficients of the
// equally spaced profile (FFTW), where the periodised Gaussian kernel's transmission is exact.
// Open profiles: the sampled weighting function s(x) = exp(-pi (x / (alpha lambda_c))^2) over
// |x| <= lambda_c, normalised to unit sum; within lambda_c of an end, where the window leaves the
// profile, the weights of the samples it still covers are normalised again (the zeroth-order
// Gaussian regression of ISO 16610-28 / ISO 16610-31, no end run-out discarded): a constant passes
// unchanged to the ends, a slope or curvature is bent towards the profile's inside there.

#include <memory>
#include <span>
#include <vector>

namespace arcwheel::characteristics {

// sqrt(ln 2 / pi) = 0.4697...
[[nodiscard]] double GaussianAlpha();

// The mean line's transmission at harmonic (or 1 / wavelength) `k` of a filter with cut-off `cutoff`
// in the same unit: exp(-pi (alpha k / cutoff)^2).
[[nodiscard]] double GaussianTransmission(double k, double cutoff);

// The mean line of a closed profile of n equally spaced samples over one revolution, for a cut-off
// of `cutoff_upr` undulations per revolution. Harmonic k of the profile is multiplied by
// GaussianTransmission(k, cutoff_upr), the mean (k = 0) kept. Throws Error{kInvalidOption,
// "characteristics.filter"} unless 0 < cutoff_upr <= n / 2, Error{kBadInput} for n < 8. Safe to
// call from several threads.
[[nodiscard]] std::vector<double> FilterClosedProfile(std::span<const double> values, double cutoff_upr);

// FilterClosedProfile made once for many profiles of one length and cut-off (a bootstrap filters
// some 10^5 of them): its plans, transmission and buffers are kept, and Apply gives the same
// numbers as FilterClosedProfile. Not for two threads at once: one object a thread.
class ClosedProfileFilter {
 public:
  // Throws as FilterClosedProfile does for n and cutoff_upr.
  ClosedProfileFilter(std::size_t n, double cutoff_upr);
  ~ClosedProfileFilter();
  ClosedProfileFilter(ClosedProfileFilter&&) noexcept;
  ClosedProfileFilter& operator=(ClosedProfileFilter&&) noexcept;

  // `filtered` (n values) = the mean line of `values` (n values); the two may be the same.
  void Apply(std::span<const double> values, std::span<double> filtered);

 private:
  struct State;
  std::unique_ptr<State> state_;
};

// Amplitudes sqrt(a_k^2 + b_k^2) of the Fourier series a_0 + sum_k a_k cos(k t) + b_k sin(k t) of a
// closed profile of n equally spaced samples, for k = 1 .. min(max_harmonic, ceil(n / 2) - 1), in
// the unit of the values; element k - 1 holds harmonic k.
[[nodiscard]] std::vector<double> HarmonicAmplitudes(std::span<const double> values, int max_harmonic);

// The closed profile's estimate without its white noise of 1-sigma `noise_sigma`: each harmonic
// k >= 1 whose power |X_k|^2 exceeds power_ratio times the noise's (n sigma^2) kept with the
// Wiener weight 1 - n sigma^2 / |X_k|^2, every other dropped (the noise cannot be told from it),
// the mean kept. Throws Error{kBadInput} for n < 8.
[[nodiscard]] std::vector<double> SignificantHarmonics(std::span<const double> values, double noise_sigma,
                                                       double power_ratio);

// The mean line of an open profile sampled every `spacing_mm`, for a cut-off wavelength
// `cutoff_mm` (end treatment above). Throws Error{kInvalidOption, "characteristics.filter"} unless
// spacing_mm > 0 and cutoff_mm >= 5 spacing_mm (below that the weighting function is not
// resolved), Error{kBadInput} for fewer than 2 samples.
[[nodiscard]] std::vector<double> FilterOpenProfile(std::span<const double> values, double spacing_mm,
                                                    double cutoff_mm);

}  // namespace arcwheel::characteristics
