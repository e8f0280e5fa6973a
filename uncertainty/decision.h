#pragma once
// Conformity decisions for a measured value with its expanded uncertainty against a
// specification, after ISO 14253-1:2017 ("Geometrical product specifications (GPS) - Inspection
// by measurement of workpieces and measuring equipment - Part 1: Decision rules for verifying
// conformity or nonconformity with specifications"). Stage id "uncertainty.decision".
//
// kIso14253 (the standard's default rule, clause 5): conformance is proven when the whole
// interval value +- U lies inside the specification zone [min, max] (the conformance zone is the
// specification zone shrunk by U at each limit); nonconformance is proven when the whole interval
// lies outside it (the value is more than U beyond a limit); otherwise neither is proven.
// kSimpleAcceptance (shared risk, by agreement between supplier and customer, ISO 14253-1 clause
// 5 note and ILAC-G8 "simple acceptance"): the value itself decides, min <= value <= max, its
// uncertainty not added; nothing is left unproven.

#include <optional>
#include <span>
#include <string_view>

namespace arcwheel::uncertainty {

enum class DecisionRule { kIso14253, kSimpleAcceptance };
// "iso14253-1" and "simple-acceptance": the names a tolerance file's "decision_rule" uses.
[[nodiscard]] std::string_view DecisionRuleName(DecisionRule rule);
// The rule a name stands for; nullopt for an unknown name.
[[nodiscard]] std::optional<DecisionRule> DecisionRuleFromName(std::string_view name);
// How a report names the rule: "ISO 14253-1:2017 default rule (uncertainty against the
// specification)" and "shared risk: simple acceptance (value against the limit, uncertainty not
// added)".
[[nodiscard]] std::string_view DecisionRuleTitle(DecisionRule rule);

enum class Decision { kConforms, kDoesNotConform, kNotProven };
// "conforms", "does not conform", "not proven": summary.json and the report.
[[nodiscard]] std::string_view DecisionName(Decision decision);

// A specification zone, one- or two-sided: min and/or max, inclusive (ISO 14253-1 3.6).
struct Specification {
  std::optional<double> min = std::nullopt;
  std::optional<double> max = std::nullopt;
};

struct DecisionOptions {
  DecisionRule rule = DecisionRule::kIso14253;
};

// The decision for `value` with expanded uncertainty `expanded` (U, >= 0, same unit) against
// `specification` (at least one limit). Under kIso14253 a value or U that could not be computed
// (not finite) proves nothing (kNotProven); under kSimpleAcceptance a value that could not be
// computed does not conform, and U is not used.
[[nodiscard]] Decision Decide(double value, double expanded, const Specification& specification,
                              const DecisionOptions& options = {});

// The decision over several toleranced quantities: kDoesNotConform if any does not conform, else
// kNotProven if any is not proven, else kConforms. Empty input: nullopt (nothing toleranced).
[[nodiscard]] std::optional<Decision> Overall(std::span<const Decision> decisions);

}  // namespace arcwheel::uncertainty
