#include "characteristics/gaussian_filter.h"

#include <fftw3.h>
#include <fmt/core.h>

#include <cmath>
#include <complex>
#include <map>
#include <memory>
#include <numbers>

#include "core/check.h"
#include "core/error.h"
#include "core/fftw_planner.h"

namespace arcwheel::characteristics {
namespace {

constexpr std::string_view kGaussianFilterStage = "characteristics.filter";

struct FftwFree {
  void operator()(void* memory) const { fftw_free(memory); }
};
using RealBuffer = std::unique_ptr<double[], FftwFree>;
using ComplexBuffer = std::unique_ptr<fftw_complex[], FftwFree>;

RealBuffer AllocateReal(std::size_t n) { return RealBuffer(fftw_alloc_real(n)); }
ComplexBuffer AllocateComplex(std::size_t n) { return ComplexBuffer(fftw_alloc_complex(n)); }

// FFTW's planner is not thread-safe, its plans are: one pair of plans per profile length, made
// once under the planner's lock and executed on each call's own (equally aligned, fftw_malloc)
// buffers. Single-threaded: a profile is short. The cache destroys its plans at exit, so that a
// leak checker sees none.
struct Plans {
  fftw_plan forward = nullptr;
  fftw_plan inverse = nullptr;
};

class PlanCache {
 public:
  // Takes the planner once so that its lock, a function-local static, is made before the cache
  // and so outlives it: the destructor takes it again.
  PlanCache() { const FftwPlanner planner; }
  PlanCache(const PlanCache&) = delete;
  PlanCache& operator=(const PlanCache&) = delete;
  ~PlanCache() {
    const FftwPlanner planner;
    for (auto& [n, made] : plans_) {
      fftw_destroy_plan(made.forward);
      fftw_destroy_plan(made.inverse);
    }
  }

  Plans For(std::size_t n) {
    const FftwPlanner planner(1);
    auto found = plans_.find(n);
    if (found != plans_.end()) return found->second;
    RealBuffer real = AllocateReal(n);
    ComplexBuffer spectrum = AllocateComplex(n / 2 + 1);
    const int size = static_cast<int>(n);
    Plans made;
    made.forward = fftw_plan_dft_r2c_1d(size, real.get(), spectrum.get(), FFTW_ESTIMATE);
    made.inverse = fftw_plan_dft_c2r_1d(size, spectrum.get(), real.get(), FFTW_ESTIMATE);
    return plans_.emplace(n, made).first->second;
  }

