#include "processing/spindle_speed.h"

#include <Eigen/Dense>
#include <cmath>
#include <complex>
#include <numbers>
#include <vector>

#include "core/check.h"
#include "processing/helix_geometry.h"

namespace arcwheel::processing {
namespace {

using Complex = std::complex<double>;

struct TurnHarmonics {
  double turn = 0.0;               // turn index
  std::vector<Complex> amplitude;  // Q_h = A_h - i B_h, h = 1..H
  double residual_sigma = 0.0;     // rms of the per-bin fit residual
};

// Bins every turn by phase at `rpm`, and fits each well-filled turn with
// p0 + p1 s + p2 s^2 + sum_h (A_h cos(h theta) + B_h sin(h theta)).
std::vector<TurnHarmonics> FitTurns(const acquisition::Scan& scan, std::span<const double> z, double rpm,
                                    int bins, int harmonics) {
  const HelixGeometry geometry(scan, rpm);
  const double u0 = geometry.PhaseAt(0);
  const auto turns = static_cast<std::size_t>(std::floor((geometry.PhaseAt(scan.size() - 1) - u0) / 360.0)) + 1;
  const auto nb = static_cast<std::size_t>(bins);
  std::vector<double> sum(turns * nb, 0.0);
  std::vector<int> count(turns * nb, 0);
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (!std::isfinite(z[i])) continue;
    const double turn_position = (geometry.PhaseAt(i) - u0) / 360.0;
    const auto k = static_cast<std::size_t>(turn_position);
    const auto b = std::min(nb - 1, static_cast<std::size_t>((turn_position - static_cast<double>(k)) * bins));
    sum[k * nb + b] += z[i];
    ++count[k * nb + b];
  }
  const int parameters = 3 + 2 * harmonics;
  const auto design_row = [&](std::size_t b, auto&& row) {
    const double s = (static_cast<double>(b) + 0.5) / bins;
    const double theta = 2.0 * std::numbers::pi * s;
    row(0) = 1.0;
    row(1) = s - 0.5;
    row(2) = (s - 0.5) * (s - 0.5);
    for (int h = 1; h <= harmonics; ++h) {
      row(1 + 2 * h) = std::cos(h * theta);
      row(2 + 2 * h) = std::sin(h * theta);
    }
  };
  // Most turns have every bin filled: their least-squares solution is one precomputed matrix.
  Eigen::MatrixXd full_design(static_cast<Eigen::Index>(nb), parameters);
  for (std::size_t b = 0; b < nb; ++b) design_row(b, full_design.row(static_cast<Eigen::Index>(b)));
  const Eigen::MatrixXd full_solver = full_design.completeOrthogonalDecomposition().pseudoInverse();

