#include "uncertainty/budget_json.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <optional>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/json_text.h"
#include "core/number_format.h"
#include "schema/summary.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kBudgetJsonStage = "uncertainty.budget";
namespace s = schema::summary;

struct UnitInfo {
  std::string_view kind;  // "length", "percent", "dimensionless", "temperature", "angle", ...
  double scale = 1.0;     // to the kind's base unit (mm, %, 1, K, rad)
};

std::optional<UnitInfo> Unit(std::string_view unit) {
  if (unit == "mm") return UnitInfo{"length", 1.0};
  if (unit == "um") return UnitInfo{"length", 1e-3};
  if (unit == "nm") return UnitInfo{"length", 1e-6};
  if (unit == "%") return UnitInfo{"percent", 1.0};
  if (unit == "1") return UnitInfo{"dimensionless", 1.0};
  if (unit == "ppm") return UnitInfo{"dimensionless", 1e-6};
  if (unit == "K") return UnitInfo{"temperature", 1.0};
  if (unit == "degC") return UnitInfo{"temperature", 1.0};
  if (unit == "rad") return UnitInfo{"angle", 1.0};
  if (unit == "deg") return UnitInfo{"angle", std::numbers::pi / 180.0};
  if (unit == "1/K") return UnitInfo{"expansion", 1.0};
  return std::nullopt;
}

constexpr std::string_view kUnits = "mm, um, nm, %, 1, ppm, K, degC, deg, rad, 1/K";

std::string Quoted(const nlohmann::json& value) {
  if (value.is_string()) {
    std::string text = "'";
    text.append(value.get<std::string>()).push_back('\'');
    return text;
  }
  if (value.is_number()) return ShowSignificant(value.get<double>());
  return JsonText(value);
}

class Reader {
 public:
  explicit Reader(std::vector<std::string>& problems) : problems_(problems) {}

  void Problem(const std::string& where, const nlohmann::json& value, const std::string& rule) {
    problems_.push_back(where + " = " + Quoted(value) + " violates " + rule);
  }

  // A finite number at `where`; `minimum` as a rule (">= 0", "> 0") when given.
  std::optional<double> Number(const nlohmann::json& object, const std::string& key, const std::string& where,
                               std::string_view rule) {
    const nlohmann::json& value = object.at(key);
    if (!value.is_number() || !std::isfinite(value.get<double>())) {
      Problem(where, value, rule.empty() ? "a finite number" : "a finite number " + std::string(rule));
      return std::nullopt;
    }
    const double number = value.get<double>();
    if ((rule == ">= 0" && number < 0.0) || (rule == "> 0" && number <= 0.0)) {
      Problem(where, value, "a finite number " + std::string(rule));
      return std::nullopt;
    }
    return number;
  }

 private:
  std::vector<std::string>& problems_;
};

std::optional<Distribution> DistributionFromName(std::string_view name) {
  for (const Distribution d :
       {Distribution::kNormal, Distribution::kRectangular, Distribution::kTriangular, Distribution::kArcsine})
    if (DistributionName(d) == name) return d;
  return std::nullopt;
}

const std::set<std::string>& InputKeys() {
  static const std::set<std::string> keys = {
      "name",     "source", "unit",       "value",       "distribution",     "sigma",
      "expanded", "k",      "half_width", "sensitivity", "sensitivity_unit", "relative_factor",
      "dof",      "type"};
  return keys;
}

