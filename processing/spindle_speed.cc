#include "processing/spindle_speed.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "core/check.h"
#include "core/dense.h"
#include "core/error.h"
#include "core/parallel.h"
#include "processing/helix_geometry.h"

namespace arcwheel::processing {
namespace {

using Complex = std::complex<double>;

struct TurnHarmonics {
  double turn = 0.0;                    // turn index of the window's middle
  std::vector<Complex> amplitude;       // Q_h = A_h - i B_h, h = 1..H
  std::vector<double> amplitude_sigma;  // 1 sigma of |Q_h| from the turn's residuals
  double residual_sigma = 0.0;          // rms of the per-bin fit residual
};

// Over one turn a smooth trend and the lowest harmonics are nearly the same functions (a ramp's
// Fourier series), so each fit spans a window of several turns: the trend (the arc profile passing
// under the sensor) is a cubic in time across the window, the wheel's signature repeats in it.
constexpr int kTurnsPerWindow = 4;
constexpr int kTrendTerms = 4;
constexpr std::size_t kMaxWindows = 64;

// A long scan pins the speed far better than needed: at most kMaxWindows windows, spread over it
// with this spacing (in windows).
std::size_t SpreadSpacing(std::size_t turns) {
  const std::size_t available = turns / static_cast<std::size_t>(kTurnsPerWindow);
  return std::max<std::size_t>(1, (available + kMaxWindows - 1) / kMaxWindows);
}

// The scan's valid samples binned by turn and by phase within the turn: cell k * bins + b holds
// bin b of turn k.
struct PhaseBins {
  std::size_t turns = 0;
  std::size_t bins = 0;
  std::vector<double> sum;
  std::vector<double> position;  // sum of the samples' fractional turn positions
  std::vector<int> count;
};

// Bins the valid samples of turns [first, first + turns) of the scan into `out` (cell k * bins + b
// holds bin b of turn first + k), reading every `stride`-th sample from `begin`.
template <typename T>
void BinTurns(const HelixGeometry& geometry, std::span<const T> z, std::size_t begin, std::size_t stride,
              std::size_t first, PhaseBins& out) {
  const double u0 = geometry.PhaseAt(0);
  const std::size_t nb = out.bins;
  const auto bins = static_cast<double>(nb);
  for (std::size_t i = begin; i < z.size(); i += stride) {
    const double turn_position = (geometry.PhaseAt(i) - u0) / 360.0;
    const auto k = static_cast<std::size_t>(turn_position);
    if (k >= first + out.turns) break;  // the phase increases with i
    if (!std::isfinite(z[i])) continue;
    const double fraction = turn_position - static_cast<double>(k);
    const auto b = std::min(nb - 1, static_cast<std::size_t>(fraction * bins));
    const std::size_t cell = (k - first) * nb + b;
    out.sum[cell] += z[i];
    out.position[cell] += fraction;
    ++out.count[cell];
  }
}

// The scan binned by phase at one speed, one window of turns at a time. Windows far apart are all
// a long scan needs (at most kMaxWindows of kTurnsPerWindow turns), so a scan whose phase follows
// from its settings is binned only over the windows asked for, from the first sample of each
// (found by bisection); other scans are binned whole once. Either way every cell sums the same
// samples in the same order.
template <typename T>
class WindowBinner {
 public:
  WindowBinner(const acquisition::Scan& scan, std::span<const T> z, double rpm, int bins)
      : geometry_(scan, rpm), z_(z), bins_(static_cast<std::size_t>(bins)) {
    const double u0 = geometry_.PhaseAt(0);
    turns_ = static_cast<std::size_t>(std::floor((geometry_.PhaseAt(scan.size() - 1) - u0) / 360.0)) + 1;
    // Bins need a few samples each, not thirty: long scans are read with a stride.
    stride_ = std::max<std::size_t>(1, z.size() / (turns_ * bins_ * 4));
    if (!geometry_.from_settings()) {
      whole_ = Empty(turns_);
      BinTurns(geometry_, z_, 0, stride_, 0, whole_);
    }
  }

  [[nodiscard]] std::size_t turns() const { return turns_; }

