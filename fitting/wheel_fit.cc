#include "fitting/wheel_fit.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <span>
#include <utility>

#include "core/check.h"
#include "core/dense.h"
#include "core/error.h"
#include "core/free_memory.h"
#include "core/interrupt.h"
#include "core/nan.h"
#include "core/parallel.h"
#include "fitting/circle_fit.h"

namespace arcwheel::fitting {
namespace {

constexpr const char* kWheelFitStage = "fitting";

// What the means and their sigmas need of one phase's fit. Of the circle's sensitivities only
// the two rows the sigmas of the means propagate are kept (8 MB at 1e8 samples instead of 17).
struct PhaseSolution {
  PhaseFit fit;
  std::vector<std::uint32_t> points;  // the section's points in the fit, by index
  // Rows: d(centre axial)/d(rho_k), d(radius)/d(rho_k) for the points in that order.
  Eigen::Matrix<double, 2, Eigen::Dynamic> sensitivity;
};
constexpr int kAxialRow = 0;
constexpr int kRadiusRow = 1;

// The section's covariance from the points' own sigmas (noise along rho, independent between
// turns) through the fit's first-order sensitivity: C = S diag(sigma^2) S^T; chi2 with the same
// sigmas. Left as FitCircle gave it when a sigma is not positive.
void PropagatePointSigmas(std::span<const double> y, std::span<const double> rho,
                          std::span<const double> sigma, CircleFit& circle) {
  if (!std::all_of(sigma.begin(), sigma.end(), [](double s) { return s > 0; })) return;
  Eigen::VectorXd variance(static_cast<Eigen::Index>(sigma.size()));
  for (std::size_t k = 0; k < sigma.size(); ++k) variance(static_cast<Eigen::Index>(k)) = sigma[k] * sigma[k];
  circle.covariance = circle.sensitivity_to_y * variance.asDiagonal() * circle.sensitivity_to_y.transpose();
  double chi2 = 0.0;
  for (std::size_t k = 0; k < y.size(); ++k) {
    const double e =
        std::hypot(y[k] - circle.center_mm.x(), rho[k] - circle.center_mm.y()) - circle.radius_mm;
    chi2 += e * e / variance(static_cast<Eigen::Index>(k));
  }
  circle.chi2 = chi2;
}

// Copies a usable circle into the phase fit; flags it when the radius is not determined.
void SetPhaseFit(const CircleFit& c, PhaseFit& fit) {
  fit.center_axial_mm = c.center_mm.x();
  fit.center_radial_mm = c.center_mm.y();
  fit.arc_radius_mm = c.radius_mm;
  fit.center_axial_sigma_mm = std::sqrt(c.covariance(0, 0));
  fit.center_radial_sigma_mm = std::sqrt(c.covariance(1, 1));
  fit.arc_radius_sigma_mm = std::sqrt(c.covariance(2, 2));
  fit.arc_error_um = c.pv_residual_mm * 1000.0;
  fit.chi2_per_dof = fit.points > 3 ? c.chi2 / (fit.points - 3) : 0.0;
  if (!std::isfinite(fit.arc_radius_sigma_mm) || fit.arc_radius_sigma_mm > 0.1 * fit.arc_radius_mm) {
    fit.flag = "ill-conditioned: the radius is not determined";
    return;
  }
  fit.usable = true;
}

// Fits the section's points with |y - center| <= half (all points for FitSpan::kFull).
PhaseSolution FitSection(const processing::Section& section, double center_mm, double half_mm, bool full,
                         const WheelFitOptions& options) {
  ARCWHEEL_CHECK(section.y_mm.size() <= UINT32_MAX) << section.y_mm.size() << " section points";
  PhaseSolution out;
  std::vector<double> y, rho, sigma;
  for (std::size_t k = 0; k < section.y_mm.size(); ++k) {
    if (!full && std::abs(section.y_mm[k] - center_mm) > half_mm) continue;
    y.push_back(section.y_mm[k]);
    rho.push_back(section.rho_mm[k]);
    sigma.push_back(section.sigma_mm[k]);
    out.points.push_back(static_cast<std::uint32_t>(k));
  }
  PhaseFit& fit = out.fit;
  fit.points = static_cast<int>(y.size());
  if (fit.points < options.min_points) {
    fit.flag = fmt::format("too few points in the band ({})", fit.points);
    return out;
  }
  const double extent = y.back() - y.front();
  if (!full && extent < options.min_band_coverage * 2.0 * half_mm) {
    fit.flag = fmt::format("the section covers {:.3g} mm of the {:.3g} mm band", extent, 2.0 * half_mm);
    return out;
  }
  // The section's circle is the unweighted geometric least-squares circle (formats.md 3.1).
  CircleFit circle = FitCircle(y, rho, {}, options.circle);
  if (!circle.IsUsable()) {
    fit.flag = circle.message;
    return out;
  }
  PropagatePointSigmas(y, rho, sigma, circle);
  SetPhaseFit(circle, fit);
  if (fit.usable) {
    out.sensitivity.resize(2, circle.sensitivity_to_y.cols());
    out.sensitivity.row(kAxialRow) = circle.sensitivity_to_y.row(0);
    out.sensitivity.row(kRadiusRow) = circle.sensitivity_to_y.row(2);
  }
  return out;
}

// Variance of the mean of parameter `row` (kAxialRow, kRadiusRow) over the usable phases,
// exactly through the helix spline (neighbouring phases share spline coefficients, so their
// errors correlate); for a map without one, from the phases' own sigmas.
double SigmaOfMean(const std::vector<PhaseSolution>& solutions, int row, const processing::WheelMap& map) {
  int usable = 0;
  for (const auto& s : solutions) usable += s.fit.usable ? 1 : 0;
  if (!map.spline) {
    // Sections of their own samples (a line-profile scan's frames): the phases' errors are
    // independent, so the mean's variance is the sum of theirs over n^2.
    double variance = 0.0;
    for (const PhaseSolution& s : solutions) {
      if (!s.fit.usable) continue;
      const double sigma = row == kRadiusRow ? s.fit.arc_radius_sigma_mm : s.fit.center_axial_sigma_mm;
      variance += sigma * sigma;
    }
    return usable > 0 ? std::sqrt(variance) / usable : 0.0;
  }
  const double factor = map.spline->CovarianceFactorOfSum([&](const processing::HelixSpline::TermSink& add) {
    for (std::size_t j = 0; j < solutions.size(); ++j) {
      const PhaseSolution& s = solutions[j];
      if (!s.fit.usable) continue;
      const std::vector<double>& u_deg = map.sections[j].u_deg;
      for (std::size_t k = 0; k < s.points.size(); ++k) {
        add(u_deg[s.points[k]], s.sensitivity(row, static_cast<Eigen::Index>(k)) / usable);
      }
    }
  });
  return map.noise_sigma_mm * std::sqrt(std::max(0.0, factor));
}

// cos and sin of each phase, computed once for all the axial nodes.
struct PhaseHarmonic {
  double cos = 0.0, sin = 0.0;
};

std::vector<PhaseHarmonic> PhaseHarmonics(const processing::WheelMap& map) {
  std::vector<PhaseHarmonic> out(map.n_phase());
  for (std::size_t j = 0; j < out.size(); ++j) {
    const double c = map.phase_deg[j] * std::numbers::pi / 180.0;
    out[j] = {std::cos(c), std::sin(c)};
  }
  return out;
}

// Peak-to-valley after removing mean and first harmonic (least squares) over the phases given.
double Roundness(const std::vector<PhaseHarmonic>& phase, const std::vector<double>& rho) {
  const auto n = static_cast<Eigen::Index>(rho.size());
  Eigen::MatrixXd design(n, 3);
  Eigen::VectorXd values(n);
  for (Eigen::Index i = 0; i < n; ++i) {
    design(i, 0) = 1.0;
    design(i, 1) = phase[static_cast<std::size_t>(i)].cos;
    design(i, 2) = phase[static_cast<std::size_t>(i)].sin;
    values(i) = rho[static_cast<std::size_t>(i)];
  }
  const Eigen::VectorXd residual = values - design * dense::ColPivQrSolve(design, values);
  return residual.maxCoeff() - residual.minCoeff();
}

// Fits every phase whose index is j = k * step (k = 0, 1, ...) with the band centred on
// band_center_mm; the others are left unfitted. The phases are independent: two workers take
// alternate ones.
void FitPhases(const processing::WheelMap& map, double band_center_mm, std::size_t step,
               const WheelFitOptions& options, std::vector<PhaseSolution>& solutions) {
  const bool full = options.fit_span == FitSpan::kFull;
  const std::size_t n_phase = map.n_phase();
  constexpr int kWorkers = 2;
  RunOnWorkers(kWorkers, [&](int worker) {
    for (std::size_t j = static_cast<std::size_t>(worker) * step; j < n_phase; j += kWorkers * step) {
      solutions[j] = FitSection(map.sections[j], band_center_mm, options.band_half_width_mm, full, options);
    }
  });
}

// Mean arc-centre axial position over the usable phases. Throws Error{kFitFailed} if none is usable.
double MeanCenterAxialOfUsable(const std::vector<PhaseSolution>& solutions) {
  double sum_a = 0.0;
  int usable = 0;
  for (const PhaseSolution& solution : solutions) {
    if (solution.fit.usable) {
      sum_a += solution.fit.center_axial_mm;
      ++usable;
    }
  }
  if (usable == 0) {
    const std::string why = !solutions.empty() ? solutions[0].fit.flag : "no phases";
    throw Error(ErrorCode::kFitFailed, kWheelFitStage,
                "no phase gave a usable arc fit (phase 0: " + why + ")");
  }
  return sum_a / usable;
}

struct CenteredFits {
  std::vector<PhaseSolution> solutions;
  double used_center_mm = 0.0;  // the centre of the band the final fits used
  double mean_center_mm = 0.0;  // the mean arc centre those fits found
};

// Pass 1 centres the band on the middle of the scanned span; pass 2 on the mean arc centre.
CenteredFits FitPhasesInCenteredBand(const processing::WheelMap& map, const WheelFitOptions& options) {
  const std::size_t n_phase = map.n_phase();
  CenteredFits out;
  out.solutions.resize(n_phase);
  double band_center = 0.5 * (map.y_mm.front() + map.y_mm.back());
  for (int pass = 0; pass < 2; ++pass) {
    out.used_center_mm = band_center;
    ThrowIfInterrupted();
    // Pass 1 only centres the band, for which every 8th phase is plenty.
    const std::size_t step = pass == 0 && n_phase >= 64 ? 8 : 1;
    if (pass == 1 || step > 1) {
      for (auto& solution : out.solutions) solution = PhaseSolution{};
    }
    FitPhases(map, band_center, step, options, out.solutions);
    band_center = MeanCenterAxialOfUsable(out.solutions);
  }
  out.mean_center_mm = band_center;
  return out;
}

// The band the fits used, clipped to the scanned span. Throws Error{kBadInput} if nothing is left.
void SetBand(const processing::WheelMap& map, const CenteredFits& fits, const WheelFitOptions& options,
             WheelFit& out) {
  const double y_min = map.y_mm.front();
  const double y_max = map.y_mm.back();
  const double half = options.band_half_width_mm;
  out.band_low_mm = std::max(fits.used_center_mm - half, y_min);
  out.band_high_mm = std::min(fits.used_center_mm + half, y_max);
  if (!(out.band_high_mm > out.band_low_mm)) {
    throw Error(ErrorCode::kBadInput, kWheelFitStage,
                fmt::format("the band {:.4g} +- {:.4g} mm lies outside the scanned span [{:.4g}, {:.4g}] mm",
                            fits.mean_center_mm, half, y_min, y_max));
  }
  if (out.band_high_mm - out.band_low_mm < 2.0 * half - 1e-9 && options.fit_span != FitSpan::kFull) {
    out.warnings.push_back(fmt::format("the band was clipped to [{:.4f}, {:.4f}] mm by the scanned span",
                                       out.band_low_mm, out.band_high_mm));
  }
}

// Copies the phase fits into `out` and sets the means, spreads and sigmas over the usable ones.
void SummarisePhases(const std::vector<PhaseSolution>& solutions, const processing::WheelMap& map,
                     WheelFit& out) {
  for (const auto& s : solutions) out.phases.push_back(s.fit);
  SummariseUsablePhases(out);
  out.mean_arc_radius_sigma_mm = SigmaOfMean(solutions, kRadiusRow, map);
  out.mean_center_axial_sigma_mm = SigmaOfMean(solutions, kAxialRow, map);
}

bool InBand(double y_mm, const WheelFit& fit) {
  return y_mm >= fit.band_low_mm - 1e-9 && y_mm <= fit.band_high_mm + 1e-9;
}

// Runout and roundness over the map's axial nodes in the band.
void SetRunoutAndRoundness(const processing::WheelMap& map, const WheelFitOptions& options, WheelFit& out) {
  const std::size_t n_phase = map.n_phase();
  const std::vector<PhaseHarmonic> harmonics = PhaseHarmonics(map);
  std::vector<PhaseHarmonic> phase;
  std::vector<double> rho;
  for (std::size_t m = 0; m < map.n_y(); ++m) {
    const double y = map.y_mm[m];
    if (!InBand(y, out)) continue;
    phase.clear();
    rho.clear();
    for (std::size_t j = 0; j < n_phase; ++j) {
      if (std::isfinite(map.rho(j, m))) {
        phase.push_back(harmonics[j]);
        rho.push_back(map.rho(j, m));
      }
    }
    out.axial_y_mm.push_back(y);
    if (static_cast<double>(rho.size()) < options.min_phase_coverage * static_cast<double>(n_phase) ||
        rho.size() < 4) {
      out.runout_um.push_back(kNaN);
      out.roundness_um.push_back(kNaN);
      continue;
    }
    const auto [lo, hi] = std::minmax_element(rho.begin(), rho.end());
    out.runout_um.push_back((*hi - *lo) * 1000.0);
    out.roundness_um.push_back(Roundness(phase, rho) * 1000.0);
    out.max_runout_um = std::max(out.max_runout_um, out.runout_um.back());
    out.max_roundness_um = std::max(out.max_roundness_um, out.roundness_um.back());
  }
}

// Mean deviation of the sections from their own circles at each axial node in the band.
void SetProfileError(const processing::WheelMap& map, WheelFit& out) {
  for (std::size_t m = 0; m < map.n_y(); ++m) {
    const double y = map.y_mm[m];
    if (!InBand(y, out)) continue;
    double sum = 0.0;
    int count = 0;
    for (std::size_t j = 0; j < map.n_phase(); ++j) {
      const PhaseFit& f = out.phases[j];
      const double u = y - f.center_axial_mm;
      if (!f.usable || !std::isfinite(map.rho(j, m)) || std::abs(u) >= f.arc_radius_mm) continue;
      sum += map.rho(j, m) - (f.center_radial_mm + std::sqrt(f.arc_radius_mm * f.arc_radius_mm - u * u));
      ++count;
    }
    out.profile_u_mm.push_back(y - out.mean_center_axial_mm);
    out.profile_error_um.push_back(count > 0 ? sum / count * 1000.0 : kNaN);
  }
}

// The map minus the mean wheel (the circle of mean radius and centre), over the whole map.
void SetFormError(const processing::WheelMap& map, WheelFit& out) {
  const std::size_t n_phase = map.n_phase();
  const std::size_t n_y = map.n_y();
  out.form_error_um.assign(n_phase * n_y, kNaN);
  const double R = out.mean_arc_radius_mm;
  for (std::size_t m = 0; m < n_y; ++m) {
    const double u = map.y_mm[m] - out.mean_center_axial_mm;
    if (std::abs(u) >= R) continue;
    const double mean_wheel = out.mean_center_radial_mm + std::sqrt(R * R - u * u);
    for (std::size_t j = 0; j < n_phase; ++j) {
      out.form_error_um[j * n_y + m] = (map.rho(j, m) - mean_wheel) * 1000.0;
    }
  }
}

}  // namespace

std::vector<std::string> WheelFitOptions::Problems() const {
  std::vector<std::string> problems;
  if (!(band_half_width_mm > 0))
    problems.push_back(fmt::format("--band-half-width-mm = {} violates > 0", band_half_width_mm));
  if (min_points < 4) problems.push_back(fmt::format("--min-points = {} violates >= 4", min_points));
  if (!(min_band_coverage >= 0 && min_band_coverage <= 1))
    problems.push_back(fmt::format("min_band_coverage = {} violates 0..1", min_band_coverage));
  if (!(min_phase_coverage > 0 && min_phase_coverage <= 1))
    problems.push_back(fmt::format("min_phase_coverage = {} violates (0, 1]", min_phase_coverage));
  for (const std::string& p : circle.Problems()) problems.push_back("circle." + p);
  return problems;
}

WheelFit FitWheel(const processing::WheelMap& map, const WheelFitOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kWheelFitStage, options.Problems());
  WheelFit out;
  {
    const CenteredFits fits = FitPhasesInCenteredBand(map, options);
    SetBand(map, fits, options, out);
    SummarisePhases(fits.solutions, map, out);
  }  // the fits' sensitivities go before the map-wide arrays below are made
  ReturnFreedMemory();
  SetMapMetrics(map, options, out);
  return out;
}

void SetMapMetrics(const processing::WheelMap& map, const WheelFitOptions& options, WheelFit& fit) {
  SetRunoutAndRoundness(map, options, fit);
  SetProfileError(map, fit);
  SetFormError(map, fit);
}

}  // namespace arcwheel::fitting
