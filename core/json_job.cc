#include "core/json_job.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel {

using nlohmann::json;

JsonSection::JsonSection(const json& document, JsonJobContext context)
    : JsonSection(&document, "", std::make_shared<const JsonJobContext>(std::move(context))) {}

JsonSection::JsonSection(const json* object, std::string prefix,
                         std::shared_ptr<const JsonJobContext> context)
    : object_(object), prefix_(std::move(prefix)), context_(std::move(context)) {
  if (object_ != nullptr && !object_->is_object()) Expected("", "an object");
}

bool JsonSection::Has(const std::string& key) const {
  return object_ != nullptr && object_->contains(key) && !object_->at(key).is_null();
}

std::string JsonSection::Dotted(const std::string& key) const {
  if (key.empty()) return prefix_.empty() ? "(root)" : prefix_;
  return prefix_.empty() ? key : prefix_ + "." + key;
}

const json& JsonSection::At(const std::string& key) const { return object_->at(key); }

void JsonSection::Fail(const std::string& key, const std::string& detail) const {
  throw Error(ErrorCode::kBadInput, context_->stage,
              fmt::format("'{}': key '{}' {}", context_->file, Dotted(key), detail));
}

void JsonSection::Expected(const std::string& key, const std::string& expected) const {
  std::string given = "nothing: the key is missing";
  if (key.empty() && object_ != nullptr) {
    given = object_->dump();
  } else if (Has(key)) {
    given = JsonText(At(key));
  }
  Fail(key, fmt::format("expected {}, got {}", expected, given));
}

void JsonSection::ThrowIfProblems(const std::vector<std::string>& problems) const {
  if (problems.empty()) return;
  throw Error(ErrorCode::kBadInput, context_->stage,
              fmt::format("'{}': {}", context_->file, JoinProblems(problems)));
}

double JsonSection::FiniteNumber(const std::string& key, const std::string& expected) const {
  const json& v = At(key);
  if (!v.is_number() || !std::isfinite(v.get<double>())) Expected(key, expected);
  return v.get<double>();
}

double JsonSection::Number(const std::string& key, double fallback) {
  used_.insert(key);
  const double value = Has(key) ? FiniteNumber(key, "a finite number") : fallback;
  resolved_[key] = value;
  return value;
}

double JsonSection::RequiredNumber(const std::string& key) {
  if (!Has(key)) Expected(key, "a finite number");
  return Number(key, 0.0);
}

std::optional<double> JsonSection::OptionalNumber(const std::string& key) {
  used_.insert(key);
  if (!Has(key)) return std::nullopt;
  return Number(key, 0.0);
}

int JsonSection::WholeNumber(const std::string& key, int fallback, int low, int high) {
  used_.insert(key);
  const std::string expected = fmt::format("a whole number within {} .. {}", low, high);
  const double value = Has(key) ? FiniteNumber(key, expected) : fallback;
  if (!(value >= low && value <= high) || value != std::floor(value)) Expected(key, expected);
  resolved_[key] = static_cast<int>(value);
  return static_cast<int>(value);
}

int JsonSection::Integer(const std::string& key, int fallback) {
  used_.insert(key);
  int value = fallback;
  if (Has(key)) {
    const json& v = At(key);
    constexpr auto kLow = std::numeric_limits<int>::min(), kHigh = std::numeric_limits<int>::max();
    const bool fits = v.is_number_unsigned() ? v.get<std::uint64_t>() <= static_cast<std::uint64_t>(kHigh)
                                             : v.is_number_integer() && v.get<std::int64_t>() >= kLow &&
                                                   v.get<std::int64_t>() <= kHigh;
    if (!fits) Expected(key, "an integer");
    value = v.get<int>();
  }
  resolved_[key] = value;
  return value;
}

bool JsonSection::Boolean(const std::string& key, bool fallback) {
  used_.insert(key);
  bool value = fallback;
  if (Has(key)) {
    if (!At(key).is_boolean()) Expected(key, "true or false");
    value = At(key).get<bool>();
  }
  resolved_[key] = value;
  return value;
}

std::string JsonSection::String(const std::string& key, const std::string& fallback) {
  return OptionalString(key).value_or(fallback);
}

std::optional<std::string> JsonSection::OptionalString(const std::string& key) {
  used_.insert(key);
  if (!Has(key)) return std::nullopt;
  if (!At(key).is_string()) Expected(key, "a string");
  resolved_[key] = At(key).get<std::string>();
  return At(key).get<std::string>();
}

std::string JsonSection::Choice(const std::string& key, const std::vector<std::string>& choices) {
  used_.insert(key);
  const std::string expected = fmt::format("one of \"{}\"", fmt::join(choices, "\", \""));
  std::string value = choices.front();
  if (Has(key)) {
    if (!At(key).is_string()) Expected(key, expected);
    value = At(key).get<std::string>();
    if (std::find(choices.begin(), choices.end(), value) == choices.end()) Expected(key, expected);
  }
  resolved_[key] = value;
  return value;
}

std::vector<double> JsonSection::Numbers(const std::string& key, std::vector<double> fallback) {
  used_.insert(key);
  if (Has(key)) {
    const std::string expected = fmt::format("an array of {} finite numbers", fallback.size());
    const json& v = At(key);
    if (!v.is_array() || v.size() != fallback.size()) Expected(key, expected);
    for (std::size_t i = 0; i < v.size(); ++i) {
      if (!v[i].is_number() || !std::isfinite(v[i].get<double>())) Expected(key, expected);
      fallback[i] = v[i].get<double>();
    }
  }
  resolved_[key] = fallback;
  return fallback;
}

std::vector<double> JsonSection::RequiredNumbers(const std::string& key, std::size_t count) {
  if (!Has(key)) Expected(key, fmt::format("an array of {} finite numbers", count));
  return Numbers(key, std::vector<double>(count, 0.0));
}

const json& JsonSection::Raw(const std::string& key) {
  used_.insert(key);
  resolved_[key] = At(key);
  return At(key);
}

void JsonSection::Section(const std::string& key, bool required,
                          const std::function<void(JsonSection&)>& read) {
  used_.insert(key);
  if (required && !Has(key)) Expected(key, "an object");
  JsonSection child(Has(key) ? &At(key) : nullptr, Dotted(key), context_);
  read(child);
  child.Finish();
  resolved_[key] = child.resolved_;
}

void JsonSection::Elements(const std::string& key, const std::string& what,
                           const std::function<void(JsonSection&)>& read) {
  used_.insert(key);
  const std::string expected = fmt::format("an array of {}", what);
  if (!Has(key) || !At(key).is_array()) Expected(key, expected);
  json resolved = json::array();
  for (std::size_t i = 0; i < At(key).size(); ++i) {
    JsonSection element(&At(key)[i], fmt::format("{}[{}]", Dotted(key), i), context_);
    read(element);
    element.Finish();
    resolved.push_back(element.resolved_);
  }
  resolved_[key] = resolved;
}

void JsonSection::SetResolved(const std::string& key, const json& value) { resolved_[key] = value; }

void JsonSection::Finish() const {
  if (object_ == nullptr) return;
  std::vector<std::string> unknown;
  for (const auto& [key, value] : object_->items()) {
    if (!used_.count(key)) unknown.push_back(Dotted(key));
  }
  if (unknown.empty()) return;
  throw Error(ErrorCode::kBadInput, context_->stage,
              fmt::format("'{}': unknown key{} '{}' (see {} for the job keys)", context_->file,
                          unknown.size() == 1 ? "" : "s", fmt::join(unknown, "', '"), context_->docs_page));
}

}  // namespace arcwheel
