#pragma once
// Per-phase arc fits and the wheel's metrics (method.md A.5-A.6, formats.md 3.1).

#include <string>
#include <vector>

#include "fitting/circle_fit_options.h"
#include "processing/wheel_map.h"

namespace arcwheel::fitting {

enum class FitSpan { kBand, kFull };

struct WheelFitOptions {
  double band_half_width_mm = 8.0;  // > 0
  FitSpan fit_span = FitSpan::kBand;
  int min_points = 8;               // a phase with fewer points in the band is flagged
  double min_band_coverage = 0.6;   // fraction of the band's width the points must span
  double min_phase_coverage = 0.9;  // fraction of phases a runout/roundness node needs
  CircleFitOptions circle;          // each section's circle fit; a fit that does not converge is flagged
  // Empty when valid, else one line per violation with its value, named by the flag of
  // `arcwheel process` ("--min-points = 3 violates >= 4") or, without one, by its field here
  // ("min_band_coverage", "circle.max_iterations").
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct PhaseFit {
  double arc_radius_mm = 0, arc_radius_sigma_mm = 0;
  double center_axial_mm = 0, center_axial_sigma_mm = 0;
  double center_radial_mm = 0, center_radial_sigma_mm = 0;
  double arc_error_um = 0;  // PV of geometric residuals in the band
  double chi2_per_dof = 0;  // weighted residuals: ~1 when the section is a circle plus noise
  int points = 0;
  bool usable = false;
  std::string flag;  // empty when usable
};

struct WheelFit {
  std::vector<PhaseFit> phases;
  double mean_arc_radius_mm = 0, mean_arc_radius_sigma_mm = 0;
  double arc_radius_range_mm = 0, arc_radius_fluctuation_pct = 0;
  double arc_radius_std_mm = 0, arc_radius_noise_std_mm = 0, arc_radius_excess_std_mm = 0;
  double mean_center_axial_mm = 0, mean_center_axial_sigma_mm = 0, center_axial_deviation_mm = 0;
  double mean_center_radial_mm = 0;
  double band_low_mm = 0, band_high_mm = 0;
  double max_arc_error_um = 0, max_runout_um = 0, max_roundness_um = 0;
  double median_chi2_per_dof = 0;
  int usable_phases = 0;
  // Over the map's axial nodes in the band.
  std::vector<double> axial_y_mm, runout_um, roundness_um;
  // Mean deviation of the sections from their own circles, u = y - mean_center_axial_mm.
  std::vector<double> profile_u_mm, profile_error_um;
  // rho minus the mean wheel (circle of mean radius and centre), um, [n_phase * n_y].
  std::vector<double> form_error_um;
  // The sections' points (the all-sample fit, fitting/sample_fit.h; empty from FitWheel): each
  // phase's runs in the band, gathered in section_bins equal axial bins over it, [n_phase *
  // section_bins]: their mean geometric residual against the phase's circle (um), mean axial
  // position (mm) and the residual's 1-sigma from the noise (um); NaN where a bin holds no run.
  int section_bins = 0;
  std::vector<double> section_residual_um, section_y_mm, section_sigma_um;
  std::vector<std::string> warnings;
};

// Throws Error{kFitFailed} when no phase gives a usable fit, kBadInput when the band lies
// outside the scanned span. A map without a helix spline (a line-profile scan's sections,
// processing/profile_sections.h) has sections that share no samples: the sigmas of the means are
// then the phases' own, combined as independent.
[[nodiscard]] WheelFit FitWheel(const processing::WheelMap& map, const WheelFitOptions& options);

// The headline figures over the usable phases of fit.phases (method.md A.6): their count, the
// means, the arc radius's range, fluctuation and standard deviations (of the fits, of the noise and
// the excess beyond it), the arc centre's axial deviation, the median chi-square per degree of
// freedom, the largest arc error, and a warning when some phases are left out. At least one phase
// must be usable. The sigmas of the means are the caller's: they depend on whether the phases
// share samples.
void SummariseUsablePhases(WheelFit& fit);

// Runout and roundness at the map's axial nodes in the band, the mean profile error and the form
// error, for a fit whose phases, means and band are already set (FitWheel's last steps; the
// all-sample fit, fitting/sample_fit.h, uses them on its own map).
void SetMapMetrics(const processing::WheelMap& map, const WheelFitOptions& options, WheelFit& fit);

}  // namespace arcwheel::fitting
