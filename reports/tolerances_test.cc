#include "reports/tolerances.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <limits>

#include "core/error.h"

namespace arcwheel::reports {
namespace {

using ::testing::HasSubstr;

TEST(Judge, PassesInsideInclusiveLimitsAndFailsOutside) {
  const Limit band{.min = 74.9, .max = 75.1};
  EXPECT_EQ(Judge(75.0, band), Verdict::kPass);
  EXPECT_EQ(Judge(75.1, band), Verdict::kPass) << "limits are inclusive";
  EXPECT_EQ(Judge(74.9, band), Verdict::kPass);
  EXPECT_EQ(Judge(75.1000001, band), Verdict::kFail);
  EXPECT_EQ(Judge(74.8999999, band), Verdict::kFail);
  EXPECT_EQ(Judge(3.0, Limit{.max = 2.0}), Verdict::kFail);
  EXPECT_EQ(Judge(-50.0, Limit{.max = 2.0}), Verdict::kPass);
  EXPECT_EQ(Judge(1.0, Limit{.min = 2.0}), Verdict::kFail);
  EXPECT_EQ(Judge(1.0, std::nullopt), Verdict::kNoTolerance);
  EXPECT_EQ(Judge(std::numeric_limits<double>::quiet_NaN(), Limit{.max = 2.0}), Verdict::kFail)
      << "a value that could not be computed cannot pass";
}

TEST(ParseTolerances, ReadsNumbersAsUpperLimitsAndObjectsAsRanges) {
  const Tolerances t = ParseTolerances(R"({"max_arc_error_um": 3.5,
      "mean_arc_radius_mm": {"min": 74.95, "max": 75.05}, "max_runout_um": {"max": 10}})",
                                       "tol.json");
  ASSERT_EQ(t.limits.size(), 3u);
  EXPECT_EQ(t.limits.at("max_arc_error_um").max, 3.5);
  EXPECT_FALSE(t.limits.at("max_arc_error_um").min.has_value());
  EXPECT_EQ(t.limits.at("mean_arc_radius_mm").min, 74.95);
  EXPECT_EQ(t.limits.at("mean_arc_radius_mm").max, 75.05);
  EXPECT_EQ(t.limits.at("max_runout_um").max, 10.0);
}

TEST(ParseTolerances, RefusesUnknownKeysBadNumbersAndInvertedRanges) {
  auto message = [](const std::string& text) {
    try {
      (void)ParseTolerances(text, "tol.json");
    } catch (const Error& error) {
      EXPECT_EQ(error.code(), ErrorCode::kBadInput);
      return std::string(error.what());
    }
    return std::string("no error");
  };
  EXPECT_THAT(message(R"({"max_runnout_um": 3})"),
              HasSubstr("'tol.json' key 'max_runnout_um' is not a headline quantity"));
  EXPECT_THAT(message(R"({"max_runout_um": "3"})"), HasSubstr("key 'max_runout_um' is neither a number"));
  EXPECT_THAT(message(R"({"max_runout_um": {"maximum": 3}})"), HasSubstr("key 'max_runout_um'.maximum"));
  EXPECT_THAT(message(R"({"mean_arc_radius_mm": {"min": 76, "max": 75}})"), HasSubstr("has min"));
  EXPECT_THAT(message(R"({"max_runout_um": {}})"), HasSubstr("has neither 'min' nor 'max'"));
  EXPECT_THAT(message("[1, 2]"), HasSubstr("'tol.json' is not a JSON object"));
  EXPECT_THAT(message("{"), HasSubstr("'tol.json' is not valid JSON"));
}

