#include "fitting/profile_fit.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <vector>

namespace arcwheel::fitting {
namespace {

// Longest lag of the autocorrelation sum, in section points.
constexpr int kMaxLags = 200;

// Each usable phase's residuals against its circle in the band, by point, NaN outside it.
std::vector<std::vector<double>> BandResiduals(const processing::WheelMap& map, const WheelFit& fit) {
  std::vector<std::vector<double>> residuals(map.n_phase());
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    const PhaseFit& f = fit.phases[j];
    if (!f.usable) continue;
    const processing::Section& s = map.sections[j];
    residuals[j].assign(s.y_mm.size(), std::nan(""));
    for (std::size_t k = 0; k < s.y_mm.size(); ++k) {
      if (s.y_mm[k] < fit.band_low_mm || s.y_mm[k] > fit.band_high_mm) continue;
      residuals[j][k] =
          std::hypot(s.y_mm[k] - f.center_axial_mm, s.rho_mm[k] - f.center_radial_mm) - f.arc_radius_mm;
    }
  }
  return residuals;
}

// Takes out the mean residual at each axial position (bins of the median point spacing): the
// profile every phase shares.
void RemoveSharedProfile(const processing::WheelMap& map, std::vector<std::vector<double>>& residuals) {
  std::vector<double> spacing;
  for (std::size_t j = 0; j < map.n_phase() && spacing.size() < 4096; ++j) {
    const auto& y = map.sections[j].y_mm;
    for (std::size_t k = 1; k < y.size(); ++k) spacing.push_back(y[k] - y[k - 1]);
  }
  std::nth_element(spacing.begin(), spacing.begin() + static_cast<long>(spacing.size() / 2), spacing.end());
  const double bin =
      spacing.empty() || !(spacing[spacing.size() / 2] > 0) ? 1.0 : spacing[spacing.size() / 2];
  std::map<long, std::pair<double, int>> profile;
  const auto key = [&](double y) { return std::lround(y / bin); };
  for (std::size_t j = 0; j < residuals.size(); ++j) {
    for (std::size_t k = 0; k < residuals[j].size(); ++k) {
      if (!std::isfinite(residuals[j][k])) continue;
      auto& [sum, count] = profile[key(map.sections[j].y_mm[k])];
      sum += residuals[j][k];
      ++count;
    }
  }
  for (std::size_t j = 0; j < residuals.size(); ++j) {
    for (std::size_t k = 0; k < residuals[j].size(); ++k) {
      if (!std::isfinite(residuals[j][k])) continue;
      const auto& [sum, count] = profile[key(map.sections[j].y_mm[k])];
      residuals[j][k] -= sum / count;
    }
  }
}

ProfileResiduals Spread(const std::vector<std::vector<double>>& residuals) {
  ProfileResiduals out;
  double ss = 0.0, n = 0.0;
  for (const auto& r : residuals) {
    for (const double e : r) {
      if (!std::isfinite(e)) continue;
      ss += e * e;
      n += 1.0;
    }
  }
  out.sigma_mm = n > 0 ? std::sqrt(ss / n) : 0.0;
  if (!(ss > 0)) return out;
  double sum = 0.0;
  for (int lag = 1; lag <= kMaxLags; ++lag) {
    double products = 0.0, pairs = 0.0;
    for (const auto& r : residuals) {
      for (std::size_t k = static_cast<std::size_t>(lag); k < r.size(); ++k) {
        if (!std::isfinite(r[k]) || !std::isfinite(r[k - static_cast<std::size_t>(lag)])) continue;
        products += r[k] * r[k - static_cast<std::size_t>(lag)];
        pairs += 1.0;
      }
    }
    const double rho = pairs > 0 ? (products / pairs) / (ss / n) : 0.0;
    if (!(rho > 0.0)) break;
    sum += rho;
    out.correlation_lags = lag;
  }
  out.correlation_factor = 1.0 + 2.0 * sum;
  out.point_sigma_mm = out.sigma_mm * std::sqrt(out.correlation_factor);
  return out;
}

// Every sigma of `fit` from points of sigma s0, for points of sigma s0 * scale: the covariances
// are s^2 S S^T (wheel_fit.cc), so the phases' sigmas scale by `scale` and chi-square by its
// inverse square; the means' sigmas (independent phases) scale as the phases'.
void ScaleSigmas(double scale, WheelFit& fit) {
  for (PhaseFit& phase : fit.phases) {
    phase.arc_radius_sigma_mm *= scale;
    phase.center_axial_sigma_mm *= scale;
    phase.center_radial_sigma_mm *= scale;
    phase.chi2_per_dof /= scale * scale;
  }
  const std::vector<std::string> warnings = fit.warnings;
  SummariseUsablePhases(fit);
  fit.warnings = warnings;
  fit.mean_arc_radius_sigma_mm *= scale;
  fit.mean_center_axial_sigma_mm *= scale;
}

}  // namespace

WheelFit FitProfileWheel(processing::WheelMap& map, const WheelFitOptions& options,
                         ProfileResiduals* residuals) {
  // The circles are unweighted (formats.md 3.1): the points' sigmas only scale the covariances, so
  // one fit with a common sigma, rescaled, is the fit with the residuals' sigma.
  const double provisional = map.noise_sigma_mm > 0 ? map.noise_sigma_mm : 1e-3;
  for (processing::Section& section : map.sections) {
    std::fill(section.sigma_mm.begin(), section.sigma_mm.end(), provisional);
  }
  WheelFit fit = FitWheel(map, options);
  std::vector<std::vector<double>> e = BandResiduals(map, fit);
  RemoveSharedProfile(map, e);
  const ProfileResiduals spread = Spread(e);
  if (residuals != nullptr) *residuals = spread;
  if (!(spread.point_sigma_mm > 0)) return fit;
  for (processing::Section& section : map.sections) {
    std::fill(section.sigma_mm.begin(), section.sigma_mm.end(), spread.point_sigma_mm);
  }
  map.map_sigma_mm = spread.point_sigma_mm;
  ScaleSigmas(spread.point_sigma_mm / provisional, fit);
  return fit;
}

}  // namespace arcwheel::fitting
