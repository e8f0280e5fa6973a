#pragma once
// The wheel's form characteristics as a drawing specifies them, each one value under a named
// specification operator (docs/characteristics.md):
//   - roundness (ISO 12181): RONt of the map's turn at each axial node in the band, after the
//     ISO 16610-21 closed-profile Gaussian filter, about the associated reference circle;
//   - circular run-out (ISO 1101): the total indicator reading of the same turn about the datum,
//     the spindle axis (no association: the axis is given), after the same filter;
//   - arc profile error (ISO 1101 profile of a line, the arc with free radius): the peak-to-valley
//     of a phase's section about its associated arc, over the band, optionally after the open-
//     profile Gaussian filter;
// and the wheel's value of each, the largest over the band's nodes (or the phases).
//
// Type A uncertainty: the map's values carry independent noise of a known sigma, so a parametric
// bootstrap re-evaluates the operator on a noise-free estimate of the profiles (the uncertainty
// stage's smoothed fits of the turns and the sections) plus fresh noise. A peak-to-valley of noisy
// points is biased upwards (a filter lowers the bias, it does not remove it): the replicates'
// largest value less the estimate's estimates that bias, and the value is corrected by it; the
// replicates' standard deviation is u. Pure, deterministic for a given seed.

#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "characteristics/association.h"