TEST(AddToleranceFlag, ParsesMaxAndMinMaxForms) {
  Tolerances t;
  AddToleranceFlag(t, "max_roundness_um=2.5");
  AddToleranceFlag(t, "mean_arc_radius_mm=74.9:75.1");
  AddToleranceFlag(t, "arc_radius_range_mm=:0.01");
  AddToleranceFlag(t, "center_axial_deviation_mm=0.001:");
  EXPECT_EQ(t.limits.at("max_roundness_um").max, 2.5);
  EXPECT_EQ(t.limits.at("mean_arc_radius_mm").min, 74.9);
  EXPECT_EQ(t.limits.at("mean_arc_radius_mm").max, 75.1);
  EXPECT_FALSE(t.limits.at("arc_radius_range_mm").min.has_value());
  EXPECT_EQ(t.limits.at("arc_radius_range_mm").max, 0.01);
  EXPECT_EQ(t.limits.at("center_axial_deviation_mm").min, 0.001);
  AddToleranceFlag(t, "max_roundness_um=4");
  EXPECT_EQ(t.limits.at("max_roundness_um").max, 4.0) << "a later flag replaces an earlier limit";
}

TEST(AddToleranceFlag, RefusesMalformedFlagsQuotingThem) {
  for (const char* flag : {"max_roundness_um", "roundness=3", "max_roundness_um=abc", "max_roundness_um=3um",
                           "max_roundness_um=:", "mean_arc_radius_mm=76:75"}) {
    Tolerances t;
    try {
      AddToleranceFlag(t, flag);
      ADD_FAILURE() << flag << " was accepted";
    } catch (const Error& error) {
      EXPECT_EQ(error.code(), ErrorCode::kInvalidOption);
      EXPECT_THAT(error.what(), HasSubstr(std::string("'") + flag + "'"));
    }
  }
}

TEST(ParseTolerances, ReadsTheOperatorAFormToleranceNames) {
  const Tolerances t =
      ParseTolerances(R"({"max_roundness_um": {"max": 2.0, "filter_upr": 150, "association": "least-squares"},
                                          "max_runout_um": {"max": 9, "filter": "none"},
                                          "max_arc_error_um": {"max": 3, "filter_cutoff_mm": 2.5}})",
                      "t.json");
  const NamedOperator& roundness = t.operators.at("max_roundness_um");
  EXPECT_EQ(roundness.filter_upr, 150.0);
  EXPECT_EQ(roundness.association, "least-squares");
  EXPECT_EQ(t.limits.at("max_roundness_um").max, 2.0);
  EXPECT_TRUE(t.operators.at("max_runout_um").no_filter);
  EXPECT_EQ(t.operators.at("max_arc_error_um").filter_cutoff_mm, 2.5);
  EXPECT_TRUE(ParseTolerances(R"({"max_roundness_um": 2})", "t.json").operators.empty());
}

TEST(ParseTolerances, RefusesAnOperatorArcwheelCannotEvaluateNamingTheKey) {
  const std::pair<const char*, const char*> cases[] = {
      {R"({"mean_arc_radius_mm": {"max": 55.5, "filter_upr": 50}})",
       "'t.json' key 'mean_arc_radius_mm'.filter_upr"},
      {R"({"max_runout_um": {"max": 9, "association": "minimum-zone"}})", "datum axis"},
      {R"({"max_arc_error_um": {"max": 3, "filter_upr": 50}})", "filter_cutoff_mm"},
      {R"({"max_roundness_um": {"max": 2, "filter_cutoff_mm": 0.8}})", "filter_upr"},
      {R"({"max_roundness_um": {"max": 2, "association": "chebyshev"}})", "minimum-zone"},
      {R"({"max_roundness_um": {"max": 2, "filter_upr": 0}})", "not above 0"},
      {R"({"max_roundness_um": {"max": 2, "filter": "none", "filter_upr": 50}})", "both"},
  };
  for (const auto& [text, expected] : cases) {
    try {
      (void)ParseTolerances(text, "t.json");
      ADD_FAILURE() << "accepted " << text;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kBadInput) << text;
      EXPECT_NE(std::string(e.what()).find(expected), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace arcwheel::reports