  // Turns [first, first + kTurnsPerWindow): cell k * bins + b holds bin b of turn first + k.
  [[nodiscard]] PhaseBins Window(std::size_t first) const {
    const auto window = static_cast<std::size_t>(kTurnsPerWindow);
    PhaseBins out = Empty(window);
    if (whole_.turns > 0) {
      const auto from = static_cast<long>(first * bins_);
      const auto to = static_cast<long>((first + window) * bins_);
      std::copy(whole_.sum.begin() + from, whole_.sum.begin() + to, out.sum.begin());
      std::copy(whole_.position.begin() + from, whole_.position.begin() + to, out.position.begin());
      std::copy(whole_.count.begin() + from, whole_.count.begin() + to, out.count.begin());
      return out;
    }
    BinTurns(geometry_, z_, stride_ * FirstStrideInTurn(first), stride_, first, out);
    return out;
  }

 private:
  [[nodiscard]] PhaseBins Empty(std::size_t turns) const {
    PhaseBins out;
    out.turns = turns;
    out.bins = bins_;
    out.sum.assign(turns * bins_, 0.0);
    out.position.assign(turns * bins_, 0.0);
    out.count.assign(turns * bins_, 0);
    return out;
  }

  // The first j with sample j * stride in turn `first` or later (the phase increases with j).
  [[nodiscard]] std::size_t FirstStrideInTurn(std::size_t first) const {
    const double u0 = geometry_.PhaseAt(0);
    std::size_t lo = 0;
    std::size_t hi = (z_.size() + stride_ - 1) / stride_;
    while (lo < hi) {
      const std::size_t mid = lo + (hi - lo) / 2;
      const auto k = static_cast<std::size_t>((geometry_.PhaseAt(mid * stride_) - u0) / 360.0);
      if (k < first) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    return lo;
  }

  HelixGeometry geometry_;
  std::span<const T> z_;
  std::size_t bins_ = 0;
  std::size_t turns_ = 0;
  std::size_t stride_ = 1;
  PhaseBins whole_;
};

// The filled cells of the window of turns starting at `first`; empty unless every turn of it has
// at least 90 % of its bins filled.
std::vector<std::size_t> CoveredWindowCells(const PhaseBins& bins, std::size_t first) {
  const std::size_t nb = bins.bins;
  std::vector<std::size_t> cells;
  for (std::size_t k = first; k < first + static_cast<std::size_t>(kTurnsPerWindow); ++k) {
    std::size_t filled = 0;
    for (std::size_t b = 0; b < nb; ++b) {
      if (bins.count[k * nb + b] > 0) {
        cells.push_back(k * nb + b);
        ++filled;
      }
    }
    if (static_cast<double>(filled) < 0.9 * static_cast<double>(nb)) return {};
  }
  return cells;
}

// Fits the cells of the window of turns from `first` (binned by WindowBinner::Window) with sum_j p_j tau^j +
// sum_h (A_h cos(h theta) + B_h sin(h theta)). Each bin enters at the mean position of its own samples, not
// at its centre: with a non-integer number of samples per bin the two differ, and the arc's slope through a
// turn would turn that difference into a phase that drifts along the axis.
TurnHarmonics FitWindow(const PhaseBins& bins, const std::vector<std::size_t>& cells, std::size_t first,
                        int harmonics) {
  const std::size_t nb = bins.bins;
  const int parameters = kTrendTerms + 2 * harmonics;
  const auto rows = static_cast<Eigen::Index>(cells.size());
  Eigen::MatrixXd design(rows, parameters);
  Eigen::VectorXd values(rows);
  for (Eigen::Index r = 0; r < rows; ++r) {
    const std::size_t cell = cells[static_cast<std::size_t>(r)];
    const double fraction = bins.position[cell] / bins.count[cell];
    const double in_window = static_cast<double>(cell / nb) + fraction;
    const double tau = (in_window - 0.5 * kTurnsPerWindow) / kTurnsPerWindow;
    const double theta = 2.0 * std::numbers::pi * fraction;
    double power = 1.0;
    for (int j = 0; j < kTrendTerms; ++j, power *= tau) design(r, j) = power;
    // cos(h theta), sin(h theta) by the angle-addition recurrence from h = 1: one sincos a row
    // instead of two per harmonic, exact to a few units of rounding at h = 12.
    const double c1 = std::cos(theta);
    const double s1 = std::sin(theta);
    double c = c1, sn = s1;
    for (int h = 1; h <= harmonics; ++h) {
      design(r, kTrendTerms - 2 + 2 * h) = c;
      design(r, kTrendTerms - 1 + 2 * h) = sn;
      const double next_c = c * c1 - sn * s1;
      sn = sn * c1 + c * s1;
      c = next_c;
    }
    values(r) = bins.sum[cell] / bins.count[cell];
  }
  const Eigen::MatrixXd normal = design.transpose() * design;
  const Eigen::VectorXd p = dense::LdltSolve(normal, Eigen::VectorXd(design.transpose() * values));
  const Eigen::MatrixXd inverse =
      dense::LdltSolve(normal, Eigen::MatrixXd(Eigen::MatrixXd::Identity(parameters, parameters)));
  const double rss = (design * p - values).squaredNorm();
  TurnHarmonics turn;
  turn.turn = static_cast<double>(first) + 0.5 * kTurnsPerWindow;
  turn.residual_sigma = std::sqrt(rss / std::max<double>(1.0, static_cast<double>(rows - parameters)));
  for (int h = 1; h <= harmonics; ++h) {
    const int c = kTrendTerms - 2 + 2 * h;
    turn.amplitude.emplace_back(p(c), -p(c + 1));
    turn.amplitude_sigma.push_back(turn.residual_sigma *
                                   std::sqrt(0.5 * (inverse(c, c) + inverse(c + 1, c + 1))));
  }
  return turn;
}

// Bins the scan by phase at `rpm` and fits each window whose turns are 90 % covered (FitWindow);
// `turn` is the window's middle. Windows start every `spacing` windows, at most kMaxWindows of
// them; `spacing` 0 spreads them over the whole scan.
template <typename T>
std::vector<TurnHarmonics> FitTurns(const acquisition::Scan& scan, std::span<const T> z, double rpm, int bins,
                                    int harmonics, std::size_t spacing) {
  const WindowBinner<T> binner(scan, z, rpm, bins);
  const auto window = static_cast<std::size_t>(kTurnsPerWindow);
  const std::size_t stride = window * (spacing > 0 ? spacing : SpreadSpacing(binner.turns()));
  std::vector<std::size_t> firsts;
  std::vector<PhaseBins> binned;
  std::vector<std::vector<std::size_t>> cells;
  for (std::size_t first = 0; first + window <= binner.turns() && firsts.size() < kMaxWindows;
       first += stride) {
    PhaseBins window_bins = binner.Window(first);
    std::vector<std::size_t> covered = CoveredWindowCells(window_bins, 0);
    if (covered.empty()) continue;
    firsts.push_back(first);
    binned.push_back(std::move(window_bins));
    cells.push_back(std::move(covered));
  }
  // The windows' fits are independent: two workers take alternate ones.
  std::vector<TurnHarmonics> result(firsts.size());
  constexpr int kWorkers = 2;
  RunOnWorkers(kWorkers, [&](int worker) {
    for (auto w = static_cast<std::size_t>(worker); w < firsts.size(); w += kWorkers) {
      result[w] = FitWindow(binned[w], cells[w], firsts[w], harmonics);
    }
  });
  return result;
}

struct Drift {
  double delta = 0.0;  // relative speed error
  double sigma = 0.0;
};

// Least-squares slope of the unwrapped phase of harmonic h over the turns.
Drift PhaseDrift(const std::vector<TurnHarmonics>& turns, int h) {
  const auto index = static_cast<std::size_t>(h - 1);
  std::vector<double> x;
  std::vector<double> phase;
  double unwrapped = std::arg(turns.front().amplitude[index]);
  for (std::size_t k = 0; k < turns.size(); ++k) {
    if (k > 0) {
      unwrapped += std::arg(turns[k].amplitude[index] * std::conj(turns[k - 1].amplitude[index]));
    }
    x.push_back(turns[k].turn);
    phase.push_back(unwrapped);
  }
  const auto n = static_cast<double>(x.size());
  double mx = 0, my = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    mx += x[i];
    my += phase[i];
  }
  mx /= n;
  my /= n;
  double sxx = 0, sxy = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    sxx += (x[i] - mx) * (x[i] - mx);
    sxy += (x[i] - mx) * (phase[i] - my);
  }
  const double slope = sxy / sxx;
  double rss = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double r = phase[i] - my - slope * (x[i] - mx);
    rss += r * r;
  }
  const double slope_sigma = std::sqrt(rss / std::max(1.0, n - 2.0) / sxx);
  const double scale = 2.0 * std::numbers::pi * h;
  return {slope / scale, slope_sigma / scale};
}

