#pragma once
// The processing stage end to end: raw Scan -> WheelMap (method.md A.2-A.4, A.7).
//   1. the valid span (invalid ends trimmed),
//   2. noise from second differences, 3. despiking,
//   4. beam-offset correction (optional), 5. spindle speed (encoder, estimate, or nominal),
//   6. the wheel map: from the helix spline's sections (ProcessScan), or its nodes alone, for the
//      sample fit to estimate (ProcessScanInPlace, the `process` path).

#include <cstddef>
#include <string>
#include <vector>

#include "acquisition/scan.h"
#include "core/stage_clock.h"
#include "processing/despike.h"
#include "processing/helix_geometry.h"
#include "processing/spindle_speed.h"
#include "processing/stuck_readings.h"
#include "processing/wheel_map.h"

namespace arcwheel::processing {

enum class RpmSource { kAuto, kNominal, kEncoder, kEstimate };

struct ProcessOptions {
  DespikeOptions despike;
  SpindleSpeedOptions speed;
  // kAuto: the encoder when there is one, else the estimate when significant, else nominal.
  RpmSource rpm_source = RpmSource::kAuto;
  MapOptions map;
  // Lateral offset of the sensor's beam from the wheel axis (method.md A.7); 0 = none.
  double beam_offset_mm = 0.0;
  // Wheel radius at the arc apex, for the beam-offset correction; <= 0: from the scan's
  // wheel_diameter_mm.
  double wheel_radius_mm = 0.0;
  // Runs of exactly equal readings lasting this much of a turn (and at least 16 samples) are a
  // stuck sensor and are dropped (processing/stuck_readings.h); 0 keeps them.
  double stuck_run_deg = 20.0;
  // Every problem of the nested options and of these, one line each with its value, named as
  // `arcwheel process` spells the option (see DespikeOptions::Problems).
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct ProcessedScan {
  std::size_t samples = 0;
  std::size_t valid_samples = 0;  // before despiking
  std::size_t first_valid = 0;    // the trimmed span [first_valid, last_valid]
  std::size_t last_valid = 0;
  StuckReadingsResult stuck;
  DespikeResult despike;
  double noise_sigma_mm = 0.0;
  SpindleSpeedEstimate speed;  // filled when estimated
  PhaseSource phase_source = PhaseSource::kNominal;
  double rpm_used = 0.0;
  WheelMap map;
  std::vector<std::string> warnings;
  StageClock timings;  // wall time of each step above
};

// Throws Error{kInvalidOption} for bad options, kBadInput for scans that cannot be mapped.
// Takes the scan by value: its readings become the radial coordinate in place (a 1e7-sample scan
// is processed within about twice its own size). Move the scan in when it is not needed after.
[[nodiscard]] ProcessedScan ProcessScan(acquisition::Scan scan, const ProcessOptions& options);

// The `process` path: as ProcessScan up to the map, whose nodes and coverage counts it lays out
// (PlanWheelMap) and whose values it leaves to the per-phase fits of every sample
// (fitting::FitWheelToSamples), the one estimate of them. The radial coordinate (despiked; NaN
// where invalid) stays in the scan's readings (z_float_mm or z_mm, see acquisition::VisitReadings)
// for those fits and the wheel model's (fitting/wheel_model.h).
[[nodiscard]] ProcessedScan ProcessScanInPlace(acquisition::Scan& scan, const ProcessOptions& options);

}  // namespace arcwheel::processing