namespace arcwheel::characteristics {

// How a drawing names a characteristic's operator. Closed profiles take a cut-off in undulations
// per revolution, open ones a cut-off wavelength; nullopt: no filter. Run-out has no association
// (its reference is the datum axis).
struct FormOperator {
  std::optional<double> cutoff_upr = std::nullopt;
  std::optional<double> cutoff_mm = std::nullopt;
  std::optional<Association> association = std::nullopt;
  std::string parameter;  // "RONt", "TIR", "PV"
  // In short, as page 1 and the terminal print it: "RONt, 50 UPR, MZ"; "TIR, 50 UPR, spindle axis".
  [[nodiscard]] std::string Describe() const;
};

// The defaults and their sources (docs/characteristics.md): ISO 12181-2 for roundness (50 UPR,
// minimum zone); run-out with the same filter, as roundness instruments evaluate it (ISO 1101
// names none); the profile of a line by ISO 1101's default association, the minimum zone, without
// a filter (a section holds a few dozen points across the band).
[[nodiscard]] FormOperator DefaultRoundnessOperator();
[[nodiscard]] FormOperator DefaultRunoutOperator();
[[nodiscard]] FormOperator DefaultArcProfileOperator();

// Why `op` cannot be evaluated for the characteristic (a filter of the wrong kind, an association
// that is not defined there), or "" when it can.
[[nodiscard]] std::string RoundnessOperatorProblem(const FormOperator& op, int points_per_turn);
[[nodiscard]] std::string RunoutOperatorProblem(const FormOperator& op, int points_per_turn);
[[nodiscard]] std::string ArcProfileOperatorProblem(const FormOperator& op);

// The measured wheel as the per-phase fits and the map give it.
struct WheelForm {
  // rho(c, y), mm, [n_phase * n_y] row-major by phase (phases equally spaced over a turn), NaN
  // where not covered; the axial nodes; a map value's 1-sigma from the noise.
  std::span<const double> rho_mm{};
  std::span<const double> y_mm{};
  double map_sigma_mm = 0.0;
  // Each map value's own 1-sigma, mm, [n_phase * n_y] as rho_mm (the noise over the root of its
  // cell's samples); empty, or NaN at a value: map_sigma_mm stands for it. A cell of three
  // samples and one of four differ by 15 %: the median alone overstates the noise of the map's
  // maxima and so their bias.
  std::span<const double> rho_sigma_mm{};
  // The radial distance from the spindle axis of rho = 0 (the wheel's radius): a roundness
  // profile is of distances from the axis, and the association's limaçon depends on it (weakly).
  double radius_offset_mm = 0.0;
  double band_low_mm = 0.0, band_high_mm = 0.0;
  // Each phase's least-squares arc (centre, radius) and whether it is usable (1).
  std::span<const double> center_axial_mm{}, center_radial_mm{}, arc_radius_mm{};
  std::span<const char> usable{};
  // The sections' points (fitting::WheelFit::section_*), [n_phase * section_bins]: residual
  // against the phase's arc (um), axial position (mm), 1-sigma (um); NaN where a bin is empty.
  // Without them (section_bins = 0) the map's nodes in the band stand for them.
  int section_bins = 0;
  std::span<const double> section_residual_um{}, section_y_mm{}, section_sigma_um{};
  // The sections' noise-free estimate (um), laid out as their points (the bins, or the map's nodes
  // in the band without them), and the factor the points' sigmas are scaled by to the noise the
  // sections show: the uncertainty stage's fit (WheelUncertainty::smoothed_section_um). Empty: the
  // arc profile's bootstrap starts from the measured points, and its bias comes out far too small.
  std::span<const double> section_smooth_um{};
  double section_sigma_scale = 1.0;
  // The turns' noise-free estimate (um, about rho = 0), [n_band_nodes * n_phase] row-major by the
  // band's nodes in order: the map's harmonics fitted along the nodes (uncertainty::
  // FitNoiseFreeRows). Empty: each turn's significant harmonics alone (SignificantHarmonics), whose
  // noise left in the kept harmonics makes the bootstrap's bias of a maximum over the nodes small.
  std::span<const double> turn_smooth_um{};
};

struct CharacteristicsOptions {
  FormOperator roundness = DefaultRoundnessOperator();
  FormOperator runout = DefaultRunoutOperator();
  FormOperator arc_profile = DefaultArcProfileOperator();
  int replicates = 100;  // >= 20
  std::uint64_t seed = 20261205;
  // Nodes (phases) re-evaluated by the bootstrap: those within this many noise sigmas of the
  // largest value, at most `max_candidates` of them. The rest cannot become the maximum.
  double candidate_sigmas = 8.0;
  int max_candidates = 1000;
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// One characteristic of the wheel: the largest over its nodes of the operator's value.
struct FormCharacteristic {
  FormOperator op;
  double measured_um = 0.0;  // the operator on the measured map
  double bias_um = 0.0;      // the noise's bias of that value, by the bootstrap
  double value_um = 0.0;     // measured - bias, never below zero
  double u_um = 0.0;         // type A: the replicates' standard deviation
  int replicates = 0;
  // Where the largest value is: the axial node (roundness, run-out) or the phase (arc profile).
  int worst_index = -1;
  double worst_at = 0.0;  // y_mm or phase_deg
  // The measured value at every node (phase); NaN where it cannot be evaluated.
  std::vector<double> per_node_um;
};

// The worst section of roundness as the operator sees it, for the report's polar plot.
struct RoundnessSection {
  double y_mm = 0.0;
  std::vector<double> phase_deg;
  std::vector<double> filtered_radius_mm;  // the filtered turn about the spindle axis
  AssociatedCircle reference;
  double ront_um = 0.0, ronp_um = 0.0, ronv_um = 0.0;  // of the filtered turn about the reference
  std::vector<double> harmonic_amplitude_um;           // of the unfiltered turn, element k - 1 = k UPR
};

// One turn (radii about the spindle axis, mm, at equally spaced phases) at axial position y_mm as
// the roundness operator `op` (its filter and association) sees it. Throws as EvaluateRoundness.
[[nodiscard]] RoundnessSection RoundnessSectionOf(std::span<const double> phase_deg,
                                                  std::span<const double> radius_mm, const FormOperator& op,
                                                  double y_mm);

struct WheelCharacteristics {
  FormCharacteristic roundness, runout, arc_profile;
  RoundnessSection worst_roundness_section;
};

// Throws Error{kInvalidOption, "characteristics.wheel"} for invalid options or an operator that
// cannot be evaluated, Error{kBadInput} for arrays of mismatched sizes or no node in the band.
[[nodiscard]] WheelCharacteristics EvaluateWheelCharacteristics(const WheelForm& form,
                                                                const CharacteristicsOptions& options);

// EvaluateWheelCharacteristics in its two parts, for a caller that has the turns' inputs before
// the sections' (`process`: the sections' smoothed fit comes from the uncertainty stage, and the
// turns are evaluated while it runs). The turns' roundness, run-out and worst roundness section
// (arc_profile left empty) read neither section_smooth_um nor section_sigma_scale; the sections'
// arc profile needs them. The same numbers as together, and the same refusals.
[[nodiscard]] WheelCharacteristics EvaluateTurnCharacteristics(const WheelForm& form,
                                                               const CharacteristicsOptions& options);
[[nodiscard]] FormCharacteristic EvaluateArcProfile(const WheelForm& form,
                                                    const CharacteristicsOptions& options);

}  // namespace arcwheel::characteristics
