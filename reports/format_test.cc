#include "reports/format.h"

#include <gtest/gtest.h>

#include <limits>
#include <nlohmann/json.hpp>

namespace arcwheel::reports {
namespace {

TEST(FormatFixed, UsesTheTypographicMinusAndDropsTheSignOfAZero) {
  EXPECT_EQ(FormatFixed(-1.25, 1), "−1.2");  // round half to even, as printf does
  EXPECT_EQ(FormatFixed(-0.0004, 3), "0.000");
  EXPECT_EQ(FormatFixed(7.125, 2), "7.12");
  EXPECT_EQ(FormatFixed(std::numeric_limits<double>::quiet_NaN(), 2), "n/a");
}

TEST(FormatValue, WritesTheUnitsDigitsAndSymbol) {
  EXPECT_EQ(FormatValue(55.442224536, units::kRadius_mm), "55.44222 mm");
  EXPECT_EQ(FormatValue(0.0406371, units::kLength_mm), "0.0406 mm");
  EXPECT_EQ(FormatValue(7.1349, units::kLength_um), "7.13 µm");
  EXPECT_EQ(FormatValue(1.5, units::kSpeed_um_per_s), "1.50 µm/s");
  EXPECT_EQ(FormatValue(INFINITY, units::kLength_um), "n/a");
  EXPECT_EQ(FormatWithSigma(-90.04, 2.31, units::kAngle_deg), "−90.0 ± 2.3 deg");
}

TEST(FormatSignificant, KeepsSevenDigitsAndWritesWholeNumbersWhole) {
  EXPECT_EQ(FormatSignificant(0.19967978891870555), "0.1996798");
  EXPECT_EQ(FormatSignificant(500.0), "500");
  EXPECT_EQ(FormatSignificant(360.0), "360");
  EXPECT_EQ(FormatSignificant(0.1), "0.1");
  EXPECT_EQ(FormatSignificant(-2.5e-7), "−2.5e-07");
  EXPECT_EQ(FormatSignificant(1234567.89), "1234568");
  EXPECT_EQ(FormatSignificant(12345678.9), "1.234568e+07");
}

TEST(FormatDuration, PicksTheUnitThatSuitsTheDuration) {
  EXPECT_EQ(FormatDuration(1e-4), "0.1 ms");
  EXPECT_EQ(FormatDuration(5e-6), "5 µs");
  EXPECT_EQ(FormatDuration(2.5), "2.50 s");
  EXPECT_EQ(FormatDuration(754.0), "12.6 min");
  EXPECT_EQ(FormatDuration(7200.0), "2.00 h");
}

TEST(FormatHeight, WritesNanometreResidualsInNanometres) {
  EXPECT_EQ(FormatHeight(0.0123, 0.05), "12.3 nm");
  EXPECT_EQ(FormatHeight(0.512, 1.8), "0.512 µm");
  EXPECT_EQ(FormatHeight(-0.004, 0.02), "−4.0 nm");
}

TEST(FormatJsonValue, WritesIntegersAsIntegersAndLongNumbersShort) {
  EXPECT_EQ(FormatJsonValue(nlohmann::json(360)), "360");
  EXPECT_EQ(FormatJsonValue(nlohmann::json(8.0)), "8");
  EXPECT_EQ(FormatJsonValue(nlohmann::json(0.19967978891870555)), "0.1996798");
  EXPECT_EQ(FormatJsonValue(nlohmann::json("band")), "band");
  EXPECT_EQ(FormatJsonValue(nlohmann::json::parse("[1, 2.5, true]")), "[1, 2.5, true]");
  EXPECT_EQ(FormatJsonValue(nlohmann::json(-3)), "−3");
}

}  // namespace
}  // namespace arcwheel::reports
