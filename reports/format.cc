#include "reports/format.h"

#include <fmt/format.h>

#include <cmath>
#include <nlohmann/json.hpp>

#include "core/json_text.h"
#include "core/number_format.h"

namespace arcwheel::reports {
namespace {

// format.h names the default of FormatSignificant without including the formatter's header.
static_assert(kMaxShownDigits == 7);

// The typographic minus: a hyphen reads as a dash. A value that rounds to zero loses its sign.
std::string WithMinus(std::string text) {
  if (text.empty() || text.front() != '-') return text;
  if (text.find_first_not_of("-0.") == std::string::npos) return text.substr(1);
  return "−" + text.substr(1);
}

}  // namespace

std::string FormatFixed(double value, int decimals) {
  if (!std::isfinite(value)) return "n/a";
  return WithMinus(ShowFixed(value, decimals));
}

std::string FormatValue(double value, Unit unit) {
  if (!std::isfinite(value)) return "n/a";
  return FormatFixed(value, unit.decimals) + " " + std::string(unit.symbol);
}

std::string FormatWithSigma(double value, double sigma, Unit unit) {
  if (!std::isfinite(value)) return "n/a";
  return FormatFixed(value, unit.decimals) + " ± " + FormatFixed(sigma, unit.decimals) + " " +
         std::string(unit.symbol);
}

std::string FormatSignificant(double value, int digits) {
  if (!std::isfinite(value)) return "n/a";
  return WithMinus(ShowSignificant(value, digits));
}

std::string FormatDuration(double seconds) {
  if (!std::isfinite(seconds)) return "n/a";
  const double magnitude = std::abs(seconds);
  if (magnitude == 0.0) return "0 s";
  if (magnitude < 1e-5) return FormatSignificant(seconds * 1e6, 3) + " µs";
  if (magnitude < 1.0) return FormatSignificant(seconds * 1e3, 3) + " ms";
  if (magnitude < 600.0) return FormatFixed(seconds, 2) + " s";
  if (magnitude < 7200.0) return FormatFixed(seconds / 60.0, 1) + " min";
  return FormatFixed(seconds / 3600.0, 2) + " h";
}

std::string FormatHeight(double value_um, double scale_um) {
  if (std::isfinite(scale_um) && std::abs(scale_um) < 0.1)
    return FormatValue(value_um * 1000.0, units::kLength_nm);
  return FormatFixed(value_um, 3) + " µm";
}

std::string FormatJsonValue(const nlohmann::json& value) {
  if (value.is_string()) return value.get<std::string>();
  if (value.is_number_integer()) return WithMinus(JsonText(value));
  if (value.is_number()) return FormatSignificant(value.get<double>());
  if (value.is_boolean()) return value.get<bool>() ? "true" : "false";
  if (value.is_null()) return "null";
  if (value.is_array()) {
    std::string text = "[";
    for (std::size_t i = 0; i < value.size(); ++i) text += (i == 0 ? "" : ", ") + FormatJsonValue(value[i]);
    return text + "]";
  }
  return JsonText(value);
}

}  // namespace arcwheel::reports
