#pragma once
// The uncertainty of every headline figure of a wheel scan (docs/uncertainty.md): type A from
// the data (the fit's sigma of the mean arc radius; for each peak-to-valley figure the
// noise-corrected estimate and its bootstrap spread, noise_corrected.h), type B from a budget
// (budget_json.h, default_budget.h), combined per GUM (budget.h). Stage id "uncertainty.wheel".
// The inputs are plain arrays, filled by the process pipeline from its per-phase fits and map.

#include <map>
#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "uncertainty/budget.h"
#include "uncertainty/budget_json.h"
#include "uncertainty/decision.h"
#include "uncertainty/noise_corrected.h"

namespace arcwheel::uncertainty {

// What the per-phase fits and the map give, as formats.md 3.1 defines it.
struct WheelObservations {
  // Headline figures as summary.json records them (the contract's raw figures).
  double mean_arc_radius_mm = 0.0;
  double mean_arc_radius_sigma_mm = 0.0;
  double arc_radius_range_mm = 0.0;
  double arc_radius_fluctuation_pct = 0.0;
  double center_axial_deviation_mm = 0.0;
  double max_arc_error_um = 0.0;
  double max_runout_um = 0.0;
  double max_roundness_um = 0.0;
  // Per phase node (equally spaced over a turn); NaN or not usable = no fit at that phase.
  std::span<const double> arc_radius_mm{}, arc_radius_sigma_mm{};
  std::span<const double> center_axial_mm{}, center_axial_sigma_mm{};
  std::span<const double> center_radial_mm{};
  std::span<const char> usable{};  // 1 = usable
  // The map rho(c, y), mm, [n_phase * n_y] row-major by phase, NaN where not covered; its nodes;
  // the typical 1-sigma of a map value from the noise; the band.
  std::span<const double> rho_mm{};
  std::span<const double> y_mm{};
  double map_sigma_mm = 0.0;
  double band_low_mm = 0.0, band_high_mm = 0.0;
  // The sections' points (fitting::WheelFit::section_*), [n_phase * section_bins], NaN where none:
  // residual against the phase's circle (um), axial position (mm), 1-sigma (um). Without them
  // (section_bins = 0) the map's nodes in the band stand for them, with the map's sigma.
  int section_bins = 0;
  std::span<const double> section_residual_um{}, section_y_mm{}, section_sigma_um{};
};

struct WheelUncertaintyOptions {
  // Highest harmonic tried over a turn (range, centre deviation, runout, roundness). >= 1.
  int max_harmonic = 24;
  // Highest Legendre degree tried across the band (arc error). >= 1.
  int max_degree = 10;
  int replicates = 100;  // bootstrap data sets, >= 20 (u to about 7 %: 99 degrees of freedom)
  // The bootstrap's seed, mixed with a digest of the observations: the same scan gives the same
  // numbers, two scans independent draws.
  std::uint64_t seed = 20261203;
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct QuantityUncertainty {
  std::string key;        // summary.json key
  std::string unit;       // "mm", "um", "%"
  double measured = 0.0;  // the headline figure as recorded
  // The estimate a decision uses: the measured mean, or the noise-corrected PV; plus the budget's
  // corrections.
  double value = 0.0;
  double noise_bias = 0.0;  // PV figures: measured - noise-corrected
  std::string type_a_method;
  std::vector<Input> inputs;  // type A first, then the budget's
  Combined combined;
};

// One toleranced quantity's decision: its specification and what the rule made of value +- U.
struct ConformityDecision {
  std::string key;  // summary.json key
  Specification specification;
  Decision decision = Decision::kNotProven;
};

struct WheelUncertainty {
  std::string budget_source = "default";
  BudgetFile budget;
  std::vector<QuantityUncertainty> quantities;  // in BudgetQuantityKeys() order
  // With tolerances (DecideConformity): the rule and a decision per toleranced quantity.
  std::optional<DecisionRule> rule = std::nullopt;
  std::vector<ConformityDecision> decisions;
  // The sections as the arc error's estimator fits them (NoiseCorrectedPv::fitted_rows): the
  // noise-free estimate of each section's residual (um) at its points, [n_phase * columns] as the
  // section points lie (WheelObservations::section_*, or the map's nodes in the band); empty when
  // there is no estimate. And the factor the estimator scaled the points' sigmas by (Birge ratio).
  std::vector<double> smoothed_section_um;
  double section_sigma_scale = 1.0;
  // The quantity by key; nullptr if absent.
  [[nodiscard]] const QuantityUncertainty* Find(std::string_view key) const;
};

// Throws Error{kInvalidOption} for bad options or budget inputs, Error{kBadInput} for arrays of
// mismatched sizes.
[[nodiscard]] WheelUncertainty EvaluateWheelUncertainty(const WheelObservations& observations,
                                                        const BudgetFile& budget,
                                                        const WheelUncertaintyOptions& options = {});

// Decides every quantity that `specifications` (by summary.json key) tolerances by `rule`, with
// the value and U the evaluation gave (Decide), into uncertainty.rule and uncertainty.decisions;
// the report's page 1 decides the same way. Throws Error{kBadInput} for a key that is not a
// quantity of the budget.
void DecideConformity(WheelUncertainty& uncertainty,
                      const std::map<std::string, Specification>& specifications, DecisionRule rule);

// summary.json's "uncertainty" object (schema/summary.h, namespace uncertainty).
[[nodiscard]] nlohmann::json WheelUncertaintyToJson(const WheelUncertainty& uncertainty);

}  // namespace arcwheel::uncertainty
