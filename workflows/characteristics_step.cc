#include "workflows/characteristics_step.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <nlohmann/json.hpp>
#include <span>

#include "core/error.h"
#include "fitting/wheel_fit.h"
#include "processing/wheel_map.h"
#include "reports/tolerances.h"
#include "schema/summary.h"
#include "uncertainty/noise_corrected.h"
#include "uncertainty/wheel_uncertainty.h"
#include "workflows/process_pipeline.h"

namespace arcwheel::workflows {
namespace {

namespace key = schema::summary;
using characteristics::Association;
using characteristics::FormOperator;

std::optional<double> CutOff(double value) {
  return value > 0.0 ? std::optional<double>(value) : std::nullopt;
}

// `op` with what the tolerance of `contract_key` names in place of the defaults.
void ApplyNamedOperator(const ProcessPipelineOptions& options, std::string_view contract_key,
                        FormOperator& op) {
  if (!options.tolerances) return;
  const auto found = options.tolerances->operators.find(std::string(contract_key));
  if (found == options.tolerances->operators.end()) return;
  const reports::NamedOperator& named = found->second;
  if (named.no_filter) op.cutoff_upr = op.cutoff_mm = std::nullopt;
  if (named.filter_upr) op.cutoff_upr = named.filter_upr;
  if (named.filter_cutoff_mm) op.cutoff_mm = named.filter_cutoff_mm;
  if (named.association) op.association = characteristics::ParseAssociation(*named.association);
}

// A closed-profile cut-off the options (not a tolerance) ask for that the map's phases cannot
// carry becomes the largest of ISO 12181-2's series (15, 50, 150, 500 UPR) they can, and says so.
void FitCutOffToThePhases(std::string_view what, FormOperator& op, int points_per_turn,
                          std::vector<std::string>& warnings) {
  if (!op.cutoff_upr || *op.cutoff_upr <= points_per_turn / 2.0) return;
  std::optional<double> fitted;
  for (const double series : {15.0, 50.0, 150.0, 500.0}) {
    if (series <= points_per_turn / 2.0) fitted = series;
  }
  warnings.push_back(fmt::format("{}: the {:g} UPR filter needs {:g} phases per turn; {} at {} phases", what,
                                 *op.cutoff_upr, 2.0 * *op.cutoff_upr,
                                 fitted ? fmt::format("{:g} UPR used", *fitted) : std::string("no filter"),
                                 points_per_turn));
  op.cutoff_upr = fitted;
}

std::string OperatorProblem(std::string_view contract_key, const FormOperator& op, int points_per_turn) {
  if (contract_key == key::kMaxRoundnessUm)
    return characteristics::RoundnessOperatorProblem(op, points_per_turn);
  if (contract_key == key::kMaxRunoutUm) return characteristics::RunoutOperatorProblem(op, points_per_turn);
  return characteristics::ArcProfileOperatorProblem(op);
}

// The budget's type B inputs of a quantity, with the operator's type A in place of the
// uncertainty stage's.
uncertainty::Combined CombineWithBudget(const uncertainty::WheelUncertainty& wheel,
                                        std::string_view contract_key,
                                        const characteristics::FormCharacteristic& form) {
  std::vector<uncertainty::Input> inputs;
  uncertainty::Input type_a;
  type_a.name = "noise (operator)";
  type_a.source = fmt::format("parametric bootstrap of the map's noise, {} replicates", form.replicates);
  type_a.unit = "um";
  type_a.spread = std::isfinite(form.u_um) ? form.u_um : 0.0;
  type_a.dof = form.replicates > 1 ? form.replicates - 1.0 : uncertainty::kInfiniteDof;
  type_a.type = uncertainty::EvaluationType::kA;
  inputs.push_back(type_a);
  const uncertainty::QuantityUncertainty* q = wheel.Find(contract_key);
  if (q != nullptr) {
    for (const uncertainty::Input& input : q->inputs)
      if (input.type == uncertainty::EvaluationType::kB) inputs.push_back(input);
  }
  return uncertainty::Combine(inputs, wheel.budget.combine);
}

std::optional<uncertainty::Decision> DecisionOf(const ProcessPipelineOptions& options,
                                                std::string_view contract_key, double value,
                                                double expanded) {
  if (!options.tolerances) return std::nullopt;
  const auto found = options.tolerances->limits.find(std::string(contract_key));
  if (found == options.tolerances->limits.end()) return std::nullopt;
  return uncertainty::Decide(
      value, expanded, {.min = found->second.min, .max = found->second.max},
      {.rule = options.tolerances->rule.value_or(uncertainty::DecisionRule::kIso14253)});
}

Characteristic FormItem(const ProcessPipelineOptions& options, const uncertainty::WheelUncertainty& wheel,
                        std::string name, std::string_view contract_key, std::string label,
                        const characteristics::FormCharacteristic& form, std::string where,
                        std::string at_key) {
  Characteristic c;
  c.name = std::move(name);
  c.contract_key = contract_key;
  c.label = std::move(label);
  c.unit = "um";
  const uncertainty::Combined combined = CombineWithBudget(wheel, contract_key, form);
  c.value = form.value_um + combined.correction;
  c.u = combined.standard_uncertainty;
  c.expanded = combined.expanded;
  c.coverage_factor = combined.coverage_factor;
  c.operator_text = form.op.Describe();
  c.cutoff_upr = form.op.cutoff_upr;
  c.cutoff_mm = form.op.cutoff_mm;
  c.association =
      form.op.association ? std::string(characteristics::AssociationName(*form.op.association)) : "";
  c.parameter = form.op.parameter;
  c.where = std::move(where);
  if (form.worst_index >= 0) {
    c.at_key = std::move(at_key);
    c.at = form.worst_at;
  }
  c.decision = DecisionOf(options, contract_key, c.value, c.expanded);
  return c;
}

// A least-squares figure of the per-phase fits, as the uncertainty stage evaluates it.
Characteristic FitItem(const ProcessPipelineOptions& options, const uncertainty::WheelUncertainty& wheel,
                       std::string name, std::string_view contract_key, std::string label,
                       std::string parameter) {
  Characteristic c;
  c.name = std::move(name);
  c.contract_key = contract_key;
  c.label = std::move(label);
  c.unit = "mm";
  c.association = "least-squares";
  c.parameter = std::move(parameter);
  c.operator_text = c.parameter + ", no filter, LS";
  const uncertainty::QuantityUncertainty* q = wheel.Find(contract_key);
  if (q == nullptr)
    throw Error(ErrorCode::kInternal, "process", fmt::format("no uncertainty for {}", contract_key));
  c.unit = q->unit;
  c.value = q->value;
  c.u = q->combined.standard_uncertainty;
  c.expanded = q->combined.expanded;
  c.coverage_factor = q->combined.coverage_factor;
  c.decision = DecisionOf(options, contract_key, c.value, c.expanded);
  return c;
}

// The turns of the map in the band without their noise, um about rho = 0, [band nodes x phases]:
// the uncertainty stage's fit of the map (harmonics kept over all the nodes, each fitted along
// them) up to three times the larger turn cut-off (its Gaussian passes 0.2 % there), so that the
// bootstrap of roundness and run-out draws about turns with little noise left in them. Empty when
// the map has no noise or no node in the band.
// Each map value's 1-sigma from the noise, mm: the per-sample noise over the root of the cell's
// samples that the despiking kept; NaN where none. Over simulated scans the map's residuals
// about its smoothed turns scatter by 1.00 of it in cells of three samples and of four alike.
std::vector<double> ValueSigmasMm(const processing::WheelMap& map) {
  std::vector<double> sigma(map.rho_mm.size(), std::numeric_limits<double>::quiet_NaN());
  if (map.sample_count.size() != sigma.size() || map.despiked_count.size() != sigma.size()) return sigma;
  for (std::size_t cell = 0; cell < sigma.size(); ++cell) {
    const int samples = map.sample_count[cell] - map.despiked_count[cell];
    if (samples > 0) sigma[cell] = map.noise_sigma_mm / std::sqrt(static_cast<double>(samples));
  }
  return sigma;
}

std::vector<double> SmoothedTurns(const processing::WheelMap& map, std::span<const double> value_sigma_mm,
                                  double band_low_mm, double band_high_mm,
                                  const characteristics::CharacteristicsOptions& operators, int max_degree) {
  const std::size_t n_phase = map.n_phase(), n_y = map.n_y();
  std::vector<std::size_t> band;
  for (std::size_t j = 0; j < n_y; ++j)
    if (map.y_mm[j] >= band_low_mm && map.y_mm[j] <= band_high_mm) band.push_back(j);
  const double sigma_um = map.map_sigma_mm * 1000.0;
  if (band.size() < 3 || !(sigma_um > 0.0) || n_phase < 8) return {};
  std::vector<double> rows(band.size() * n_phase), sigmas(rows.size());
  for (std::size_t i = 0; i < band.size(); ++i) {
    for (std::size_t p = 0; p < n_phase; ++p) {
      const std::size_t cell = p * n_y + band[i];
      rows[i * n_phase + p] = map.rho_mm[cell] * 1000.0;
      sigmas[i * n_phase + p] =
          std::isfinite(value_sigma_mm[cell]) ? value_sigma_mm[cell] * 1000.0 : sigma_um;
    }
  }
  const int most = static_cast<int>(n_phase - 2) / 2;
  double cutoff_upr = 0.0;
  for (const auto& op : {operators.roundness, operators.runout})
    cutoff_upr = std::max(cutoff_upr, op.cutoff_upr.value_or(static_cast<double>(most)));
  const uncertainty::NoiseCorrectedPvOptions fit{
      .basis = uncertainty::SmoothBasis::kFourier,
      .max_order = std::min(most, static_cast<int>(std::ceil(3.0 * cutoff_upr))),
      .across_rows_max_degree = std::min(max_degree, static_cast<int>(band.size()) - 2)};
  try {
    return uncertainty::FitNoiseFreeRows(rows, sigmas, static_cast<int>(band.size()),
                                         static_cast<int>(n_phase), fit);
  } catch (const Error&) {
    return {};  // no turn with half its values: each turn's own harmonics stand in
  }
}

}  // namespace

characteristics::CharacteristicsOptions CharacteristicOperators(const ProcessPipelineOptions& options,
                                                                int points_per_turn,
                                                                std::vector<std::string>* warnings) {
  characteristics::CharacteristicsOptions out;
  out.roundness = {.cutoff_upr = CutOff(options.roundness_filter_upr),
                   .cutoff_mm = std::nullopt,
                   .association = options.roundness_association,
                   .parameter = "RONt"};
  out.runout = {.cutoff_upr = CutOff(options.runout_filter_upr),
                .cutoff_mm = std::nullopt,
                .association = std::nullopt,
                .parameter = "TIR"};
  out.arc_profile = {.cutoff_upr = std::nullopt,
                     .cutoff_mm = CutOff(options.arc_error_filter_mm),
                     .association = options.arc_error_association,
                     .parameter = "PV"};
  std::vector<std::string> fitted;
  FitCutOffToThePhases("roundness", out.roundness, points_per_turn, fitted);
  FitCutOffToThePhases("circular run-out", out.runout, points_per_turn, fitted);
  if (warnings != nullptr) warnings->insert(warnings->end(), fitted.begin(), fitted.end());
  ApplyNamedOperator(options, key::kMaxRoundnessUm, out.roundness);
  ApplyNamedOperator(options, key::kMaxRunoutUm, out.runout);
  ApplyNamedOperator(options, key::kMaxArcErrorUm, out.arc_profile);
  out.replicates = options.uncertainty.replicates;
  out.seed = options.uncertainty.seed;
  std::vector<std::string> problems;
  const std::pair<std::string_view, const FormOperator*> named[] = {{key::kMaxRoundnessUm, &out.roundness},
                                                                    {key::kMaxRunoutUm, &out.runout},
                                                                    {key::kMaxArcErrorUm, &out.arc_profile}};
  for (const auto& [contract_key, op] : named) {
    if (const std::string problem = OperatorProblem(contract_key, *op, points_per_turn); !problem.empty()) {
      const bool from_tolerance =
          options.tolerances && options.tolerances->operators.count(std::string(contract_key));
      problems.push_back(fmt::format("{} ({}): {}", contract_key,
                                     from_tolerance ? "the tolerance's operator" : "the options", problem));
    }
  }
  ThrowIfProblems(ErrorCode::kInvalidOption, "process", problems);
  return out;
}

SmoothedTurnMap SmoothTurnMap(const ProcessPipelineOptions& options, const processing::WheelMap& map,
                              const fitting::WheelFit& fit) {
  SmoothedTurnMap out;
  out.value_sigma_mm = ValueSigmasMm(map);
  out.turn_smooth_um = SmoothedTurns(map, out.value_sigma_mm, fit.band_low_mm, fit.band_high_mm,
                                     CharacteristicOperators(options, static_cast<int>(map.n_phase())),
                                     options.uncertainty.max_degree);
  return out;
}

namespace {

// The characteristics' view of the map and the fits: characteristics::WheelForm holds spans, and the
// per-phase arrays they point into live here (so it is neither copied nor moved).
class FormOfTheWheel {
 public:
  FormOfTheWheel(const processing::WheelMap& map, const fitting::WheelFit& fit, double wheel_radius_mm,
                 const SmoothedTurnMap& smoothed) {
    for (const fitting::PhaseFit& phase : fit.phases) {
      center_axial_.push_back(phase.center_axial_mm);
      center_radial_.push_back(phase.center_radial_mm);
      radius_.push_back(phase.arc_radius_mm);
      usable_.push_back(phase.usable ? 1 : 0);
    }
    form.rho_mm = map.rho_mm;
    form.y_mm = map.y_mm;
    form.map_sigma_mm = map.map_sigma_mm;
    form.radius_offset_mm = wheel_radius_mm;
    form.band_low_mm = fit.band_low_mm;
    form.band_high_mm = fit.band_high_mm;
    form.center_axial_mm = center_axial_;
    form.center_radial_mm = center_radial_;
    form.arc_radius_mm = radius_;
    form.usable = usable_;
    form.section_bins = fit.section_bins;
    form.section_residual_um = fit.section_residual_um;
    form.section_y_mm = fit.section_y_mm;
    form.section_sigma_um = fit.section_sigma_um;
    form.rho_sigma_mm = smoothed.value_sigma_mm;
    form.turn_smooth_um = smoothed.turn_smooth_um;
  }
  FormOfTheWheel(const FormOfTheWheel&) = delete;
  FormOfTheWheel& operator=(const FormOfTheWheel&) = delete;

