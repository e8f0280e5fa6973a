// The headline figures over the usable phases, for the all-sample fit (sample_fit.cc) and the
// spline sections' fit (wheel_fit.cc) alike.

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "core/check.h"
#include "core/statistics.h"
#include "fitting/wheel_fit.h"

namespace arcwheel::fitting {

void SummariseUsablePhases(WheelFit& out) {
  std::vector<double> radii, axial, radial, sigmas, chi2;
  for (const PhaseFit& fit : out.phases) {
    if (!fit.usable) continue;
    radii.push_back(fit.arc_radius_mm);
    axial.push_back(fit.center_axial_mm);
    radial.push_back(fit.center_radial_mm);
    sigmas.push_back(fit.arc_radius_sigma_mm);
    chi2.push_back(fit.chi2_per_dof);
    out.max_arc_error_um = std::max(out.max_arc_error_um, fit.arc_error_um);
  }
  ARCWHEEL_CHECK(!radii.empty()) << "no usable phase to summarise";
  const auto n = static_cast<double>(radii.size());
  out.usable_phases = static_cast<int>(radii.size());
  out.mean_arc_radius_mm = Mean(radii);
  out.mean_center_axial_mm = Mean(axial);
  out.mean_center_radial_mm = Mean(radial);
  const auto [r_min, r_max] = std::minmax_element(radii.begin(), radii.end());
  out.arc_radius_range_mm = *r_max - *r_min;
  out.arc_radius_fluctuation_pct = out.arc_radius_range_mm / out.mean_arc_radius_mm * 100.0;
  const auto [a_min, a_max] = std::minmax_element(axial.begin(), axial.end());
  out.center_axial_deviation_mm = *a_max - *a_min;
  double var = 0.0, noise = 0.0;
  for (std::size_t k = 0; k < radii.size(); ++k) {
    var += (radii[k] - out.mean_arc_radius_mm) * (radii[k] - out.mean_arc_radius_mm);
    noise += sigmas[k] * sigmas[k];
  }
  out.arc_radius_std_mm = std::sqrt(var / std::max(1.0, n - 1.0));
  out.arc_radius_noise_std_mm = std::sqrt(noise / n);
  out.arc_radius_excess_std_mm =
      std::sqrt(std::max(0.0, out.arc_radius_std_mm * out.arc_radius_std_mm -
                                  out.arc_radius_noise_std_mm * out.arc_radius_noise_std_mm));
  out.median_chi2_per_dof = Median(chi2);
  const std::size_t n_phase = out.phases.size();
  if (out.usable_phases < static_cast<int>(n_phase)) {
    out.warnings.push_back(fmt::format("{} of {} phases were not usable and are left out of the means",
                                       n_phase - static_cast<std::size_t>(out.usable_phases), n_phase));
  }
}

}  // namespace arcwheel::fitting
