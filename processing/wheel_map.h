#pragma once
// The wheel map (method.md A.3-A.4): the helix spline sampled at every phase node on every
// turn (the "sections", which the arc fits use), and those sections interpolated along the axis
// onto a regular (phase, axial) grid (the map, which runout, roundness and the report use).

#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "core/stage_clock.h"
#include "processing/helix_geometry.h"
#include "processing/helix_spline.h"

namespace arcwheel::processing {

struct MapOptions {
  int phases = 360;            // phase nodes 0, 360/phases, ...; 4..36000
  double knot_step_deg = 0.0;  // helix spline knot spacing; <= 0: 360/phases, widened to >= 2.5 samples
  double axial_step_mm = 0.0;  // map node spacing; <= 0: one helix pitch
  int min_support = 2;         // a section point needs this many valid samples within its two knot intervals
  double max_sigma_ratio = 1.5;  // ... and a sigma at most this many times the median point's; >= 1
  // Empty when valid, else one line per violation with its value, named by the flag of
  // `arcwheel process` ("--phases = 2 violates 4..36000") or, without one, by its ProcessOptions
  // path ("map.min_support").
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The helix points at one phase node, ordered by axial position.
struct Section {
  std::vector<double> y_mm;
  std::vector<double> rho_mm;
  std::vector<double> sigma_mm;  // 1-sigma of rho from the measurement noise
  std::vector<double> u_deg;     // unwrapped phase of each point on the helix
};

struct WheelMap {
  std::vector<double> phase_deg;    // [n_phase]
  std::vector<double> y_mm;         // [n_y]
  std::vector<double> rho_mm;       // [n_phase * n_y], row-major by phase; NaN where not covered
  std::vector<int> sample_count;    // valid samples per cell
  std::vector<int> despiked_count;  // despiked samples per cell
  std::vector<Section> sections;    // [n_phase]
  double noise_sigma_mm = 0.0;      // per-sample noise used for the sigmas
  // The typical 1-sigma of a section point: the median over every section's points
  // (summary.json's map_sigma_um); 0 when there is none. Kept when the sections are let go.
  double map_sigma_mm = 0.0;
  double knot_step_deg = 0.0;
  double axial_step_mm = 0.0;
  double pitch_mm = 0.0;
  std::shared_ptr<const HelixSpline> spline;  // kept for exact propagation of the noise

  [[nodiscard]] std::size_t n_phase() const { return phase_deg.size(); }
  [[nodiscard]] std::size_t n_y() const { return y_mm.size(); }
  [[nodiscard]] double rho(std::size_t phase, std::size_t axial) const {
    return rho_mm[phase * n_y() + axial];
  }
};

// `rho_mm` per sample (NaN = invalid), already despiked. `despiked` lists rejected samples.
// `clock`, when given, times the steps.
[[nodiscard]] WheelMap BuildWheelMap(std::span<const double> rho_mm, const HelixGeometry& geometry,
                                     double noise_sigma_mm, std::span<const std::size_t> despiked,
                                     const MapOptions& options, StageClock* clock = nullptr);
[[nodiscard]] WheelMap BuildWheelMap(std::span<const float> rho_mm, const HelixGeometry& geometry,
                                     double noise_sigma_mm, std::span<const std::size_t> despiked,
                                     const MapOptions& options, StageClock* clock = nullptr);

// The map's nodes without their values, for the sample fit to estimate (fitting/sample_fit.h):
// the phase and axial nodes over the axial span that every phase node covers (CommonAxialSpan in
// the .cc), the coverage counts, rho_mm all NaN, no sections, no spline.
[[nodiscard]] WheelMap PlanWheelMap(std::span<const double> rho_mm, const HelixGeometry& geometry,
                                    double noise_sigma_mm, std::span<const std::size_t> despiked,
                                    const MapOptions& options, StageClock* clock = nullptr);
[[nodiscard]] WheelMap PlanWheelMap(std::span<const float> rho_mm, const HelixGeometry& geometry,
                                    double noise_sigma_mm, std::span<const std::size_t> despiked,
                                    const MapOptions& options, StageClock* clock = nullptr);

}  // namespace arcwheel::processing
