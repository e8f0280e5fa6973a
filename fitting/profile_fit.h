#pragma once
// The per-phase arc fits of a line-profile scan's sections (processing/profile_sections.h), with
// sigmas from the sections' own residuals (docs/processing.md, "Line-profile scans").
//
// A section point averages a few frames' readings, and besides the noise it carries the wheel's
// texture (grit) between those frames' phases, which the frames of one phase on later turns repeat
// and which neighbouring columns share. Neither is seen by the spread of the readings alone. So each
// section point's sigma is set to what the residuals show, the pooled spread of the residuals against each
// phase's circle after the profile that every phase shares (the wheel's profile error, the same at each
// phase) is taken out, times the square root of the residuals' long-run correlation factor along the axis (1
// + 2 sum of their autocorrelations, summed while positive); the fits' covariances follow it.

#include "fitting/wheel_fit.h"
#include "processing/wheel_map.h"

namespace arcwheel::fitting {

struct ProfileResiduals {
  double sigma_mm = 0.0;          // pooled spread of the residuals, the shared profile taken out
  double correlation_factor = 1;  // 1 + 2 sum of the autocorrelations (>= 1 for positively correlated)
  int correlation_lags = 0;       // lags summed
  double point_sigma_mm = 0.0;    // the section points' sigma set: sigma * sqrt(factor)
};

// Fits `map` (FitWheel), sets every section point's sigma and map.map_sigma_mm as above, and gives
// the fit the covariances those sigmas make (the circles are unweighted, so only the sigmas
// change). Throws as FitWheel.
[[nodiscard]] WheelFit FitProfileWheel(processing::WheelMap& map, const WheelFitOptions& options,
                                       ProfileResiduals* residuals = nullptr);

}  // namespace arcwheel::fitting
