#pragma once
// The one formatter of the numbers a person reads: terminal lines, reports, and JSON shown in a
// report. Stored files (summary.json, HDF5, CSV, G-code) keep full precision and do not use it.
//
// A number is shown with at most kMaxShownDigits significant digits. A double carries 15-17, and
// printing them all ("55.401577631285676 mm") claims a resolution no measurement has; seven keep
// a 10 nm step on a 100 mm radius (100.00001 mm is the largest such case we print).

#include <fmt/format.h>

#include <algorithm>
#include <string>
#include <string_view>

namespace arcwheel {

inline constexpr int kMaxShownDigits = 7;

// `value` with `decimals` decimals, fewer where that would show more than kMaxShownDigits
// significant digits: (55.401577631, 5) -> "55.40158", (12345.6789, 4) -> "12345.68",
// (-0.0001, 3) -> "0.000" (a value that rounds to zero has no sign), NaN -> "n/a". A whole
// number of more than seven digits keeps its integer digits ((123456789.4, 2) -> "123456789").
[[nodiscard]] std::string ShowFixed(double value, int decimals);

// The same with an explicit sign, for changes: (0.00123, 4) -> "+0.0012"; a change that rounds to
// zero is "+0.0000" whichever its sign.
[[nodiscard]] std::string ShowSigned(double value, int decimals);

// At most `digits` (1 to kMaxShownDigits) significant digits, trailing zeros and a bare point
// dropped, an exponent where the number is very large or small: 0.19967978 -> "0.1996798",
// 500.0 -> "500", 1e-7 -> "1e-07". For numbers without a fixed scale (options, limits as given).
[[nodiscard]] std::string ShowSignificant(double value, int digits = kMaxShownDigits);

// How many significant digits `text`, a number as printed ("-0.00120", "55.40158", "1.5e-07"),
// shows: leading zeros do not count, trailing zeros after the point do, trailing zeros of a whole
// number do not ("132000" shows 3). For tests that read what a person is shown.
[[nodiscard]] int SignificantDigitsShown(const std::string& text);

// A free text made for a stored file (a wheel's description, a G-code comment) as a person reads
// it: every number in it with more than kMaxShownDigits significant digits shown with seven
// ("Ra = 55.401577631285676 mm" -> "Ra = 55.40158 mm"); shorter numbers and other text unchanged.
[[nodiscard]] std::string ShowNumbersIn(std::string_view text);

// A number to format through ShowFixed / ShowSigned / ShowSignificant from a fmt format string:
// fmt::print("{:.5f} +- {:.5f} mm", Shown(radius), Shown(sigma)). The spec takes an alignment
// ('<', '>'), '+', a width, a precision and the type f (fixed: ShowFixed), g or none
// (ShowSignificant) or e (exponent, at most seven significant digits).
struct Shown {
  double value;
  explicit Shown(double v) : value(v) {}
};

}  // namespace arcwheel

template <>
struct fmt::formatter<arcwheel::Shown> {
  char align = '>';
  bool plus = false;
  int width = 0;
  int precision = -1;
  char type = 0;

  constexpr auto parse(fmt::format_parse_context& context) -> decltype(context.begin()) {
    auto it = context.begin();
    const auto end = context.end();
    if (it != end && (*it == '<' || *it == '>')) align = *it++;
    if (it != end && *it == '+') plus = true, ++it;
    while (it != end && *it >= '0' && *it <= '9') width = width * 10 + (*it++ - '0');
    if (it != end && *it == '.') {
      ++it;
      precision = 0;
      while (it != end && *it >= '0' && *it <= '9') precision = precision * 10 + (*it++ - '0');
    }
    if (it != end && (*it == 'f' || *it == 'g' || *it == 'e')) type = *it++;
    if (it != end && *it != '}') throw fmt::format_error("arcwheel::Shown: unsupported format spec");
    return it;
  }

  auto format(const arcwheel::Shown& shown, fmt::format_context& context) const -> decltype(context.out()) {
    const std::string text = Text(shown.value);
    const int pad = width - static_cast<int>(text.size());
    auto out = context.out();
    if (align == '>' && pad > 0) out = std::fill_n(out, pad, ' ');
    out = std::copy(text.begin(), text.end(), out);
    if (align == '<' && pad > 0) out = std::fill_n(out, pad, ' ');
    return out;
  }

 private:
  [[nodiscard]] std::string Text(double value) const;
};