std::optional<BudgetInput> ParseInput(const nlohmann::json& item, const std::string& quantity,
                                      std::size_t index, Reader& reader) {
  const std::string fallback = quantity + "[" + std::to_string(index) + "]";
  if (!item.is_object()) {
    reader.Problem(fallback, item, "an object");
    return std::nullopt;
  }
  BudgetInput out;
  Input& input = out.input;
  const bool named =
      item.contains("name") && item["name"].is_string() && !item["name"].get<std::string>().empty();
  const std::string where = named ? quantity + "." + item["name"].get<std::string>() : fallback;
  if (!named) reader.Problem(fallback + ".name", item.value("name", nlohmann::json()), "a non-empty text");
  if (named) input.name = item["name"].get<std::string>();
  bool ok = named;
  for (const auto& [key, value] : item.items()) {
    if (!InputKeys().contains(key)) {
      reader.Problem(where + "." + key, value,
                     "a known key (name, source, unit, value, distribution, sigma, "
                     "expanded, k, half_width, sensitivity, sensitivity_unit, relative_factor, dof, type)");
      ok = false;
    }
  }
  if (item.contains("source")) {
    if (item["source"].is_string()) {
      input.source = item["source"].get<std::string>();
    } else {
      reader.Problem(where + ".source", item["source"], "a text");
      ok = false;
    }
  }
  // Distribution and spread.
  std::optional<Distribution> distribution;
  if (!item.contains("distribution") || !item["distribution"].is_string() ||
      !(distribution = DistributionFromName(item["distribution"].get<std::string>()))) {
    reader.Problem(where + ".distribution", item.value("distribution", nlohmann::json()),
                   "one of normal, rectangular, triangular, arcsine");
    ok = false;
  } else {
    input.distribution = *distribution;
    auto spread = [&](const std::string& key) -> bool {
      if (!item.contains(key)) {
        reader.Problem(where + "." + key, nlohmann::json(),
                       "given for a " + item["distribution"].get<std::string>() + " input");
        return false;
      }
      const auto number = reader.Number(item, key, where + "." + key, ">= 0");
      if (number) input.spread = *number;
      return number.has_value();
    };
    if (*distribution == Distribution::kNormal) {
      if (item.contains("sigma")) {
        ok = spread("sigma") && ok;
        input.coverage_factor = 1.0;
        if (item.contains("expanded") || item.contains("k")) {
          reader.Problem(where + ".sigma", item["sigma"], "given alone (not with expanded or k)");
          ok = false;
        }
      } else {
        ok = spread("expanded") && ok;
        if (!item.contains("k")) {
          reader.Problem(where + ".k", nlohmann::json(), "given with expanded");
          ok = false;
        } else if (const auto k = reader.Number(item, "k", where + ".k", "> 0")) {
          input.coverage_factor = *k;
        } else {
          ok = false;
        }
      }
      if (item.contains("half_width")) {
        reader.Problem(where + ".half_width", item["half_width"],
                       "absent for a normal input (sigma, or expanded and k)");
        ok = false;
      }
    } else {
      ok = spread("half_width") && ok;
      for (const char* key : {"sigma", "expanded", "k"}) {
        if (item.contains(key)) {
          reader.Problem(where + "." + key, item[key],
                         "absent for a " + item["distribution"].get<std::string>() + " input (half_width)");
          ok = false;
        }
      }
    }
  }
  if (item.contains("value")) {
    if (const auto value = reader.Number(item, "value", where + ".value", "")) {
      input.value = *value;
    } else {
      ok = false;
    }
  }
  if (item.contains("dof") && !item["dof"].is_null()) {
    if (const auto dof = reader.Number(item, "dof", where + ".dof", "> 0")) {
      input.dof = *dof;
    } else {
      ok = false;
    }
  }
  if (item.contains("type")) {
    const nlohmann::json& type = item["type"];
    if (type == "A") {
      input.type = EvaluationType::kA;
    } else if (type == "B") {
      input.type = EvaluationType::kB;
    } else {
      reader.Problem(where + ".type", type, "'A' or 'B'");
      ok = false;
    }
  }
  // Units and sensitivity.
  const std::string quantity_unit = QuantityUnit(quantity);
  const std::optional<UnitInfo> quantity_info = Unit(quantity_unit);
  std::optional<UnitInfo> unit_info;
  if (!item.contains("unit") || !item["unit"].is_string() ||
      !(unit_info = Unit(item["unit"].get<std::string>()))) {
    reader.Problem(where + ".unit", item.value("unit", nlohmann::json()), "one of " + std::string(kUnits));
    return std::nullopt;
  }
  input.unit = item["unit"].get<std::string>();
  const bool relative = item.contains("sensitivity") && item["sensitivity"] == "relative";
  double sensitivity = 1.0;
  if (item.contains("sensitivity") && !relative) {
    if (const auto number = reader.Number(item, "sensitivity", where + ".sensitivity", "")) {
      sensitivity = *number;
    } else {
      reader.Problem(where + ".sensitivity", item["sensitivity"], "a number or 'relative'");
      ok = false;
    }
  }
  if (relative) {
    if (unit_info->kind != "dimensionless" && unit_info->kind != "percent") {
      reader.Problem(where + ".unit", item["unit"], "1, ppm or % for a relative sensitivity");
      return std::nullopt;
    }
    if (item.contains("sensitivity_unit")) {
      reader.Problem(where + ".sensitivity_unit", item["sensitivity_unit"],
                     "absent for a relative sensitivity");
      return std::nullopt;
    }
    out.relative = true;
    double factor = 1.0;
    if (item.contains("relative_factor")) {
      const auto number = reader.Number(item, "relative_factor", where + ".relative_factor", "");
      if (!number) return std::nullopt;
      factor = *number;
    }
    input.sensitivity = factor * (unit_info->kind == "percent" ? 0.01 : unit_info->scale);
  } else if (item.contains("sensitivity_unit")) {
    const nlohmann::json& text = item["sensitivity_unit"];
    const std::string expected = quantity_unit + "/" + input.unit;
    const std::string given = text.is_string() ? text.get<std::string>() : "";
    const std::size_t slash = given.find('/');
    const std::optional<UnitInfo> numerator =
        slash == std::string::npos ? std::nullopt : Unit(given.substr(0, slash));
    if (!numerator || given.substr(slash + 1) != input.unit || numerator->kind != quantity_info->kind) {
      reader.Problem(where + ".sensitivity_unit", text,
                     "'" + expected + "' (" + quantity + " per " + input.unit + ")");
      return std::nullopt;
    }
    input.sensitivity = sensitivity * numerator->scale / quantity_info->scale;
  } else {
    if (unit_info->kind != quantity_info->kind) {
      reader.Problem(where + ".unit", item["unit"],
                     "a unit of " + quantity + " (" + quantity_unit + ") or a sensitivity_unit '" +
                         quantity_unit + "/" + input.unit + "'");
      return std::nullopt;
    }
    input.sensitivity = sensitivity * unit_info->scale / quantity_info->scale;
  }
  if (!ok) return std::nullopt;
  return out;
}

}  // namespace