// The harmonics whose mean amplitude over the windows stands clear of both its own noise and the
// amplitude floor.
std::vector<int> HarmonicsClearOfTheNoise(const std::vector<TurnHarmonics>& turns, int harmonics,
                                          const SpindleSpeedOptions& options) {
  std::vector<int> usable;
  for (int h = 1; h <= harmonics; ++h) {
    const auto index = static_cast<std::size_t>(h - 1);
    double mean_amplitude = 0.0;
    double mean_sigma = 0.0;
    for (const auto& t : turns) {
      mean_amplitude += std::abs(t.amplitude[index]);
      mean_sigma += t.amplitude_sigma[index];
    }
    mean_amplitude /= static_cast<double>(turns.size());
    mean_sigma /= static_cast<double>(turns.size());
    const double floor_mm = options.min_harmonic_amplitude_um / 1000.0;
    if (mean_amplitude > std::max(options.min_harmonic_snr * mean_sigma, floor_mm)) usable.push_back(h);
  }
  return usable;
}

// The drifts of the usable harmonics combined: their weighted mean and its sigma.
Drift CombineDrifts(const std::vector<TurnHarmonics>& turns, const std::vector<int>& usable) {
  std::vector<Drift> drifts;
  double weight_sum = 0.0;
  double weighted = 0.0;
  for (const int h : usable) {
    drifts.push_back(PhaseDrift(turns, h));
    const double w = 1.0 / std::max(drifts.back().sigma * drifts.back().sigma, 1e-30);
    weight_sum += w;
    weighted += w * drifts.back().delta;
  }
  const double delta = weighted / weight_sum;
  double sigma_relative = std::sqrt(1.0 / weight_sum);
  // Harmonics that disagree beyond their sigmas reveal model error (what the wheel does that the
  // per-turn model does not describe): widen the sigma by the Birge ratio.
  if (drifts.size() > 1) {
    double chi2 = 0.0;
    for (const Drift& d : drifts)
      chi2 += (d.delta - delta) * (d.delta - delta) / std::max(d.sigma * d.sigma, 1e-30);
    sigma_relative *= std::max(1.0, std::sqrt(chi2 / static_cast<double>(drifts.size() - 1)));
  }
  return {delta, sigma_relative};
}

