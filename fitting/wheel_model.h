#pragma once
// The wheel model: one least-squares fit of every valid sample in the band (docs/wheel_model.md),
//   rho(c, y) = b(c) + sqrt(Ra(c)^2 - (y - a(c))^2) + p(y - a(c)),
// in the contract's frame (formats.md 1). Ra(c), a(c) and b(c) are periodic cubic B-splines in
// the phase c; p(u) is the profile error common to all phases, a cubic B-spline in u = y - a(c)
// held orthogonal to 1, u and u^2 over the band (zero mean, zero least-squares slope and
// curvature), so that it cannot trade off against b, a and Ra.
//
// The per-phase fits see each phase's section alone, so profile noise reaches each phase's radius
// amplified some 60 times; the model shares every sample between the few coefficients that the
// data support, and says with a chi-square test whether Ra(c) varies at all.

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include "fitting/wheel_fit.h"
#include "processing/helix_geometry.h"
#include "processing/wheel_map.h"

namespace arcwheel::fitting {

struct WheelModelOptions {
  // Knots per turn of Ra(c), a(c) and b(c) (b carries the runout): 1 (Ra and a only) is a
  // constant, 4..360 a periodic cubic spline, 0 chosen by the Bayesian information criterion from
  // kKnotChoices (and 1 for Ra and a).
  int radius_knots = 0;
  int axial_knots = 0;
  int runout_knots = 0;
  double profile_knot_step_mm = 0.5;  // knot spacing of p(u)
  int max_iterations = 40;            // Gauss-Newton iterations per fit
  double significance_level = 0.01;   // of the test "Ra(c) varies"
  int harmonics = 8;                  // radius harmonics reported (at most radius_knots / 2)
  // Size of the warm-up subsample (one sample out of every run of N / warm_start_samples, N the
  // scan's size), on which the finest knots' fit converges before the passes over every sample;
  // 0 (or a scan under 4 times this size) skips it, so that every Gauss-Newton iteration passes
  // over every sample. Either way the result is the least-squares optimum over every sample.
  std::size_t warm_start_samples = 100000;
  // On a scan of more samples than this whose phase and axial position follow from its settings
  // (no time, axial or encoder column), the fit runs on per-cell moments of the samples (a cell: a
  // run of samples on one turn within one knot interval) after one pass over them, and the
  // residual map takes one more: the normal equations are then exact to second order in the
  // cell's length (docs/wheel_model.md, "Binned fit", states the error). The maximum never bins.
  std::size_t binned_above_samples = 500000;
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The knot counts the model chooses from: nested (each refines the one before), so that one fit
// at the finest serves to compare them all.
inline constexpr int kKnotChoices[] = {4, 8, 16, 32, 64};

// amplitude * cos(order * c + phase_deg) in Ra(c), with 1-sigma uncertainties.
struct RadiusHarmonic {
  int order = 0;
  double amplitude_um = 0, amplitude_sigma_um = 0;
  double phase_deg = 0, phase_sigma_deg = 0;
};

struct WheelModel {
  bool fitted = false;
  int radius_knots = 0, axial_knots = 0, runout_knots = 0, profile_coefficients = 0;
  bool knots_chosen = false;  // by the information criterion (else as given)
  double band_low_mm = 0, band_high_mm = 0;
  double center_axial_reference_mm = 0;  // mean a, the band's centre
  std::size_t samples = 0;               // samples in the band that the fit used
  int parameters = 0;                    // free parameters (the constraints on p taken off)
  int iterations = 0;                    // Gauss-Newton passes (binned: over the cells), warm-up aside
  double residual_rms_um = 0;            // of the fit, against the scan's noise estimate:
  double noise_sigma_um = 0;
  double mean_arc_radius_mm = 0, mean_arc_radius_sigma_mm = 0;  // the mean of Ra(c) over a turn
  // max - min of Ra(c) over the phase grid, and its 1-sigma.
  double arc_radius_range_mm = 0, arc_radius_range_sigma_mm = 0;
  // Wald test of "Ra(c) is constant": chi-square with radius_knots - 1 degrees of freedom (at 4
  // knots when the information criterion chose a constant Ra).
  double variation_chi2 = 0, variation_p_value = 1;
  int variation_dof = 0;
  double significance_level = 0.01;
  bool variation_significant = false;
  std::vector<RadiusHarmonic> radius_harmonics;
  double profile_pv_um = 0;
  // The model on the map's phase grid, with 1-sigma.
  std::vector<double> phase_deg;
  std::vector<double> arc_radius_mm, arc_radius_sigma_mm;
  std::vector<double> center_axial_mm, center_axial_sigma_mm;
  std::vector<double> center_radial_mm, center_radial_sigma_mm;
  // p(u) over the band, with 1-sigma.
  std::vector<double> profile_u_mm, profile_error_um, profile_error_sigma_um;
  // Mean residual of the samples in each cell of the map's (phase, axial) grid, um; NaN where
  // a cell holds none. [n_phase * n_y], row-major by phase.
  std::vector<double> residual_um;
  // The coefficients [Ra knots, a knots, b knots, p coefficients] and their covariance
  // (row-major, size^2); p's coefficients are those of its B-spline, constraints applied.
  std::vector<double> coefficients, covariance;
};

// Fits the model to rho_mm (per sample, NaN = invalid, as the map was built from) over the band
// of `fit`, starting from its mean circle. Throws Error{kInvalidOption} for bad options and
// Error{kFitFailed} when the band holds too few samples or the fit does not converge.
// Float samples are read as they are (no widened copy); the arithmetic is in double. Nothing is
// allocated per sample. The work is split into a fixed number of parts, so the result does not
// depend on the number of cores.
[[nodiscard]] WheelModel FitWheelModel(std::span<const double> rho_mm,
                                       const processing::HelixGeometry& geometry,
                                       const processing::WheelMap& map, const WheelFit& fit,
                                       const WheelModelOptions& options);
[[nodiscard]] WheelModel FitWheelModel(std::span<const float> rho_mm,
                                       const processing::HelixGeometry& geometry,
                                       const processing::WheelMap& map, const WheelFit& fit,
                                       const WheelModelOptions& options);

}  // namespace arcwheel::fitting
