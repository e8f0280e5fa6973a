#pragma once
// The reports' typography over the one number formatter (core/number_format.h): every number a
// report prints (tables, captions, legends) goes through these functions, so that a quantity has
// the same unit and digits everywhere, and the same digits as the terminal shows.
//
// Rules: a minus sign is U+2212 ("−"), as in plot ticks; a value that rounds to zero has no sign;
// a value that is not finite prints as "n/a"; integers print as integers ("360", not "360.0");
// numbers without a fixed scale (processing parameters, limits as given) keep at most
// kMaxShownDigits (seven) significant digits with trailing zeros dropped ("0.1996798", "500").

#include <cstdint>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>

namespace arcwheel::reports {

// A unit and the decimals its values are shown with.
struct Unit {
  std::string_view symbol;
  int decimals = 0;
};

namespace units {
inline constexpr Unit kRadius_mm{"mm", 5};    // mean arc radius and its sigma: 10 nm steps
inline constexpr Unit kLength_mm{"mm", 4};    // ranges and deviations: 0.1 um steps
inline constexpr Unit kPosition_mm{"mm", 3};  // axial positions, band limits
inline constexpr Unit kLength_um{"µm", 2};
inline constexpr Unit kNoise_um{"µm", 3};  // noise estimates, residual RMS
inline constexpr Unit kLength_nm{"nm", 1};
inline constexpr Unit kPercent{"%", 3};
inline constexpr Unit kAngle_deg{"deg", 1};
inline constexpr Unit kSpeed_rpm{"rpm", 2};
inline constexpr Unit kFeed_mm_per_min{"mm/min", 1};
inline constexpr Unit kSpeed_mm_per_s{"mm/s", 3};
inline constexpr Unit kSpeed_um_per_s{"µm/s", 2};
inline constexpr Unit kAcceleration_mm_per_s2{"mm/s²", 1};
inline constexpr Unit kWear_um_per_h{"µm/h", 3};
}  // namespace units

// `value` with `decimals` decimals and the typographic minus; "n/a" when not finite.
[[nodiscard]] std::string FormatFixed(double value, int decimals);

// "7.13 µm"; "n/a" (without unit) when not finite.
[[nodiscard]] std::string FormatValue(double value, Unit unit);

// "75.01234 ± 0.00021 mm", value and sigma at the unit's decimals.
[[nodiscard]] std::string FormatWithSigma(double value, double sigma, Unit unit);

// At most `digits` significant digits, trailing zeros (and a bare point) dropped: 0.19967978 ->
// "0.1996798", 500.0 -> "500", 1e-7 -> "1e−07". For numbers without a fixed scale.
[[nodiscard]] std::string FormatSignificant(double value, int digits = 7);

// A duration with the unit that suits it: 5e-6 -> "5 µs", 1e-4 -> "0.1 ms", 2.5 -> "2.50 s", 754 -> "12.6
// min", 7200 -> "2.00 h".
[[nodiscard]] std::string FormatDuration(double seconds);

// A height given in um: in nm (1 decimal) when `scale_um`, the size of the figures it is shown
// with, is below 0.1 um, else in um with 3 decimals.
[[nodiscard]] std::string FormatHeight(double value_um, double scale_um);

// A JSON leaf as a table shows it: strings unquoted, integers as integers, other numbers by
// FormatSignificant, booleans and null as words, arrays as "[a, b]".
[[nodiscard]] std::string FormatJsonValue(const nlohmann::json& value);

}  // namespace arcwheel::reports