 private:
  std::map<std::size_t, Plans> plans_;
};

Plans PlansFor(std::size_t n) {
  static PlanCache cache;
  return cache.For(n);
}

// The n / 2 + 1 coefficients X_k = sum_j x_j exp(-2 pi i j k / n).
ComplexBuffer Spectrum(std::span<const double> values) {
  const std::size_t n = values.size();
  RealBuffer real = AllocateReal(n);
  std::copy(values.begin(), values.end(), real.get());
  ComplexBuffer spectrum = AllocateComplex(n / 2 + 1);
  fftw_execute_dft_r2c(PlansFor(n).forward, real.get(), spectrum.get());
  return spectrum;
}

void RequireClosedProfile(std::size_t n) {
  if (n < 8)
    throw Error(ErrorCode::kBadInput, kGaussianFilterStage,
                fmt::format("a closed profile needs at least 8 points, got {}", n));
}

void RequireClosedProfileCutOff(std::size_t n, double cutoff_upr) {
  RequireClosedProfile(n);
  if (!(cutoff_upr > 0) || !(cutoff_upr <= 0.5 * static_cast<double>(n))) {
    throw Error(ErrorCode::kInvalidOption, kGaussianFilterStage,
                fmt::format("cut-off {} UPR violates 0 < cut-off <= {} (half the {} points of the profile)",
                            cutoff_upr, 0.5 * static_cast<double>(n), n));
  }
}

}  // namespace

double GaussianAlpha() { return std::sqrt(std::numbers::ln2 / std::numbers::pi); }

double GaussianTransmission(double k, double cutoff) {
  const double ratio = GaussianAlpha() * k / cutoff;
  return std::exp(-std::numbers::pi * ratio * ratio);
}

struct ClosedProfileFilter::State {
  std::size_t n = 0;
  Plans plans;
  std::vector<double> gain;  // the transmission of harmonics 0 .. n / 2, times 1 / n
  RealBuffer real;
  ComplexBuffer spectrum;
};

ClosedProfileFilter::ClosedProfileFilter(std::size_t n, double cutoff_upr)
    : state_(std::make_unique<State>()) {
  RequireClosedProfileCutOff(n, cutoff_upr);
  State& s = *state_;
  s.n = n;
  s.plans = PlansFor(n);
  // The inverse transform is unnormalised: 1 / n folded into the transmission.
  const double inverse_n = 1.0 / static_cast<double>(n);
  s.gain.resize(n / 2 + 1);
  for (std::size_t k = 0; k <= n / 2; ++k)
    s.gain[k] = GaussianTransmission(static_cast<double>(k), cutoff_upr) * inverse_n;
  s.real = AllocateReal(n);
  s.spectrum = AllocateComplex(n / 2 + 1);
}

ClosedProfileFilter::~ClosedProfileFilter() = default;
ClosedProfileFilter::ClosedProfileFilter(ClosedProfileFilter&&) noexcept = default;
ClosedProfileFilter& ClosedProfileFilter::operator=(ClosedProfileFilter&&) noexcept = default;

void ClosedProfileFilter::Apply(std::span<const double> values, std::span<double> filtered) {
  State& s = *state_;
  ARCWHEEL_CHECK(values.size() == s.n && filtered.size() == s.n)
      << values.size() << " and " << filtered.size() << " values for a filter of " << s.n;
  std::copy(values.begin(), values.end(), s.real.get());
  fftw_execute_dft_r2c(s.plans.forward, s.real.get(), s.spectrum.get());
  for (std::size_t k = 0; k <= s.n / 2; ++k) {
    s.spectrum[k][0] *= s.gain[k];
    s.spectrum[k][1] *= s.gain[k];
  }
  fftw_execute_dft_c2r(s.plans.inverse, s.spectrum.get(), s.real.get());
  std::copy(s.real.get(), s.real.get() + s.n, filtered.begin());
}

std::vector<double> FilterClosedProfile(std::span<const double> values, double cutoff_upr) {
  std::vector<double> filtered(values.size());
  ClosedProfileFilter(values.size(), cutoff_upr).Apply(values, filtered);
  return filtered;
}

std::vector<double> SignificantHarmonics(std::span<const double> values, double noise_sigma,
                                         double power_ratio) {
  const std::size_t n = values.size();
  RequireClosedProfile(n);
  ComplexBuffer spectrum = Spectrum(values);
  const double noise_power = static_cast<double>(n) * noise_sigma * noise_sigma;
  const double inverse_n = 1.0 / static_cast<double>(n);
  spectrum[0][0] *= inverse_n;
  spectrum[0][1] = 0.0;
  for (std::size_t k = 1; k <= n / 2; ++k) {
    const double power = spectrum[k][0] * spectrum[k][0] + spectrum[k][1] * spectrum[k][1];
    const double weight = power > power_ratio * noise_power ? 1.0 - noise_power / power : 0.0;
    spectrum[k][0] *= weight * inverse_n;
    spectrum[k][1] *= weight * inverse_n;
  }
  RealBuffer real = AllocateReal(n);
  fftw_execute_dft_c2r(PlansFor(n).inverse, spectrum.get(), real.get());
  return {real.get(), real.get() + n};
}

std::vector<double> HarmonicAmplitudes(std::span<const double> values, int max_harmonic) {
  const std::size_t n = values.size();
  RequireClosedProfile(n);
  const std::size_t last =
      std::min<std::size_t>(static_cast<std::size_t>(std::max(max_harmonic, 0)), (n + 1) / 2 - 1);
  const ComplexBuffer spectrum = Spectrum(values);
  std::vector<double> amplitudes(last);
  for (std::size_t k = 1; k <= last; ++k) {
    amplitudes[k - 1] = 2.0 * std::hypot(spectrum[k][0], spectrum[k][1]) / static_cast<double>(n);
  }
  return amplitudes;
}

std::vector<double> FilterOpenProfile(std::span<const double> values, double spacing_mm, double cutoff_mm) {
  if (!(spacing_mm > 0) || !std::isfinite(spacing_mm) || !(cutoff_mm >= 5.0 * spacing_mm) ||
      !std::isfinite(cutoff_mm)) {
    throw Error(ErrorCode::kInvalidOption, kGaussianFilterStage,
                fmt::format("cut-off {} mm with spacing {} mm violates spacing > 0 and cut-off >= 5 spacings",
                            cutoff_mm, spacing_mm));
  }
  const std::size_t n = values.size();
  if (n < 2)
    throw Error(ErrorCode::kBadInput, kGaussianFilterStage,
                fmt::format("an open profile needs at least 2 points, got {}", n));
  // The weighting function over |x| <= lambda_c, where it has fallen to exp(-pi / alpha^2) = 7e-7.
  const auto half_width = static_cast<std::ptrdiff_t>(std::floor(cutoff_mm / spacing_mm));
  std::vector<double> weights(static_cast<std::size_t>(half_width) + 1);
  const double width_mm = GaussianAlpha() * cutoff_mm;
  for (std::size_t j = 0; j < weights.size(); ++j) {
    const double x = static_cast<double>(j) * spacing_mm / width_mm;
    weights[j] = std::exp(-std::numbers::pi * x * x);
  }
  const auto count = static_cast<std::ptrdiff_t>(n);
  std::vector<double> mean_line(n);
  for (std::ptrdiff_t i = 0; i < count; ++i) {
    const std::ptrdiff_t first = std::max<std::ptrdiff_t>(0, i - half_width);
    const std::ptrdiff_t last = std::min<std::ptrdiff_t>(count - 1, i + half_width);
    double weighted = 0.0, total = 0.0;
    for (std::ptrdiff_t j = first; j <= last; ++j) {
      const double w = weights[static_cast<std::size_t>(std::abs(j - i))];
      weighted += w * values[static_cast<std::size_t>(j)];
      total += w;
    }
    mean_line[static_cast<std::size_t>(i)] = weighted / total;
  }
  return mean_line;
}

}  // namespace arcwheel::characteristics