const std::vector<std::string>& BudgetQuantityKeys() {
  static const std::vector<std::string> keys = {
      std::string(s::kMeanArcRadiusMm),         std::string(s::kArcRadiusRangeMm),
      std::string(s::kArcRadiusFluctuationPct), std::string(s::kCenterAxialDeviationMm),
      std::string(s::kMaxArcErrorUm),           std::string(s::kMaxRunoutUm),
      std::string(s::kMaxRoundnessUm)};
  return keys;
}

std::string QuantityUnit(std::string_view key) {
  if (std::find(BudgetQuantityKeys().begin(), BudgetQuantityKeys().end(), key) == BudgetQuantityKeys().end())
    return "";
  if (key.ends_with("_mm")) return "mm";
  if (key.ends_with("_um")) return "um";
  return "%";
}

std::vector<Input> ResolveInputs(const std::vector<BudgetInput>& inputs, double value) {
  std::vector<Input> out;
  out.reserve(inputs.size());
  for (const BudgetInput& input : inputs) {
    out.push_back(input.input);
    if (input.relative) out.back().sensitivity *= value;
  }
  return out;
}

BudgetFile ParseBudget(std::string_view text, const std::string& name) {
  nlohmann::json root;
  try {
    root = ParseJsonText(text, name, kBudgetJsonStage);
  } catch (const Error& error) {
    // A budget is an option file: whatever is wrong with it exits 2, as its other problems do.
    throw Error(ErrorCode::kInvalidOption, kBudgetJsonStage,
                std::string(error.what()).substr(error.stage().size() + 2));
  }
  if (!root.is_object())
    throw Error(ErrorCode::kInvalidOption, kBudgetJsonStage, "'" + name + "' is not a JSON object");
  std::vector<std::string> problems;
  Reader reader(problems);
  BudgetFile budget;
  for (const auto& [key, value] : root.items()) {
    if (key == "coverage_probability") {
      const auto p = reader.Number(root, key, key, "> 0");
      if (p && *p >= 1.0) reader.Problem(key, value, "(0, 1)");
      if (p) budget.combine.coverage_probability = *p;
    } else if (key == "truncate_dof") {
      if (value.is_boolean()) {
        budget.combine.truncate_dof = value.get<bool>();
      } else {
        reader.Problem(key, value, "true or false");
      }
    } else if (key == "quantities") {
      if (!value.is_object()) {
        reader.Problem(key, value, "an object keyed by headline quantity");
        continue;
      }
      for (const auto& [quantity, list] : value.items()) {
        if (QuantityUnit(quantity).empty()) {
          std::string known;
          for (const std::string& k : BudgetQuantityKeys()) known += (known.empty() ? "" : ", ") + k;
          reader.Problem("quantities." + quantity, list, "a headline quantity (" + known + ")");
          continue;
        }
        if (!list.is_array()) {
          reader.Problem(quantity, list, "a list of inputs");
          continue;
        }
        std::set<std::string> names;
        auto& inputs = budget.quantities[quantity];
        for (std::size_t i = 0; i < list.size(); ++i) {
          if (auto input = ParseInput(list[i], quantity, i, reader)) {
            if (!names.insert(input->input.name).second) {
              reader.Problem(quantity + "." + input->input.name + ".name", input->input.name,
                             "unique in its quantity");
              continue;
            }
            inputs.push_back(std::move(*input));
          }
        }
      }
    } else {
      reader.Problem(key, value, "a known key (coverage_probability, truncate_dof, quantities)");
    }
  }
  if (!problems.empty()) {
    throw Error(ErrorCode::kInvalidOption, kBudgetJsonStage, "'" + name + "': " + JoinProblems(problems));
  }
  return budget;
}

