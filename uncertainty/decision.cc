#include "uncertainty/decision.h"

#include <algorithm>
#include <cmath>

#include "core/check.h"

namespace arcwheel::uncertainty {

std::string_view DecisionRuleName(DecisionRule rule) {
  return rule == DecisionRule::kIso14253 ? "iso14253-1" : "simple-acceptance";
}

std::optional<DecisionRule> DecisionRuleFromName(std::string_view name) {
  if (name == "iso14253-1") return DecisionRule::kIso14253;
  if (name == "simple-acceptance") return DecisionRule::kSimpleAcceptance;
  return std::nullopt;
}

std::string_view DecisionRuleTitle(DecisionRule rule) {
  return rule == DecisionRule::kIso14253
             ? "ISO 14253-1:2017 default rule (uncertainty against the specification)"
             : "shared risk: simple acceptance (value against the limit, uncertainty not added)";
}

std::string_view DecisionName(Decision decision) {
  switch (decision) {
    case Decision::kConforms:
      return "conforms";
    case Decision::kDoesNotConform:
      return "does not conform";
    case Decision::kNotProven:
      return "not proven";
  }
  return "unknown";
}

Decision Decide(double value, double expanded, const Specification& specification,
                const DecisionOptions& options) {
  ARCWHEEL_CHECK(specification.min || specification.max) << "a specification without limits";
  const double low = specification.min.value_or(-INFINITY);
  const double high = specification.max.value_or(INFINITY);
  if (options.rule == DecisionRule::kSimpleAcceptance) {
    if (!std::isfinite(value)) return Decision::kDoesNotConform;
    return (value >= low && value <= high) ? Decision::kConforms : Decision::kDoesNotConform;
  }
  if (!std::isfinite(value) || !std::isfinite(expanded) || expanded < 0.0) return Decision::kNotProven;
  if (value - expanded >= low && value + expanded <= high) return Decision::kConforms;
  if (value + expanded < low || value - expanded > high) return Decision::kDoesNotConform;
  return Decision::kNotProven;
}

std::optional<Decision> Overall(std::span<const Decision> decisions) {
  if (decisions.empty()) return std::nullopt;
  if (std::find(decisions.begin(), decisions.end(), Decision::kDoesNotConform) != decisions.end())
    return Decision::kDoesNotConform;
  if (std::find(decisions.begin(), decisions.end(), Decision::kNotProven) != decisions.end())
    return Decision::kNotProven;
  return Decision::kConforms;
}

}  // namespace arcwheel::uncertainty
