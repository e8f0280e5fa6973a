#include "store/database.h"

#include "core/text_pattern.h"

namespace arcwheel::store::internal {

std::optional<std::string> AsText(const Value& value) {
  if (const auto* text = std::get_if<std::string>(&value)) return *text;
  if (const auto* integer = std::get_if<std::int64_t>(&value)) return std::to_string(*integer);
  return std::nullopt;
}

std::optional<double> AsDouble(const Value& value) {
  if (const auto* number = std::get_if<double>(&value)) return *number;
  if (const auto* integer = std::get_if<std::int64_t>(&value)) return static_cast<double>(*integer);
  if (const auto* text = std::get_if<std::string>(&value)) {
    // PostgreSQL hands every value as text; float8 prints the shortest text that reads back exactly.
    try {
      return std::stod(*text);
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  return std::nullopt;
}

std::optional<std::int64_t> AsInteger(const Value& value) {
  if (const auto* integer = std::get_if<std::int64_t>(&value)) return *integer;
  if (const auto* text = std::get_if<std::string>(&value)) {
    try {
      return std::stoll(*text);
    } catch (const std::exception&) {
      return std::nullopt;
    }
  }
  return std::nullopt;
}

std::string WithoutPassword(const std::string& url) {
  static const TextPattern kPassword(R"(^([a-z]+://[^:/@]*):[^@]*@)");
  static const TextPattern kPasswordParameter(R"(password=[^&\s]*)");
  return kPasswordParameter.ReplaceIn(kPassword.ReplaceIn(url, "$1:***@"), "password=***");
}

}  // namespace arcwheel::store::internal
