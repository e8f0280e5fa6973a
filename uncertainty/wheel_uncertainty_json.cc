#include <cmath>
#include <nlohmann/json.hpp>

#include "schema/summary.h"
#include "uncertainty/wheel_uncertainty.h"

// summary.json's "uncertainty" object, apart from the evaluation in wheel_uncertainty.cc: writing
// JSON is compiled as formatting code is (uncertainty/CMakeLists.txt), the bootstraps as kernels.
namespace arcwheel::uncertainty {
namespace {

namespace s = schema::summary;
namespace su = schema::summary::uncertainty;

nlohmann::json Finite(double value) {
  return std::isfinite(value) ? nlohmann::json(value) : nlohmann::json(nullptr);
}

}  // namespace

nlohmann::json WheelUncertaintyToJson(const WheelUncertainty& uncertainty) {
  namespace qk = su::quantity;
  namespace ck = su::quantity::contribution;
  nlohmann::json quantities = nlohmann::json::object();
  for (const QuantityUncertainty& q : uncertainty.quantities) {
    nlohmann::json contributions = nlohmann::json::array();
    for (std::size_t i = 0; i < q.inputs.size() && i < q.combined.contributions.size(); ++i) {
      const Input& input = q.inputs[i];
      const Contribution& line = q.combined.contributions[i];
      contributions.push_back({{ck::kName, input.name},
                               {ck::kSource, input.source},
                               {ck::kType, input.type == EvaluationType::kA ? "A" : "B"},
                               {ck::kUnit, input.unit},
                               {ck::kDistribution, DistributionName(input.distribution)},
                               {ck::kStandardUncertainty, line.standard_uncertainty},
                               {ck::kSensitivity, line.sensitivity},
                               {ck::kContribution, line.contribution},
                               {ck::kDof, Finite(line.dof)}});
    }
    nlohmann::json item = {{qk::kUnit, q.unit},
                           {qk::kMeasured, Finite(q.measured)},
                           {qk::kValue, Finite(q.value)},
                           {qk::kTypeAMethod, q.type_a_method},
                           {qk::kContributions, std::move(contributions)},
                           {qk::kCorrection, q.combined.correction},
                           {qk::kStandardUncertainty, Finite(q.combined.standard_uncertainty)},
                           {qk::kEffectiveDof, Finite(q.combined.effective_dof)},
                           {qk::kCoverageFactor, Finite(q.combined.coverage_factor)},
                           {qk::kExpanded, Finite(q.combined.expanded)}};
    if (q.key != s::kMeanArcRadiusMm) item[qk::kNoiseBias] = Finite(q.noise_bias);
    quantities[q.key] = std::move(item);
  }
  nlohmann::json out = {{su::kCoverageProbability, uncertainty.budget.combine.coverage_probability},
                        {su::kBudgetSource, uncertainty.budget_source},
                        {su::kBudget, BudgetToJson(uncertainty.budget)},
                        {su::kQuantities, std::move(quantities)}};
  if (uncertainty.rule) {
    namespace dk = su::decision;
    nlohmann::json decisions = nlohmann::json::object();
    std::vector<Decision> all;
    for (const ConformityDecision& d : uncertainty.decisions) {
      const QuantityUncertainty& q = *uncertainty.Find(d.key);
      decisions[d.key] = {{dk::kMin, d.specification.min ? nlohmann::json(*d.specification.min) : nullptr},
                          {dk::kMax, d.specification.max ? nlohmann::json(*d.specification.max) : nullptr},
                          {dk::kValue, Finite(q.value)},
                          {dk::kExpanded, Finite(q.combined.expanded)},
                          {dk::kCoverageFactor, Finite(q.combined.coverage_factor)},
                          {dk::kDecision, DecisionName(d.decision)}};
      all.push_back(d.decision);
    }
    out[su::kDecisionRule] = DecisionRuleName(*uncertainty.rule);
    out[su::kDecisions] = std::move(decisions);
    const std::optional<Decision> overall = Overall(all);
    out[su::kOverall] = overall ? nlohmann::json(DecisionName(*overall)) : nlohmann::json(nullptr);
  }
  return out;
}

}  // namespace arcwheel::uncertainty
