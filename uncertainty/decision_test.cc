// ISO 14253-1:2017 decisions at limits placed by hand around a value and its U.

#include "uncertainty/decision.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace arcwheel::uncertainty {
namespace {

constexpr double kValue = 10.0;
constexpr double kU = 2.0;

Decision Iso(const Specification& specification, double value = kValue, double u = kU) {
  return Decide(value, u, specification);
}

TEST(Decide, LimitsAtHalfTheUncertaintyFromTheValueProveNothing) {
  EXPECT_EQ(Iso({.max = kValue + kU / 2}), Decision::kNotProven);
  EXPECT_EQ(Iso({.max = kValue - kU / 2}), Decision::kNotProven);
  EXPECT_EQ(Iso({.min = kValue - kU / 2}), Decision::kNotProven);
  EXPECT_EQ(Iso({.min = kValue + kU / 2}), Decision::kNotProven);
  EXPECT_EQ(Iso({.min = kValue - kU / 2, .max = kValue + 3 * kU}), Decision::kNotProven);
}

TEST(Decide, LimitsClearOfTheUncertaintyProveConformanceOrNonconformance) {
  // One-sided upper limit.
  EXPECT_EQ(Iso({.max = kValue + 1.5 * kU}), Decision::kConforms);
  EXPECT_EQ(Iso({.max = kValue - 1.5 * kU}), Decision::kDoesNotConform);
  // One-sided lower limit.
  EXPECT_EQ(Iso({.min = kValue - 1.5 * kU}), Decision::kConforms);
  EXPECT_EQ(Iso({.min = kValue + 1.5 * kU}), Decision::kDoesNotConform);
  // Two-sided.
  EXPECT_EQ(Iso({.min = kValue - 1.5 * kU, .max = kValue + 1.5 * kU}), Decision::kConforms);
  EXPECT_EQ(Iso({.min = kValue + 1.5 * kU, .max = kValue + 4 * kU}), Decision::kDoesNotConform);
  EXPECT_EQ(Iso({.min = kValue - 4 * kU, .max = kValue - 1.5 * kU}), Decision::kDoesNotConform);
}

TEST(Decide, ATwoSidedZoneNarrowerThanTheIntervalProvesNothing) {
  EXPECT_EQ(Iso({.min = kValue - kU / 2, .max = kValue + kU / 2}), Decision::kNotProven);
}

TEST(Decide, TheIntervalTouchingALimitFromInsideConforms) {
  // The specification zone is closed (ISO 14253-1 3.6): value + U == max lies inside it.
  EXPECT_EQ(Iso({.max = 12.0}), Decision::kConforms);
  EXPECT_EQ(Iso({.max = 8.0}), Decision::kNotProven);  // value - U == max: not outside
}

TEST(Decide, SimpleAcceptanceComparesTheValueAlone) {
  const DecisionOptions shared{.rule = DecisionRule::kSimpleAcceptance};
  EXPECT_EQ(Decide(kValue, kU, {.max = kValue + kU / 2}, shared), Decision::kConforms);
  EXPECT_EQ(Decide(kValue, kU, {.max = kValue - kU / 2}, shared), Decision::kDoesNotConform);
  EXPECT_EQ(Decide(kValue, kU, {.min = kValue + kU / 2}, shared), Decision::kDoesNotConform);
  EXPECT_EQ(Decide(kValue, kU, {.min = kValue, .max = kValue}, shared), Decision::kConforms);
  EXPECT_EQ(Decide(std::nan(""), kU, {.max = 1.0}, shared), Decision::kDoesNotConform);
}

TEST(Decide, AValueOrUncertaintyThatCouldNotBeComputedProvesNothing) {
  EXPECT_EQ(Iso({.max = 100.0}, std::nan("")), Decision::kNotProven);
  EXPECT_EQ(Iso({.max = 100.0}, kValue, std::nan("")), Decision::kNotProven);
}

TEST(Overall, NonconformanceOutweighsNotProvenWhichOutweighsConformance) {
  using D = Decision;
  EXPECT_EQ(Overall(std::vector<D>{D::kConforms, D::kNotProven, D::kDoesNotConform}), D::kDoesNotConform);
  EXPECT_EQ(Overall(std::vector<D>{D::kConforms, D::kNotProven}), D::kNotProven);
  EXPECT_EQ(Overall(std::vector<D>{D::kConforms}), D::kConforms);
  EXPECT_EQ(Overall(std::vector<D>{}), std::nullopt);
}

TEST(DecisionRuleFromName, ReadsTheNamesItWrites) {
  for (const DecisionRule rule : {DecisionRule::kIso14253, DecisionRule::kSimpleAcceptance})
    EXPECT_EQ(DecisionRuleFromName(DecisionRuleName(rule)), rule);
  EXPECT_EQ(DecisionRuleFromName("guard-band"), std::nullopt);
}

}  // namespace
}  // namespace arcwheel::uncertainty
