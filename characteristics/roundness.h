#pragma once
// ISO 12181-1 roundness parameters of a closed profile under a specification operator (ISO
// 12181-2): filtration by the ISO 16610-21 Gaussian filter, association of a reference circle,
// then the parameters as radial distances from the reference circle's centre:
//   RONt peak-to-valley deviation (for the minimum zone, the zone width),
//   RONp largest deviation outward of the reference circle, RONv largest deviation inward (as a
//   positive number), RONq root mean square deviation,
// all from the same reference circle: least squares, inscribed or circumscribed, and for the
// minimum zone the mean circle (inner + outer) / 2.
// Order (formats.md section 8): the radial function r(theta) about the instrument's axis is
// filtered as recorded (no resampling about another centre), the filtered points are associated,
// the parameters taken. The filter attenuates the eccentricity by its transmission at 1 UPR.
// ISO 12181-2's defaults: Gaussian filter 50 UPR, minimum zone.

#include <optional>
#include <span>
#include <string>
#include <vector>

#include "characteristics/association.h"

namespace arcwheel::characteristics {

struct RoundnessOptions {
  // Cut-off of the Gaussian filter in undulations per revolution, > 0 and at most half the number
  // of points; nullopt: no filter.
  std::optional<double> filter_cutoff_upr = 50.0;
  Association association = Association::kMinimumZone;
  // Highest harmonic of the amplitude spectrum, >= 1 (and at most n / 2 - 1 are given).
  int max_harmonic_upr = 500;
  // Empty when valid, else one line per violation: "filter_cutoff_upr = 0 violates > 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The operator that made a value, as a drawing names it.
struct RoundnessOperator {
  std::optional<double> filter_cutoff_upr = std::nullopt;  // nullopt: no filter
  Association association = Association::kMinimumZone;
  // In short, with the parameter: "RONt, 50 UPR, MZ"; "RONt, no filter, LS".
  [[nodiscard]] std::string Describe(std::string_view parameter = "RONt") const;
};

struct RoundnessResult {
  double ront_um = 0.0;
  double ronp_um = 0.0;
  double ronv_um = 0.0;
  double ronq_um = 0.0;
  // The reference circle of the filtered profile, its centre relative to the instrument's axis.
  AssociatedCircle reference;
  RoundnessOperator op;
  // Amplitude of harmonic k of the unfiltered radial function at element k - 1, k = 1 ..
  // min(n / 2 - 1, max_harmonic_upr), um (k = 1 holds the eccentricity).
  std::vector<double> harmonic_amplitude_um;
  std::vector<double> filtered_radius_mm;  // the profile the reference was associated to
};

// ISO 12181-1's parameters of points (x, y, mm) about their reference circle, um.
struct RoundnessParameters {
  double ront_um = 0.0;
  double ronp_um = 0.0;
  double ronv_um = 0.0;
  double ronq_um = 0.0;
};
[[nodiscard]] RoundnessParameters ParametersAbout(const AssociatedCircle& reference,
                                                  std::span<const double> x_mm, std::span<const double> y_mm);

// Whether the angles of a closed profile are equally spaced over one turn (any start, either
// direction): every step within 1 % of 360 / n deg and the steps adding up to one turn.
struct AngleSpacing {
  bool equally_spaced = false;
  double expected_step_deg = 0.0;  // 360 / n, signed as the angles run
  double turn_deg = 0.0;           // what the steps add up to (+-360 for one turn)
  // The step that differs most from the expected one: from angle[largest_gap_index] to the next
  // (cyclically), and its size.
  int largest_gap_index = 0;
  double largest_gap_deg = 0.0;
};
[[nodiscard]] AngleSpacing CheckAngleSpacing(std::span<const double> angle_deg);

// The roundness of the closed profile (angle_deg[i], radius_mm[i]): radius_mm is the radial
// distance from the instrument's axis at that angle. Throws Error{kInvalidOption,
// "characteristics.roundness"} for invalid options or a cut-off above n / 2, Error{kBadInput} for
// fewer than 8 points, angles not equally spaced over one turn, or radii not positive and finite,
// Error{kFitFailed} when the reference circle cannot be certified.
[[nodiscard]] RoundnessResult EvaluateRoundness(std::span<const double> angle_deg,
                                                std::span<const double> radius_mm,
                                                const RoundnessOptions& options);

}  // namespace arcwheel::characteristics