BudgetFile ReadBudget(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(ErrorCode::kIo, kBudgetJsonStage, "cannot open '" + path.string() + "'");
  std::ostringstream contents;
  contents << stream.rdbuf();
  return ParseBudget(contents.str(), path.string());
}

nlohmann::json BudgetToJson(const BudgetFile& budget) {
  nlohmann::json root = {{"coverage_probability", budget.combine.coverage_probability},
                         {"truncate_dof", budget.combine.truncate_dof}};
  nlohmann::json quantities = nlohmann::json::object();
  for (const auto& [quantity, inputs] : budget.quantities) {
    nlohmann::json list = nlohmann::json::array();
    for (const BudgetInput& entry : inputs) {
      const Input& input = entry.input;
      nlohmann::json item = {{"name", input.name},
                             {"source", input.source},
                             {"unit", input.unit},
                             {"value", input.value},
                             {"distribution", DistributionName(input.distribution)},
                             {"type", input.type == EvaluationType::kA ? "A" : "B"}};
      if (input.distribution == Distribution::kNormal) {
        item["expanded"] = input.spread;
        item["k"] = input.coverage_factor;
      } else {
        item["half_width"] = input.spread;
      }
      if (entry.relative) {
        const std::optional<UnitInfo> unit = Unit(input.unit);
        item["sensitivity"] = "relative";
        item["relative_factor"] = input.sensitivity / (unit->kind == "percent" ? 0.01 : unit->scale);
      } else {
        item["sensitivity"] = input.sensitivity;
        item["sensitivity_unit"] = QuantityUnit(quantity) + "/" + input.unit;
      }
      item["dof"] = std::isfinite(input.dof) ? nlohmann::json(input.dof) : nlohmann::json(nullptr);
      list.push_back(std::move(item));
    }
    quantities[quantity] = std::move(list);
  }
  root["quantities"] = std::move(quantities);
  return root;
}

}  // namespace arcwheel::uncertainty
