#pragma once
// The budget file of `arcwheel process --uncertainty budget.json` (docs/uncertainty.md): type B
// inputs for each headline quantity of summary.json, by its key. Stage id "uncertainty.budget".
//
//   {"coverage_probability": 0.95,               // optional, (0, 1)
//    "truncate_dof": true,                       // optional: nu_eff rounded down (GUM G.4.1)
//    "quantities": {
//      "mean_arc_radius_mm": [
//        {"name": "axial_scale", "source": "machine Y axis, +-1 um over the 16 mm band",
//         "unit": "ppm", "distribution": "rectangular", "half_width": 62.5,
//         "sensitivity": 1.109e-4, "sensitivity_unit": "mm/ppm"}],
//      "max_runout_um": [
//        {"name": "sensor_scale", "source": "certificate", "unit": "ppm",
//         "distribution": "normal", "expanded": 400, "k": 2, "sensitivity": "relative"},
//        {"name": "resolution", "source": "data sheet", "unit": "um",
//         "distribution": "rectangular", "half_width": 0.005}]}}
//
// An input: "name" (unique in its quantity), "source", "unit", "distribution" (normal,
// rectangular, triangular, arcsine), its spread ("sigma", or "expanded" with "k", for normal;
// "half_width" for the others), optional "value" (the correction's estimate, 0), "sensitivity"
// (c_i, 1; or "relative": c_i = the measured value per unit of a dimensionless input, for a scale
// error), "sensitivity_unit" ("<quantity unit>/<input unit>", needed when the input's unit is
// not of the quantity's kind), "dof" (infinite) and "type" ("A" or "B").
// Units: mm, um, nm (lengths), % (the fluctuation), 1, ppm (dimensionless), K, degC, deg, rad,
// 1/K. The quantity's unit is its key's suffix (_mm, _um, _pct).

#include <filesystem>
#include <map>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>
#include <vector>

#include "uncertainty/budget.h"

namespace arcwheel::uncertainty {

struct BudgetInput {
  Input input{};
  // The sensitivity is input.sensitivity times the measured value (a scale error).
  bool relative = false;
};

struct BudgetFile {
  CombineOptions combine{};
  // Type B inputs by summary.json key of the headline quantity.
  std::map<std::string, std::vector<BudgetInput>> quantities{};
};

// The keys a budget may name and their units: mean_arc_radius_mm (mm), arc_radius_range_mm,
// arc_radius_fluctuation_pct (%), center_axial_deviation_mm, max_arc_error_um (um),
// max_runout_um, max_roundness_um.
[[nodiscard]] const std::vector<std::string>& BudgetQuantityKeys();
// "mm", "um" or "%" for a key of BudgetQuantityKeys(); "" for another.
[[nodiscard]] std::string QuantityUnit(std::string_view key);

// The inputs with their sensitivities resolved for a measured `value` of the quantity.
[[nodiscard]] std::vector<Input> ResolveInputs(const std::vector<BudgetInput>& inputs, double value);

// Parses a budget file's text; `name` stands for the file. Throws Error{kInvalidOption,
// "uncertainty.budget"} naming every problem at once, "<quantity>.<input>.<field> = <value>
// violates <rule>" (a negative or non-finite spread, an unknown distribution, a unit that does not
// match its quantity, an unknown key), or naming the file for text that is not JSON.
[[nodiscard]] BudgetFile ParseBudget(std::string_view text, const std::string& name);
// Reads a budget file. Throws Error{kIo} if it cannot be read, else as ParseBudget.
[[nodiscard]] BudgetFile ReadBudget(const std::filesystem::path& path);

// The budget as a budget file spells it (ParseBudget reads it back).
[[nodiscard]] nlohmann::json BudgetToJson(const BudgetFile& budget);

}  // namespace arcwheel::uncertainty
