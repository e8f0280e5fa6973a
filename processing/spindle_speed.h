#pragma once
// The spindle speed the data show, for scans without an encoder (formats.md section 1).
//
// A speed error of delta (relative) slips the phase by 360 * delta degrees per turn (0.1 % is
// 36 deg after 100 turns). The wheel's own signature - eccentricity and lobing - returns every
// turn, so the slip shows as a phase of each harmonic that drifts linearly with the turn
// number. Each turn is binned by nominal phase, fitted with a quadratic trend (the arc
// profile passing under the sensor) plus harmonics 1..H, and the drift of each harmonic's phase
// is regressed on the turn number; delta = slope / (360 * h).
//
// A first-harmonic axial wobble of the arc centre also turns the first harmonic's phase along the
// axis, to first order exactly as a speed error would (method.md A, "things learned"). Harmonics
// h >= 2 are therefore used whenever they stand clear of the noise; h = 1 only when nothing else
// does, and the result then says so.

#include <span>
#include <string>
#include <vector>

#include "acquisition/scan.h"

namespace arcwheel::processing {

struct SpindleSpeedOptions {
  int max_harmonic = 12;  // H, 1..60
  // A harmonic is used when its mean amplitude is this many sigmas (>= 0) ...
  double min_harmonic_snr = 8.0;
  // ... and at least this large (a phase needs an amplitude), >= 0.
  double min_harmonic_amplitude_um = 0.05;
  // The estimate replaces the nominal only beyond this many sigmas, >= 0.
  double significance_sigmas = 3.0;
  int iterations = 3;  // re-binning at the improved speed, >= 0
  // Empty when valid, else one line per violation with its value. None of these has a flag of
  // `arcwheel process`: they are named as fields of ProcessOptions ("speed.max_harmonic").
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct SpindleSpeedEstimate {
  double nominal_rpm = 0.0;
  double fitted_rpm = 0.0;  // what the data say
  double sigma_rpm = 0.0;   // 1 sigma of fitted_rpm
  double used_rpm = 0.0;    // fitted_rpm if significant, else nominal_rpm
  bool available = false;   // an estimate was made (enough turns, a usable harmonic)
  bool significant = false;
  bool used_first_harmonic = false;
  int harmonics_used = 0;
  int turns_used = 0;
  std::string note;  // why the estimate could not be made, or caveats
};

// `z_mm` already despiked (NaN = invalid). The scan must have no encoder column.
[[nodiscard]] SpindleSpeedEstimate EstimateSpindleSpeed(const acquisition::Scan& scan,
                                                        std::span<const double> z_mm,
                                                        const SpindleSpeedOptions& options);
[[nodiscard]] SpindleSpeedEstimate EstimateSpindleSpeed(const acquisition::Scan& scan,
                                                        std::span<const float> z_mm,
                                                        const SpindleSpeedOptions& options);

}  // namespace arcwheel::processing
