#include "polishing/job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/testing/testing.h"
#include "polishing/removal_function.h"
#include "polishing/removal_target.h"
#include "polishing/robot_program.h"

namespace arcwheel::polishing {
namespace {

std::string ErrorOf(const std::string& text) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv") << text;
  try {
    (void)ReadErrorMapCsv(dir / "map.csv");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    return e.what();
  }
  return "accepted";
}

TEST(ReadErrorMapCsv, PlacesScatteredRowsOnTheirGridAndLeavesGapsWithoutData) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "map.csv")
      << "# comment\nx_mm,y_mm,error_um\n2.5,-1,0.25\n-2.5,-1,1\n0,1,nan\n2.5,1,-3\n";
  const ErrorMap map = ReadErrorMapCsv(dir / "map.csv");
  EXPECT_EQ(map.nx, 3);
  EXPECT_EQ(map.ny, 2);
  EXPECT_DOUBLE_EQ(map.x0_mm, -2.5);
  EXPECT_DOUBLE_EQ(map.dx_mm, 2.5);
  EXPECT_DOUBLE_EQ(map.dy_mm, 2.0);
  EXPECT_DOUBLE_EQ(map.At(0, 0), 1.0);
  EXPECT_TRUE(std::isnan(map.At(1, 0)));  // never given
  EXPECT_DOUBLE_EQ(map.At(2, 0), 0.25);
  EXPECT_TRUE(std::isnan(map.At(1, 1)));  // given as nan
  EXPECT_DOUBLE_EQ(map.At(2, 1), -3.0);
}

TEST(ReadErrorMapCsv, NamesTheFileAndLineOfMalformedInput) {
  EXPECT_NE(ErrorOf("x,y,z\n").find("map.csv' line 1: header 'x,y,z'"), std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0,abc\n").find("line 3: 'abc' is not a number"),
            std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0\n").find("line 3: has 2 values"), std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n2,0,2\n3,0,2\n3.4,0,3\n")
                .find("line 6: (3.4, 0) mm is not on the regular grid"),
            std::string::npos);
  EXPECT_NE(ErrorOf("x_mm,y_mm,error_um\n0,0,1\n1,0,2\n1,0,3\n").find("line 4: (1, 0) mm appears twice"),
            std::string::npos);
}

// A small valid job on a 5 x 5 mm map; `machine`, `removal_function` and `tool` replace its sections.
std::string JobText(const std::string& machine, const std::string& removal_function,
                    const std::string& tool) {
  return R"({"surface": {"vertex_radius_mm": 400},
  "aperture": {"diameter_mm": 4},
  "error_map": {"file": "map.csv"},
  "removal_function": )" +
         removal_function + R"(,
  "machine": )" +
         machine + R"(,
  "tool": )" +
         tool + "}";
}

std::string JobError(const std::string& text) {
  arcwheel::testing::TempDir dir;
  std::ofstream map(dir / "map.csv");
  map << "x_mm,y_mm,error_um\n";
  for (int j = -2; j <= 2; ++j) {
    for (int i = -2; i <= 2; ++i) map << i << "," << j << ",0.5\n";
  }
  map.close();
  std::ofstream(dir / "job.json") << text;
  try {
    (void)ReadPolishJob(dir / "job.json");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    return e.what();
  }
  return "accepted";
}

TEST(ReadPolishJob, ReportsEveryBadValueAtOnceEachWithItsValue) {
  const std::string good_machine = R"({"max_speed_mm_s": 100})";
  const std::string good_removal = R"({"peak_rate_um_per_s": 1, "fwhm_mm": 2})";
  ASSERT_EQ(JobError(JobText(good_machine, good_removal, "{}")), "accepted");

  const std::string message = JobError(JobText(
      R"({"max_speed_mm_s": -3})", R"({"peak_rate_um_per_s": 1, "fwhm_mm": -2})", R"({"mass_kg": 0})"));
  EXPECT_THAT(message, ::testing::HasSubstr("3 values are out of range:"));
  EXPECT_THAT(message, ::testing::HasSubstr("\n  machine.max_speed_mm_s = -3 violates > 0"));
  EXPECT_THAT(message, ::testing::HasSubstr("\n  removal_function.fwhm_mm = -2 violates > 0"));
  EXPECT_THAT(message, ::testing::HasSubstr("\n  tool.mass_kg = 0 violates > 0"));
}

TEST(PolishingOptions, DefaultsAreValidAndEachViolationNamesItsKeyAndValue) {
  EXPECT_TRUE(RemovalTargetOptions{}.Problems().empty());
  EXPECT_TRUE(GaussianRemovalFunction{}.Problems().empty());
  EXPECT_TRUE(ToolData{}.Problems().empty());
  EXPECT_TRUE((PathPrecession{.enabled = true}).Problems().empty());
  EXPECT_TRUE((PathPrecession{.enabled = false, .tilt_deg = 95.0}).Problems().empty());  // not used

  EXPECT_EQ(RemovalTargetOptions{.uniform_layer_um = -1.5}.Problems(),
            std::vector<std::string>{"removal_target.uniform_layer_um = -1.5 violates >= 0"});
  EXPECT_EQ((GaussianRemovalFunction{.peak_rate_um_per_s = 0.0, .fwhm_mm = -2.0}).Problems(),
            (std::vector<std::string>{"removal_function.peak_rate_um_per_s = 0 violates > 0",
                                      "removal_function.fwhm_mm = -2 violates > 0"}));
  EXPECT_EQ((PathPrecession{.enabled = true, .tilt_deg = 90.0, .bonnet_radius_mm = -1.0}).Problems(),
            (std::vector<std::string>{"precession.tilt_deg = 90 violates 0 <= tilt_deg < 90",
                                      "precession.bonnet_radius_mm = -1 violates >= 0"}));
  ToolData tool;
  tool.mass_kg = -5.0;
  EXPECT_EQ(tool.Problems(), std::vector<std::string>{"tool.mass_kg = -5 violates > 0"});
}

}  // namespace
}  // namespace arcwheel::polishing
