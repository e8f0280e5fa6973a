// The one formatter of numbers a person reads: at most seven significant digits.

#include "core/number_format.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

namespace arcwheel {
namespace {

TEST(ShowFixed, KeepsTheDecimalsAskedForUpToSevenSignificantDigits) {
  EXPECT_EQ(ShowFixed(55.401577631285676, 5), "55.40158");
  EXPECT_EQ(ShowFixed(0.000123456789, 5), "0.00012");
  EXPECT_EQ(ShowFixed(12345.6789, 4), "12345.68");
  EXPECT_EQ(ShowFixed(144.59842236871432, 5), "144.5984");
  EXPECT_EQ(ShowFixed(3.0, 2), "3.00");
  EXPECT_EQ(ShowFixed(-1.23456, 3), "-1.235");
}

TEST(ShowFixed, CountsTheDigitThatRoundingAdds) {
  EXPECT_EQ(ShowFixed(99999.996, 2), "100000.0");  // not 100000.00: eight digits
  EXPECT_EQ(ShowFixed(9999999.6, 1), "10000000");
}

TEST(ShowFixed, GivesAZeroNoMinusAndANonFiniteValueNoNumber) {
  EXPECT_EQ(ShowFixed(-0.0001, 3), "0.000");
  EXPECT_EQ(ShowSigned(-0.0001, 3), "+0.000");
  EXPECT_EQ(ShowFixed(std::nan(""), 3), "n/a");
  EXPECT_EQ(ShowFixed(std::numeric_limits<double>::infinity(), 3), "n/a");
}

TEST(ShowSigned, WritesThePlus) {
  EXPECT_EQ(ShowSigned(0.00123, 4), "+0.0012");
  EXPECT_EQ(ShowSigned(-0.1, 4), "-0.1000");
}

TEST(ShowSignificant, DropsTrailingZerosAndWritesWholeNumbersWhole) {
  EXPECT_EQ(ShowSignificant(0.19967978891870555), "0.1996798");
  EXPECT_EQ(ShowSignificant(0.19967978891870555, 5), "0.19968");
  EXPECT_EQ(ShowSignificant(500.0), "500");
  EXPECT_EQ(ShowSignificant(1e-7), "1e-07");
  EXPECT_EQ(ShowSignificant(132000000.0), "1.32e+08");
  EXPECT_EQ(ShowSignificant(55.401577631285676, 12), "55.40158");  // never more than seven
}

TEST(SignificantDigitsShown, CountsAsAMetrologistReadsANumber) {
  EXPECT_EQ(SignificantDigitsShown("55.401577631285676"), 17);
  EXPECT_EQ(SignificantDigitsShown("-0.00120"), 3);
  EXPECT_EQ(SignificantDigitsShown("132000"), 3);
  EXPECT_EQ(SignificantDigitsShown("1.5e-07"), 2);
  EXPECT_EQ(SignificantDigitsShown("0.000"), 0);
}

TEST(ShowNumbersIn, ShortensOnlyTheOverlongNumbersOfAText) {
  EXPECT_EQ(ShowNumbersIn("wheel Ra = 55.401577631285676 mm, Rb = 144.59842236871432 mm, 360 phases, 0.5 um"),
            "wheel Ra = 55.40158 mm, Rb = 144.5984 mm, 360 phases, 0.5 um");
}

TEST(Shown, FormatsThroughTheSpecOfAFormatString) {
  EXPECT_EQ(fmt::format("{:.5f} +- {:.5f} mm", Shown(55.401577631285676), Shown(0.0000312)),
            "55.40158 +- 0.00003 mm");
  EXPECT_EQ(fmt::format("{:+.4f}", Shown(0.00123)), "+0.0012");
  EXPECT_EQ(fmt::format("[{:8.3f}]", Shown(1.5)), "[   1.500]");
  EXPECT_EQ(fmt::format("[{:<8.3f}]", Shown(1.5)), "[1.500   ]");
  EXPECT_EQ(fmt::format("{:.2g}", Shown(0.000123456)), "0.00012");
  EXPECT_EQ(fmt::format("{:.2e}", Shown(0.000123456)), "1.23e-04");
  EXPECT_EQ(fmt::format("{}", Shown(144.59842236871432)), "144.5984");
}

}  // namespace
}  // namespace arcwheel