  std::vector<TurnHarmonics> result;
  for (std::size_t k = 0; k < turns; ++k) {
    std::vector<std::size_t> filled;
    for (std::size_t b = 0; b < nb; ++b) {
      if (count[k * nb + b] > 0) filled.push_back(b);
    }
    if (filled.size() < 0.9 * static_cast<double>(nb)) continue;
    const auto rows = static_cast<Eigen::Index>(filled.size());
    Eigen::VectorXd values(rows);
    for (Eigen::Index r = 0; r < rows; ++r) {
      const std::size_t b = filled[static_cast<std::size_t>(r)];
      values(r) = sum[k * nb + b] / count[k * nb + b];
    }
    Eigen::VectorXd p;
    double rss = 0.0;
    if (filled.size() == nb) {
      p = full_solver * values;
      rss = (full_design * p - values).squaredNorm();
    } else {
      Eigen::MatrixXd design(rows, parameters);
      for (Eigen::Index r = 0; r < rows; ++r) design_row(filled[static_cast<std::size_t>(r)], design.row(r));
      p = design.colPivHouseholderQr().solve(values);
      rss = (design * p - values).squaredNorm();
    }
    TurnHarmonics turn;
    turn.turn = static_cast<double>(k);
    turn.residual_sigma = std::sqrt(rss / std::max<double>(1.0, static_cast<double>(rows - parameters)));
    for (int h = 1; h <= harmonics; ++h) turn.amplitude.emplace_back(p(1 + 2 * h), -p(2 + 2 * h));
    result.push_back(std::move(turn));
  }
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

}  // namespace

SpindleSpeedEstimate EstimateSpindleSpeed(const acquisition::Scan& scan, std::span<const double> z,
                                          const SpindleSpeedOptions& options) {
  ARCWHEEL_CHECK(!scan.has_encoder()) << "speed estimation needs a scan without an encoder";
  SpindleSpeedEstimate estimate;
  estimate.nominal_rpm = *scan.metadata.spindle_rpm;
  estimate.fitted_rpm = estimate.used_rpm = estimate.nominal_rpm;

  const HelixGeometry nominal(scan, estimate.nominal_rpm);
  const double samples_per_turn = scan.size() / std::max(1.0, (nominal.PhaseAt(scan.size() - 1) - nominal.PhaseAt(0)) / 360.0);
  const int bins = static_cast<int>(std::clamp(samples_per_turn / 2.0, 16.0, 360.0));
  const int harmonics = std::clamp(options.max_harmonic, 1, std::max(1, bins / 2 - 3));

  double rpm = estimate.nominal_rpm;
  double sigma_relative = 0.0;
  for (int iteration = 0; iteration < options.iterations; ++iteration) {
    const std::vector<TurnHarmonics> turns = FitTurns(scan, z, rpm, bins, harmonics);
    if (turns.size() < 4) {
      estimate.note = "too few complete turns to estimate the spindle speed; the nominal speed is used";
      return estimate;
    }
    estimate.turns_used = static_cast<int>(turns.size());
    // Noise of one harmonic amplitude: per-bin residual sigma * sqrt(2 / bins).
    double residual = 0.0;
    for (const auto& t : turns) residual += t.residual_sigma * t.residual_sigma;
    const double amplitude_sigma = std::sqrt(residual / static_cast<double>(turns.size()) * 2.0 / bins);
    std::vector<int> usable;
    for (int h = 1; h <= harmonics; ++h) {
      double mean_amplitude = 0.0;
      for (const auto& t : turns) mean_amplitude += std::abs(t.amplitude[static_cast<std::size_t>(h - 1)]);
      mean_amplitude /= static_cast<double>(turns.size());
      if (mean_amplitude > options.min_harmonic_snr * amplitude_sigma) usable.push_back(h);
    }
    const bool only_first = usable.size() == 1 && usable.front() == 1;
    if (!only_first) std::erase(usable, 1);
    if (usable.empty()) {
      estimate.note = "the wheel shows no harmonic clear of the noise; the nominal speed is used";
      return estimate;
    }
    double weight_sum = 0.0;
    double weighted = 0.0;
    for (const int h : usable) {
      const Drift d = PhaseDrift(turns, h);
      const double w = 1.0 / std::max(d.sigma * d.sigma, 1e-30);
      weight_sum += w;
      weighted += w * d.delta;
    }
    const double delta = weighted / weight_sum;
    sigma_relative = std::sqrt(1.0 / weight_sum);
    rpm *= 1.0 + delta;
    estimate.harmonics_used = static_cast<int>(usable.size());
    estimate.used_first_harmonic = only_first;
  }
  estimate.available = true;
  estimate.fitted_rpm = rpm;
  estimate.sigma_rpm = sigma_relative * rpm;
  estimate.significant = std::abs(rpm - estimate.nominal_rpm) > options.significance_sigmas * estimate.sigma_rpm;
  estimate.used_rpm = estimate.significant ? rpm : estimate.nominal_rpm;
  if (estimate.used_first_harmonic) {
    estimate.note =
        "only the first harmonic (eccentricity) was usable: an axial wobble of the arc centre cannot be told "
        "from a speed error with it";
  }
  return estimate;
}

}  // namespace arcwheel::processing