// Turns of the scan at the nominal speed.
double NominalTurns(const HelixGeometry& nominal, std::size_t samples) {
  return (nominal.PhaseAt(samples - 1) - nominal.PhaseAt(0)) / 360.0;
}

void SetResult(double rpm, double sigma_relative, const SpindleSpeedOptions& options,
               SpindleSpeedEstimate& estimate) {
  estimate.available = true;
  estimate.fitted_rpm = rpm;
  estimate.sigma_rpm = sigma_relative * rpm;
  estimate.significant =
      std::abs(rpm - estimate.nominal_rpm) > options.significance_sigmas * estimate.sigma_rpm;
  estimate.used_rpm = estimate.significant ? rpm : estimate.nominal_rpm;
  if (estimate.used_first_harmonic) {
    estimate.note =
        "only the first harmonic (eccentricity) was usable: an axial wobble of the arc centre cannot be told "
        "from a speed error with it";
  }
}

}  // namespace

std::vector<std::string> SpindleSpeedOptions::Problems() const {
  std::vector<std::string> problems;
  const auto require_non_negative = [&problems](const char* name, double value) {
    if (!(value >= 0.0 && std::isfinite(value)))
      problems.push_back(fmt::format("speed.{} = {} violates finite and >= 0", name, value));
  };
  if (max_harmonic < 1 || max_harmonic > 60)
    problems.push_back(fmt::format("speed.max_harmonic = {} violates 1..60", max_harmonic));
  require_non_negative("min_harmonic_snr", min_harmonic_snr);
  require_non_negative("min_harmonic_amplitude_um", min_harmonic_amplitude_um);
  require_non_negative("significance_sigmas", significance_sigmas);
  if (iterations < 0) problems.push_back(fmt::format("speed.iterations = {} violates >= 0", iterations));
  return problems;
}

