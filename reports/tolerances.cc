#include "reports/tolerances.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "characteristics/association.h"
#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel::reports {
namespace {

constexpr const char* kTolerancesStage = "reports.tolerances";

bool IsHeadlineKey(const std::string& key) {
  return std::find(kHeadlineKeys.begin(), kHeadlineKeys.end(), key) != kHeadlineKeys.end();
}

std::string KnownKeys() {
  std::string keys;
  for (const std::string_view key : kHeadlineKeys) keys += (keys.empty() ? "" : ", ") + std::string(key);
  return keys;
}

[[noreturn]] void BadTolerance(ErrorCode code, const std::string& where, const std::string& problem) {
  throw Error(code, kTolerancesStage, where + " " + problem);
}

void CheckOrder(const Limit& limit, ErrorCode code, const std::string& where) {
  if (limit.min && limit.max && *limit.min > *limit.max) {
    BadTolerance(code, where,
                 "has min " + std::to_string(*limit.min) + " > max " + std::to_string(*limit.max));
  }
}

double FiniteNumber(const nlohmann::json& value, const std::string& where) {
  if (!value.is_number() || !std::isfinite(value.get<double>())) {
    BadTolerance(ErrorCode::kBadInput, where, "is not a finite number (found " + JsonText(value) + ")");
  }
  return value.get<double>();
}

bool TakesOperator(const std::string& key) {
  return key == schema::summary::kMaxRoundnessUm || key == schema::summary::kMaxRunoutUm ||
         key == schema::summary::kMaxArcErrorUm;
}

// One operator key of a form tolerance; false when `name` is none.
bool ParseOperatorKey(const std::string& key, const std::string& name, const nlohmann::json& value,
                      const std::string& where, NamedOperator& op) {
  const bool closed = key != schema::summary::kMaxArcErrorUm;
  if (name != "filter_upr" && name != "filter_cutoff_mm" && name != "filter" && name != "association")
    return false;
  if (!TakesOperator(key))
    BadTolerance(ErrorCode::kBadInput, where,
                 "names an operator, which arcwheel evaluates only for "
                 "max_roundness_um, max_runout_um and max_arc_error_um");
  if (name == "filter_upr" || name == "filter_cutoff_mm") {
    if (closed != (name == "filter_upr"))
      BadTolerance(ErrorCode::kBadInput, where,
                   closed ? "is for an open profile: a turn's filter is 'filter_upr'"
                          : "is for a closed profile: an arc's filter is 'filter_cutoff_mm'");
    const double cutoff = FiniteNumber(value, where);
    if (!(cutoff > 0.0))
      BadTolerance(ErrorCode::kBadInput, where, "is not above 0 (found " + JsonText(value) + ")");
    (name == "filter_upr" ? op.filter_upr : op.filter_cutoff_mm) = cutoff;
  } else if (name == "filter") {
    if (value != "none")
      BadTolerance(ErrorCode::kBadInput, where, "is not \"none\" (found " + JsonText(value) + ")");
    op.no_filter = true;
  } else {
    if (key == schema::summary::kMaxRunoutUm)
      BadTolerance(ErrorCode::kBadInput, where,
                   "names an association, but run-out is taken about the datum axis");
    const auto association =
        value.is_string() ? characteristics::ParseAssociation(value.get<std::string>()) : std::nullopt;
    if (!association)
      BadTolerance(ErrorCode::kBadInput, where,
                   "is not " + characteristics::AssociationNames() + " (found " + JsonText(value) + ")");
    op.association = value.get<std::string>();
  }
  return true;
}

Limit ParseLimit(const std::string& key, const nlohmann::json& value, const std::string& where,
                 NamedOperator& op) {
  Limit limit;
  if (value.is_number()) {
    limit.max = FiniteNumber(value, where);
    return limit;
  }
  if (!value.is_object())
    BadTolerance(ErrorCode::kBadInput, where, "is neither a number nor {\"min\":..,\"max\":..}");
  for (const auto& [name, bound] : value.items()) {
    if (name == "min") {
      limit.min = FiniteNumber(bound, where + ".min");
    } else if (name == "max") {
      limit.max = FiniteNumber(bound, where + ".max");
    } else if (!ParseOperatorKey(key, name, bound, where + "." + name, op)) {
      BadTolerance(ErrorCode::kBadInput, where + "." + name,
                   TakesOperator(key)
                       ? "is not 'min', 'max', 'filter_upr', 'filter_cutoff_mm', 'filter' or 'association'"
                       : "is not 'min' or 'max'");
    }
  }
  if (op.no_filter && (op.filter_upr || op.filter_cutoff_mm))
    BadTolerance(ErrorCode::kBadInput, where, "names both a cut-off and \"filter\": \"none\"");
  if (!limit.min && !limit.max) BadTolerance(ErrorCode::kBadInput, where, "has neither 'min' nor 'max'");
  CheckOrder(limit, ErrorCode::kBadInput, where);
  return limit;
}

std::optional<double> ParseBound(const std::string& text, const std::string& flag) {
  if (text.empty()) return std::nullopt;
  std::size_t used = 0;
  double value = 0.0;
  try {
    value = std::stod(text, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used != text.size() || !std::isfinite(value)) {
    BadTolerance(ErrorCode::kInvalidOption, "tolerance '" + flag + "'",
                 "has '" + text + "', which is not a number");
  }
  return value;
}

}  // namespace

Verdict Judge(double value, const std::optional<Limit>& limit) {
  if (!limit) return Verdict::kNoTolerance;
  if (!std::isfinite(value)) return Verdict::kFail;
  if (limit->min && value < *limit->min) return Verdict::kFail;
  if (limit->max && value > *limit->max) return Verdict::kFail;
  return Verdict::kPass;
}

Tolerances ParseTolerances(const std::string& text, const std::string& name) {
  const nlohmann::json root = ParseJsonText(text, name, kTolerancesStage);
  if (!root.is_object())
    throw Error(ErrorCode::kBadInput, kTolerancesStage, "'" + name + "' is not a JSON object");
  Tolerances tolerances;
  for (const auto& [key, value] : root.items()) {
    const std::string where = "'" + name + "' key '" + key + "'";
    if (key == "decision_rule") {
      const auto rule =
          value.is_string() ? uncertainty::DecisionRuleFromName(value.get<std::string>()) : std::nullopt;
      if (!rule)
        BadTolerance(ErrorCode::kBadInput, where,
                     "is not 'iso14253-1' or 'simple-acceptance' (found " + JsonText(value) + ")");
      tolerances.rule = rule;
      continue;
    }
    if (!IsHeadlineKey(key))
      BadTolerance(ErrorCode::kBadInput, where, "is not a headline quantity (" + KnownKeys() + ")");
    NamedOperator op;
    tolerances.limits[key] = ParseLimit(key, value, where, op);
    if (!op.Empty()) tolerances.operators[key] = op;
  }
  return tolerances;
}

Tolerances ReadTolerances(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(ErrorCode::kIo, kTolerancesStage, "cannot open '" + path.string() + "'");
  std::ostringstream contents;
  contents << stream.rdbuf();
  return ParseTolerances(contents.str(), path.string());
}

void AddToleranceFlag(Tolerances& tolerances, const std::string& flag) {
  const std::size_t equals = flag.find('=');
  if (equals == std::string::npos) {
    BadTolerance(ErrorCode::kInvalidOption, "tolerance '" + flag + "'", "is not KEY=MAX or KEY=MIN:MAX");
  }
  const std::string key = flag.substr(0, equals);
  if (!IsHeadlineKey(key)) {
    BadTolerance(ErrorCode::kInvalidOption, "tolerance '" + flag + "'",
                 "names no headline quantity (" + KnownKeys() + ")");
  }
  const std::string bounds = flag.substr(equals + 1);
  const std::size_t colon = bounds.find(':');
  Limit limit;
  if (colon == std::string::npos) {
    limit.max = ParseBound(bounds, flag);
  } else {
    limit.min = ParseBound(bounds.substr(0, colon), flag);
    limit.max = ParseBound(bounds.substr(colon + 1), flag);
  }
  if (!limit.min && !limit.max)
    BadTolerance(ErrorCode::kInvalidOption, "tolerance '" + flag + "'", "gives no limit");
  CheckOrder(limit, ErrorCode::kInvalidOption, "tolerance '" + flag + "'");
  tolerances.limits[key] = limit;
}

}  // namespace arcwheel::reports
