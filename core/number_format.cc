#include "core/number_format.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <regex>

namespace arcwheel {
namespace {

// "-0.000" and "+0.000" read as a signed value: a value that rounds to zero has no sign.
std::string WithoutSignOfZero(std::string text) {
  if (!text.empty() && (text.front() == '-' || text.front() == '+') &&
      text.find_first_not_of("+-0.") == std::string::npos) {
    return text.substr(1);
  }
  return text;
}

std::string DropTrailingZeros(std::string text) {
  const std::size_t exponent = text.find('e');
  std::string mantissa = text.substr(0, exponent);
  const std::string tail = exponent == std::string::npos ? "" : text.substr(exponent);
  if (mantissa.find('.') != std::string::npos) {
    mantissa.erase(mantissa.find_last_not_of('0') + 1);
    if (mantissa.back() == '.') mantissa.pop_back();
  }
  return mantissa + tail;
}

// Digits before the point of `text` as printed, leading zeros aside ("0.5" has none).
int IntegerDigits(const std::string& text) {
  int digits = 0;
  bool leading = true;
  for (char c : text) {
    if (c == '.' || c == 'e') break;
    if (!std::isdigit(static_cast<unsigned char>(c))) continue;
    if (leading && c == '0') continue;
    leading = false;
    ++digits;
  }
  return digits;
}

std::string FixedCapped(double value, int decimals, const char* sign) {
  if (!std::isfinite(value)) return "n/a";
  decimals = std::max(decimals, 0);
  std::string text = fmt::format(fmt::runtime(std::string("{:") + sign + ".{}f}"), value, decimals);
  // Rounding can add an integer digit (99999.995 -> 100000.00): decide on the printed text.
  for (int pass = 0; pass < 2 && SignificantDigitsShown(text) > kMaxShownDigits && decimals > 0; ++pass) {
    decimals = std::max(0, kMaxShownDigits - IntegerDigits(text));
    text = fmt::format(fmt::runtime(std::string("{:") + sign + ".{}f}"), value, decimals);
  }
  return WithoutSignOfZero(text);
}

}  // namespace

std::string ShowFixed(double value, int decimals) { return FixedCapped(value, decimals, ""); }

std::string ShowSigned(double value, int decimals) { return FixedCapped(value, decimals, "+"); }

std::string ShowSignificant(double value, int digits) {
  if (!std::isfinite(value)) return "n/a";
  digits = std::clamp(digits, 1, kMaxShownDigits);
  if (value == std::trunc(value) && std::abs(value) < 1e7) {
    return WithoutSignOfZero(fmt::format("{:.0f}", value));
  }
  return WithoutSignOfZero(DropTrailingZeros(fmt::format("{:.{}g}", value, digits)));
}

int SignificantDigitsShown(const std::string& text) {
  const std::size_t exponent = text.find_first_of("eE");
  const std::string mantissa = text.substr(0, exponent);
  std::string digits;
  for (char c : mantissa) {
    if (std::isdigit(static_cast<unsigned char>(c))) digits += c;
  }
  digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size()));
  if (mantissa.find('.') == std::string::npos) {
    // A whole number: its trailing zeros say where it was rounded, not what was measured.
    const std::size_t last = digits.find_last_not_of('0');
    digits.erase(last == std::string::npos ? 0 : last + 1);
  }
  return static_cast<int>(digits.size());
}

std::string ShowNumbersIn(std::string_view text) {
  static const std::regex kNumber(R"([-+]?\d+\.\d+(?:[eE][-+]?\d+)?)");
  std::string shown;
  const std::string input(text);
  auto last = input.cbegin();
  for (auto it = std::sregex_iterator(input.begin(), input.end(), kNumber); it != std::sregex_iterator();
       ++it) {
    const std::string token = it->str();
    shown.append(last, input.cbegin() + it->position());
    shown += SignificantDigitsShown(token) > kMaxShownDigits ? ShowSignificant(std::stod(token)) : token;
    last = input.cbegin() + it->position() + it->length();
  }
  shown.append(last, input.cend());
  return shown;
}

}  // namespace arcwheel

std::string fmt::formatter<arcwheel::Shown>::Text(double value) const {
  using namespace arcwheel;
  switch (type) {
    case 'f':
      return plus ? ShowSigned(value, precision < 0 ? 6 : precision)
                  : ShowFixed(value, precision < 0 ? 6 : precision);
    case 'e':
      if (!std::isfinite(value)) return "n/a";
      return fmt::format("{:.{}e}", value, std::clamp(precision < 0 ? 6 : precision, 0, kMaxShownDigits - 1));
    default: {
      const std::string text = ShowSignificant(value, precision <= 0 ? kMaxShownDigits : precision);
      return plus && std::isfinite(value) && value >= 0 ? "+" + text : text;
    }
  }
}
