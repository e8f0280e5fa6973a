#include "grinding/wheel.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <string>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::grinding {
namespace {

using arcwheel::testing::TempDir;
using ::testing::HasSubstr;

// A minimal summary.json as `arcwheel process` writes it; `version` is the schema_version line,
// empty for a file written before versions were recorded.
std::filesystem::path WriteSummary(const TempDir& dir, const std::string& version) {
  const std::filesystem::path path = dir / "summary.json";
  std::ofstream(path)
      << "{" << version
      << R"("mean_arc_radius_mm": 55.0, "mean_arc_radius_sigma_mm": 0.002, "max_runout_um": 1.5,
                            "scan": {"wheel_id": "W3", "wheel_diameter_mm": 150.0}})";
  return path;
}

TEST(ReadWheelSummary, ReadsAFileWrittenBeforeSchemaVersions) {
  TempDir dir;
  const WheelSummary s = ReadWheelSummary(WriteSummary(dir, ""));
  EXPECT_EQ(s.mean_arc_radius_mm, 55.0);
  EXPECT_EQ(s.wheel_diameter_mm, 150.0);
  EXPECT_EQ(s.wheel_id, "W3");
}

TEST(ReadWheelSummary, ReadsEveryMinorVersionOfMajor1) {
  TempDir dir;
  for (const std::string version : {"1.0", "1.5"}) {
    EXPECT_EQ(
        ReadWheelSummary(WriteSummary(dir, R"("schema_version": ")" + version + R"(", )")).max_runout_um, 1.5)
        << version;
  }
}

TEST(ReadWheelSummary, RefusesANewerMajorVersionNamingTheFileAndBothVersions) {
  TempDir dir;
  const std::filesystem::path path = WriteSummary(dir, R"("schema_version": "2.0", )");
  try {
    (void)ReadWheelSummary(path);
    FAIL() << "a 2.0 summary was read";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kBadInput);
    EXPECT_THAT(error.what(), HasSubstr("grinding.wheel"));
    EXPECT_THAT(error.what(), HasSubstr("'" + path.string() + "' key 'schema_version' = '2.0'"));
    EXPECT_THAT(error.what(), HasSubstr("reads schema version 1.x only"));
  }
}

TEST(ReadWheelSummary, RefusesASchemaVersionThatIsNotText) {
  TempDir dir;
  try {
    (void)ReadWheelSummary(WriteSummary(dir, R"("schema_version": 1.0, )"));
    FAIL() << "a numeric schema_version was read";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kBadInput);
    EXPECT_THAT(error.what(), HasSubstr("key 'schema_version' must be a string"));
  }
}

}  // namespace
}  // namespace arcwheel::grinding
