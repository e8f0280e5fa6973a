#pragma once
// Tolerances for the headline numbers of a wheel report, and the pass/fail verdict against them.
//
// Tolerance file (JSON object), keyed by the summary.json name of the headline quantity:
//   {"max_arc_error_um": 3.0,                                 // a number: the upper limit
//    "mean_arc_radius_mm": {"min": 74.95, "max": 75.05},      // or an object with min and/or max
//    "max_runout_um": {"max": 10},
//    "max_roundness_um": {"max": 2.0, "filter_upr": 50, "association": "minimum-zone"}}
// A form tolerance (max_roundness_um, max_runout_um, max_arc_error_um) may name its operator:
// "filter_upr" (roundness, run-out), "filter_cutoff_mm" (arc error), "filter": "none", and
// "association" (roundness, arc error); the decision is then made under it.
// Keys: mean_arc_radius_mm, arc_radius_range_mm, arc_radius_fluctuation_pct,
// center_axial_deviation_mm, max_arc_error_um, max_runout_um, max_roundness_um.
// Command-line form of one limit: "KEY=MAX" or "KEY=MIN:MAX" (either side of ':' may be empty).
// The optional key "decision_rule" names the rule (uncertainty/decision.h): "iso14253-1" (the
// default when the summary records uncertainties: conformance proven when value +- U lies inside
// the limits, nonconformance when it lies outside, else not proven) or "simple-acceptance" (shared
// risk: the estimate, noise-corrected for a PV, against the limits, its U not added). For a summary
// without uncertainties a value passes when
// min <= value <= max (limits inclusive, value as recorded in summary.json, its uncertainty not
// added); a value that could not be computed (null) fails any limit.

#include <array>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>

#include "schema/summary.h"
#include "uncertainty/decision.h"

namespace arcwheel::reports {

// The operator a drawing names with a form tolerance (docs/characteristics.md), as the file
// gives it; what it leaves out is process's default. Only max_roundness_um, max_runout_um and
// max_arc_error_um take one.
struct NamedOperator {
  std::optional<double> filter_upr = std::nullopt;        // "filter_upr": K (closed profiles)
  std::optional<double> filter_cutoff_mm = std::nullopt;  // "filter_cutoff_mm": L (open profiles)
  bool no_filter = false;                                 // "filter": "none"
  std::optional<std::string> association = std::nullopt;  // "association": "minimum-zone", ...
  [[nodiscard]] bool Empty() const { return !filter_upr && !filter_cutoff_mm && !no_filter && !association; }
};

struct Limit {
  std::optional<double> min = std::nullopt;
  std::optional<double> max = std::nullopt;
};

// The headline quantities, in report order.
inline constexpr std::array<std::string_view, 7> kHeadlineKeys = {
    schema::summary::kMeanArcRadiusMm,         schema::summary::kArcRadiusRangeMm,
    schema::summary::kArcRadiusFluctuationPct, schema::summary::kCenterAxialDeviationMm,
    schema::summary::kMaxArcErrorUm,           schema::summary::kMaxRunoutUm,
    schema::summary::kMaxRoundnessUm};

struct Tolerances {
  std::map<std::string, Limit> limits;             // by headline key; absent = no tolerance
  std::map<std::string, NamedOperator> operators;  // by headline key, where the limit names one
  // "decision_rule" as the file names it; absent = ISO 14253-1 where uncertainties are recorded.
  std::optional<uncertainty::DecisionRule> rule = std::nullopt;
};

// kNotProven: by ISO 14253-1, neither conformance nor nonconformance is proven.
enum class Verdict { kPass, kFail, kNoTolerance, kNotProven };

// Verdict of one value against an optional limit (see the file comment for the rule).
[[nodiscard]] Verdict Judge(double value, const std::optional<Limit>& limit);

// Parses a tolerance file's text; `name` stands for the file in messages. Throws
// Error{kBadInput} naming the file and key for invalid JSON, an unknown key, a non-numeric limit
// or min > max.
[[nodiscard]] Tolerances ParseTolerances(const std::string& text, const std::string& name);
// Reads a tolerance file. Throws Error{kIo} if it cannot be read, else as ParseTolerances.
[[nodiscard]] Tolerances ReadTolerances(const std::filesystem::path& path);
// Adds (or replaces) one limit given as "KEY=MAX" or "KEY=MIN:MAX". Throws
// Error{kInvalidOption} quoting the text when it does not parse or names an unknown key.
void AddToleranceFlag(Tolerances& tolerances, const std::string& flag);

}  // namespace arcwheel::reports