  characteristics::WheelForm form;

 private:
  std::vector<double> center_axial_, center_radial_, radius_;
  std::vector<char> usable_;
};

}  // namespace

TurnCharacteristics EvaluateTurnCharacteristics(const ProcessPipelineOptions& options,
                                                const processing::WheelMap& map, const fitting::WheelFit& fit,
                                                double wheel_radius_mm) {
  TurnCharacteristics out;
  out.smoothed = SmoothTurnMap(options, map, fit);
  const FormOfTheWheel wheel(map, fit, wheel_radius_mm, out.smoothed);
  out.form = characteristics::EvaluateTurnCharacteristics(
      wheel.form, CharacteristicOperators(options, static_cast<int>(map.n_phase())));
  return out;
}

CharacteristicsResult EvaluateCharacteristics(const ProcessPipelineOptions& options,
                                              const processing::WheelMap& map, const fitting::WheelFit& fit,
                                              const uncertainty::WheelUncertainty& wheel,
                                              double wheel_radius_mm, TurnCharacteristics turns) {
  std::vector<std::string> warnings;
  const characteristics::CharacteristicsOptions operators =
      CharacteristicOperators(options, static_cast<int>(map.n_phase()), &warnings);
  FormOfTheWheel form_of_the_wheel(map, fit, wheel_radius_mm, turns.smoothed);
  characteristics::WheelForm& form = form_of_the_wheel.form;
  form.section_smooth_um = wheel.smoothed_section_um;
  form.section_sigma_scale = wheel.section_sigma_scale;

  CharacteristicsResult result;
  result.warnings = std::move(warnings);
  result.form = std::move(turns.form);
  result.form.arc_profile = characteristics::EvaluateArcProfile(form, operators);
  if (options.tolerances)
    result.rule = options.tolerances->rule.value_or(uncertainty::DecisionRule::kIso14253);
  const auto& f = result.form;
  result.items.push_back(
      FitItem(options, wheel, "mean_arc_radius", key::kMeanArcRadiusMm, "mean arc radius", "mean Ra"));
  result.items.push_back(
      FitItem(options, wheel, "arc_radius_range", key::kArcRadiusRangeMm, "arc radius range", "range of Ra"));
  result.items.push_back(FitItem(options, wheel, "center_axial_deviation", key::kCenterAxialDeviationMm,
                                 "arc centre axial deviation", "range of a"));
  result.items.push_back(FormItem(options, wheel, "max_arc_error", key::kMaxArcErrorUm,
                                  "max arc profile error", f.arc_profile,
                                  fmt::format("at phase {:g} deg", f.arc_profile.worst_at), "at_phase_deg"));
  result.items.push_back(FormItem(options, wheel, "max_runout", key::kMaxRunoutUm, "max circular run-out",
                                  f.runout, fmt::format("at y = {:.3f} mm", f.runout.worst_at), "at_y_mm"));
  result.items.push_back(FormItem(options, wheel, "max_roundness", key::kMaxRoundnessUm, "max roundness",
                                  f.roundness, fmt::format("at y = {:.3f} mm", f.roundness.worst_at),
                                  "at_y_mm"));
  return result;
}

nlohmann::json CharacteristicsToJson(const CharacteristicsResult& result) {
  nlohmann::json out = nlohmann::json::object();
  const auto number = [](double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr); };
  for (const Characteristic& c : result.items) {
    nlohmann::json filter = {{"type", "none"}};
    if (c.cutoff_upr) filter = {{"type", "gaussian"}, {"cutoff_upr", *c.cutoff_upr}};
    if (c.cutoff_mm) filter = {{"type", "gaussian"}, {"cutoff_mm", *c.cutoff_mm}};
    nlohmann::json op = {{"filter", filter}, {"parameter", c.parameter}, {"short", c.operator_text}};
    op["association"] = c.association.empty() ? nlohmann::json("datum axis") : nlohmann::json(c.association);
    nlohmann::json item = {{"value_" + c.unit, number(c.value)},
                           {"operator", op},
                           {"u", number(c.u)},
                           {"U", number(c.expanded)},
                           {"k", number(c.coverage_factor)}};
    if (!c.where.empty()) item["where"] = c.where;
    if (!c.at_key.empty()) item[c.at_key] = number(c.at);
    if (c.decision) {
      item["decision"] = uncertainty::DecisionName(*c.decision);
      item["rule"] = uncertainty::DecisionRuleName(*result.rule);
    }
    out[c.name] = std::move(item);
  }
  return out;
}

}  // namespace arcwheel::workflows
