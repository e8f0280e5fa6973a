#include "core/statistics.h"

#include <gtest/gtest.h>

#include <cmath>

namespace arcwheel {
namespace {

// The upper tail of the chi-square distribution has closed forms for 1, 2 and 4 degrees of
// freedom: erfc(sqrt(x/2)), exp(-x/2) and exp(-x/2)(1 + x/2).
TEST(ChiSquaredUpperTail, EqualsTheClosedFormsOfOneTwoAndFourDegreesOfFreedom) {
  for (const double x : {0.0, 1e-6, 0.3, 1.0, 3.84, 10.0, 60.0}) {
    const double one = std::erfc(std::sqrt(x / 2.0));
    const double two = std::exp(-x / 2.0);
    const double four = std::exp(-x / 2.0) * (1.0 + x / 2.0);
    EXPECT_NEAR(ChiSquaredUpperTail(x, 1.0), one, 1e-14 * one + 1e-300) << x;
    EXPECT_NEAR(ChiSquaredUpperTail(x, 2.0), two, 1e-14 * two) << x;
    EXPECT_NEAR(ChiSquaredUpperTail(x, 4.0), four, 1e-14 * four) << x;
  }
}

TEST(ChiSquaredUpperTail, GivesFivePercentAtTheTabulatedCriticalValues) {
  // Critical values of the 5 % test (NIST/SEMATECH e-Handbook, table 1.3.6.7.4).
  EXPECT_NEAR(ChiSquaredUpperTail(3.841, 1.0), 0.05, 2e-5);
  EXPECT_NEAR(ChiSquaredUpperTail(11.070, 5.0), 0.05, 2e-5);
  EXPECT_NEAR(ChiSquaredUpperTail(18.307, 10.0), 0.05, 2e-5);
}

}  // namespace
}  // namespace arcwheel
