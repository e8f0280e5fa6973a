#pragma once
// `process`'s characteristics (formats.md section 3.3, docs/characteristics.md): every
// toleranceable characteristic of the wheel as one value under a named operator, with u, U, k and,
// where a tolerance names it, the decision. The form characteristics (roundness, run-out, arc
// profile error) come from characteristics/wheel_characteristics.h, their type A from its bootstrap
// and their type B from the uncertainty budget's inputs for the same quantity; the mean arc radius,
// the arc radius range and the arc centre's axial deviation are the least-squares figures with the
// uncertainty stage's value and U. The decisions are made here, once: the report reads them.

#include <nlohmann/json_fwd.hpp>
#include <optional>
#include <string>
#include <vector>

#include "characteristics/wheel_characteristics.h"
#include "uncertainty/decision.h"

namespace arcwheel::fitting {
struct WheelFit;
}
namespace arcwheel::processing {
struct WheelMap;
}
namespace arcwheel::reports {
struct Tolerances;
}
namespace arcwheel::uncertainty {
struct WheelUncertainty;
}

namespace arcwheel::workflows {

struct ProcessPipelineOptions;

// One characteristic as a person reads it.
struct Characteristic {
  std::string name;          // "max_roundness": summary.json's characteristics key
  std::string contract_key;  // "max_roundness_um": the tolerance file's key
  std::string label;         // "max roundness", as the terminal prints it
  std::string unit;          // "um", "mm"
  double value = 0.0;
  double u = 0.0, expanded = 0.0, coverage_factor = 0.0;
  std::string operator_text;  // "RONt, 50 UPR, MZ"
  // The operator as summary.json records it: filter, association, parameter.
  std::optional<double> cutoff_upr, cutoff_mm;
  std::string association;  // "" for run-out (the datum axis)
  std::string parameter;
  std::string where;  // "at y = 1.234 mm", "at phase 12 deg"
  // The same as a number under its key, for a reader: "at_y_mm" or "at_phase_deg" ("" for none).
  std::string at_key;
  double at = 0.0;
  std::optional<uncertainty::Decision> decision;
};

struct CharacteristicsResult {
  std::vector<Characteristic> items;  // in report order
  std::optional<uncertainty::DecisionRule> rule;
  characteristics::WheelCharacteristics form;  // the operators' details (worst section, per node)
  std::vector<std::string> warnings;           // summary.json's warnings, e.g. a cut-off lowered
};

// The operators `process` evaluates: its options' defaults, each replaced by what a tolerance
// names for it. Throws Error{kInvalidOption, "process"} for an operator arcwheel cannot evaluate
// (the tolerance's key named), with `points_per_turn` the map's phases.
// A cut-off of the options that the phases cannot carry is lowered to ISO 12181-2's next, with a
// line in `warnings`.
[[nodiscard]] characteristics::CharacteristicsOptions CharacteristicOperators(
    const ProcessPipelineOptions& options, int points_per_turn, std::vector<std::string>* warnings = nullptr);

// The map as the characteristics' bootstrap takes it: each value's 1-sigma (mm) and the band's
// turns smoothed along the nodes (um; empty where they cannot be). It needs the map and the fits
// only, so `process` makes it while the uncertainty stage runs.
struct SmoothedTurnMap {
  std::vector<double> value_sigma_mm;
  std::vector<double> turn_smooth_um;
};
[[nodiscard]] SmoothedTurnMap SmoothTurnMap(const ProcessPipelineOptions& options,
                                            const processing::WheelMap& map, const fitting::WheelFit& fit);

// The turns' characteristics (roundness, run-out, the worst roundness section) and the smoothed
// map they are taken on: they need the map and the fits only, so `process` evaluates them while the
// uncertainty stage runs.
struct TurnCharacteristics {
  SmoothedTurnMap smoothed;
  characteristics::WheelCharacteristics form;  // arc_profile empty
};
[[nodiscard]] TurnCharacteristics EvaluateTurnCharacteristics(const ProcessPipelineOptions& options,
                                                              const processing::WheelMap& map,
                                                              const fitting::WheelFit& fit,
                                                              double wheel_radius_mm);

// Every characteristic: the turns' (above), the sections' arc profile, which needs the uncertainty
// stage's smoothed fit of the sections, and the least-squares figures with the uncertainty's U.
[[nodiscard]] CharacteristicsResult EvaluateCharacteristics(
    const ProcessPipelineOptions& options, const processing::WheelMap& map, const fitting::WheelFit& fit,
    const uncertainty::WheelUncertainty& uncertainty, double wheel_radius_mm, TurnCharacteristics turns);

// summary.json's "characteristics" object.
[[nodiscard]] nlohmann::json CharacteristicsToJson(const CharacteristicsResult& result);

}  // namespace arcwheel::workflows
