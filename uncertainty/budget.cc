#include "uncertainty/budget.h"

#include <algorithm>
#include <boost/math/distributions/normal.hpp>
#include <boost/math/distributions/students_t.hpp>
#include <cmath>
#include <numeric>
#include <set>

#include "core/check.h"
#include "core/error.h"
#include "core/number_format.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kBudgetStage = "uncertainty.budget";

std::string Violation(const std::string& name, double value, const std::string& rule) {
  return name + " = " + ShowSignificant(value) + " violates " + rule;
}

}  // namespace

std::string_view DistributionName(Distribution distribution) {
  switch (distribution) {
    case Distribution::kNormal:
      return "normal";
    case Distribution::kRectangular:
      return "rectangular";
    case Distribution::kTriangular:
      return "triangular";
    case Distribution::kArcsine:
      return "arcsine";
  }
  return "unknown";
}

std::vector<std::string> Input::Problems() const {
  std::vector<std::string> problems;
  const std::string prefix = name.empty() ? std::string("input") : name;
  if (name.empty()) problems.push_back("input.name = '' violates not empty");
  if (!std::isfinite(value)) problems.push_back(Violation(prefix + ".value", value, "finite"));
  if (!std::isfinite(spread) || spread < 0.0)
    problems.push_back(Violation(prefix + ".spread", spread, "finite, >= 0"));
  if (distribution == Distribution::kNormal && (!std::isfinite(coverage_factor) || coverage_factor <= 0.0))
    problems.push_back(Violation(prefix + ".coverage_factor", coverage_factor, "finite, > 0"));
  if (!std::isfinite(sensitivity))
    problems.push_back(Violation(prefix + ".sensitivity", sensitivity, "finite"));
  if (std::isnan(dof) || dof <= 0.0)
    problems.push_back(Violation(prefix + ".dof", dof, "> 0 (may be infinite)"));
  return problems;
}

double StandardUncertainty(const Input& input) {
  switch (input.distribution) {
    case Distribution::kNormal:
      return input.spread / input.coverage_factor;
    case Distribution::kRectangular:
      return input.spread / std::sqrt(3.0);
    case Distribution::kTriangular:
      return input.spread / std::sqrt(6.0);
    case Distribution::kArcsine:
      return input.spread / std::sqrt(2.0);
  }
  ARCWHEEL_CHECK(false) << "unknown distribution";
  return 0.0;
}

Input TypeAFromReadings(std::string name, std::string unit, std::span<const double> readings,
                        double sensitivity) {
  if (readings.size() < 2) {
    throw Error(ErrorCode::kBadInput, kBudgetStage,
                "input '" + name + "' has " + std::to_string(readings.size()) + " readings, needs >= 2");
  }
  const double n = static_cast<double>(readings.size());
  const double mean = std::accumulate(readings.begin(), readings.end(), 0.0) / n;
  double sum_squares = 0.0;
  for (const double reading : readings) sum_squares += (reading - mean) * (reading - mean);
  const double s = std::sqrt(sum_squares / (n - 1.0));
  return Input{.name = std::move(name),
               .source = "type A: mean of " + std::to_string(readings.size()) + " readings",
               .unit = std::move(unit),
               .value = mean,
               .distribution = Distribution::kNormal,
               .spread = s / std::sqrt(n),
               .coverage_factor = 1.0,
               .sensitivity = sensitivity,
               .dof = n - 1.0,
               .type = EvaluationType::kA};
}

Input InputFromCombined(std::string name, std::string unit, const Combined& combined, double sensitivity) {
  return Input{.name = std::move(name),
               .source = "combined sub-budget",
               .unit = std::move(unit),
               .value = combined.correction,
               .distribution = Distribution::kNormal,
               .spread = combined.standard_uncertainty,
               .coverage_factor = 1.0,
               .sensitivity = sensitivity,
               .dof = combined.effective_dof,
               .type = EvaluationType::kB};
}

std::vector<std::string> CombineOptions::Problems() const {
  std::vector<std::string> problems;
  if (!(coverage_probability > 0.0 && coverage_probability < 1.0))
    problems.push_back(Violation("CombineOptions::coverage_probability", coverage_probability, "(0, 1)"));
  return problems;
}

double WelchSatterthwaite(std::span<const double> contributions, std::span<const double> dofs) {
  ARCWHEEL_CHECK(contributions.size() == dofs.size()) << contributions.size() << " vs " << dofs.size();
  double variance = 0.0;
  double denominator = 0.0;
  for (std::size_t i = 0; i < contributions.size(); ++i) {
    const double u2 = contributions[i] * contributions[i];
    variance += u2;
    if (std::isfinite(dofs[i])) denominator += u2 * u2 / dofs[i];
  }
  if (denominator <= 0.0) return kInfiniteDof;
  return variance * variance / denominator;
}

double CoverageFactor(double dof, double probability, bool truncate_dof) {
  ARCWHEEL_CHECK(probability > 0.0 && probability < 1.0) << probability;
  ARCWHEEL_CHECK(dof > 0.0) << dof;
  const double tail = 0.5 * (1.0 + probability);
  if (!std::isfinite(dof)) return boost::math::quantile(boost::math::normal_distribution<double>(), tail);
  const double nu = truncate_dof ? std::max(1.0, std::floor(dof)) : dof;
  return boost::math::quantile(boost::math::students_t_distribution<double>(nu), tail);
}

Combined Combine(std::span<const Input> inputs, const CombineOptions& options) {
  std::vector<std::string> problems;
  std::set<std::string> names;
  for (const Input& input : inputs) {
    const std::vector<std::string> own = input.Problems();
    problems.insert(problems.end(), own.begin(), own.end());
    if (!input.name.empty() && !names.insert(input.name).second)
      problems.push_back(input.name + ".name = '" + input.name + "' violates unique in its budget");
  }
  const std::vector<std::string> own = options.Problems();
  problems.insert(problems.end(), own.begin(), own.end());
  ThrowIfProblems(ErrorCode::kInvalidOption, kBudgetStage, problems);

  Combined combined;
  combined.coverage_probability = options.coverage_probability;
  std::vector<double> u_i;
  std::vector<double> nu_i;
  double variance = 0.0;
  for (const Input& input : inputs) {
    Contribution line{.name = input.name,
                      .standard_uncertainty = StandardUncertainty(input),
                      .sensitivity = input.sensitivity,
                      .contribution = 0.0,
                      .dof = input.dof};
    line.contribution = std::abs(line.sensitivity) * line.standard_uncertainty;
    variance += line.contribution * line.contribution;
    combined.correction += input.sensitivity * input.value;
    u_i.push_back(line.contribution);
    nu_i.push_back(line.dof);
    combined.contributions.push_back(std::move(line));
  }
  combined.standard_uncertainty = std::sqrt(variance);
  combined.effective_dof = WelchSatterthwaite(u_i, nu_i);
  combined.coverage_factor =
      CoverageFactor(combined.effective_dof, options.coverage_probability, options.truncate_dof);
  combined.expanded = combined.coverage_factor * combined.standard_uncertainty;
  return combined;
}

}  // namespace arcwheel::uncertainty