namespace {

template <typename T>
SpindleSpeedEstimate EstimateSpeed(const acquisition::Scan& scan, std::span<const T> z,
                                   const SpindleSpeedOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "processing.speed", options.Problems());
  ARCWHEEL_CHECK(!scan.has_encoder()) << "speed estimation needs a scan without an encoder";
  SpindleSpeedEstimate estimate;
  estimate.nominal_rpm = *scan.metadata.spindle_rpm;
  estimate.fitted_rpm = estimate.used_rpm = estimate.nominal_rpm;

  const HelixGeometry nominal(scan, estimate.nominal_rpm);
  const double samples_per_turn =
      static_cast<double>(scan.size()) / std::max(1.0, NominalTurns(nominal, scan.size()));
  const int bins = static_cast<int>(std::clamp(samples_per_turn / 2.0, 16.0, 360.0));
  const int harmonics = std::clamp(options.max_harmonic, 1, std::max(1, bins / 2 - 3));

  // The phases of windows far apart can only be unwrapped once the speed is nearly right (0.2 %
  // slips 95 deg of the first harmonic in 132 turns), so the estimate starts on adjacent windows
  // and spreads them at most kSpreadGrowth times wider at each iteration, out to the whole scan.
  constexpr std::size_t kSpreadGrowth = 8;
  const auto scan_turns = static_cast<std::size_t>(std::max(0.0, NominalTurns(nominal, scan.size())));
  const std::size_t widest = SpreadSpacing(scan_turns);
  std::size_t spacing = 1;
  double rpm = estimate.nominal_rpm;
  double sigma_relative = 0.0;
  for (int iteration = 0; iteration < options.iterations || spacing < widest; ++iteration) {
    if (iteration > 0) spacing = std::min(widest, spacing * kSpreadGrowth);
    const std::vector<TurnHarmonics> turns = FitTurns(scan, z, rpm, bins, harmonics, spacing);
    if (turns.size() < 4) {
      estimate.note = "too few complete turns to estimate the spindle speed; the nominal speed is used";
      return estimate;
    }
    estimate.turns_used = static_cast<int>(turns.size());
    std::vector<int> usable = HarmonicsClearOfTheNoise(turns, harmonics, options);
    const bool only_first = usable.size() == 1 && usable.front() == 1;
    if (!only_first) std::erase(usable, 1);
    if (usable.empty()) {
      estimate.note = "the wheel shows no harmonic clear of the noise; the nominal speed is used";
      return estimate;
    }
    const Drift drift = CombineDrifts(turns, usable);
    sigma_relative = drift.sigma;
    rpm *= 1.0 + drift.delta;
    estimate.harmonics_used = static_cast<int>(usable.size());
    estimate.used_first_harmonic = only_first;
  }
  SetResult(rpm, sigma_relative, options, estimate);
  return estimate;
}

}  // namespace

SpindleSpeedEstimate EstimateSpindleSpeed(const acquisition::Scan& scan, std::span<const double> z_mm,
                                          const SpindleSpeedOptions& options) {
  return EstimateSpeed(scan, z_mm, options);
}

SpindleSpeedEstimate EstimateSpindleSpeed(const acquisition::Scan& scan, std::span<const float> z_mm,
                                          const SpindleSpeedOptions& options) {
  return EstimateSpeed(scan, z_mm, options);
}

}  // namespace arcwheel::processing
