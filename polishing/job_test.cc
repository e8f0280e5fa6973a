#include "polishing/job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <string>

#include "core/error.h"
#include "core/testing/testing.h"
#include "polishing/dwell.h"
#include "polishing/removal_function.h"
#include "polishing/removal_target.h"
#include "polishing/robot_program.h"

namespace arcwheel::polishing {
namespace {

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
  return arcwheel::testing::ErrorMessageOf([&dir] { (void)ReadPolishJob(dir / "job.json"); });
}

TEST(ReadPolishJob, ReportsEveryBadValueAtOnceEachWithItsValue) {
  const std::string good_machine = R"({"max_speed_mm_s": 100})";
  const std::string good_removal = R"({"peak_rate_um_per_s": 1, "fwhm_mm": 2})";
  ASSERT_EQ(JobError(JobText(good_machine, good_removal, "{}")), "accepted");

  const std::string message = JobError(JobText(
      R"({"max_speed_mm_s": -3})", R"({"peak_rate_um_per_s": 1, "fwhm_mm": -2})", R"({"mass_kg": 0})"));
  // In the order read: the removal function's while its section is read, then the options'.
  EXPECT_THAT(message, ::testing::HasSubstr(
                           "job.json': removal_function.fwhm_mm = -2 violates > 0; "
                           "machine.max_speed_mm_s = -3 violates > 0; tool.mass_kg = 0 violates > 0"));
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

// The size check counts the points before the path is made: the count must match the paths
// RasterPath and SpiralPath then make (a circle's raster: at most 4/pi times too many).
TEST(PathPointCount, MatchesThePathsMadeOrBoundsACirclesRaster) {
  const surfaces::Aperture disc{.shape = surfaces::Aperture::Shape::kCircle, .diameter_mm = 61.3};
  const surfaces::Aperture plate{.width_x_mm = 47.0, .width_y_mm = 22.5};
  for (const RasterOptions& o :
       {RasterOptions{.line_spacing_mm = 2.0, .point_spacing_mm = 2.0, .extension_mm = 6.0},
        RasterOptions{.line_spacing_mm = 0.7, .point_spacing_mm = 0.3, .extension_mm = 1.1},
        RasterOptions{.line_spacing_mm = 5.0, .point_spacing_mm = 9.0, .extension_mm = 0.0}}) {
    SCOPED_TRACE(o.line_spacing_mm);
    for (const surfaces::Aperture& a : {disc, plate}) {
      EXPECT_EQ(PathPointCount(a, o, PathPattern::kSpiral), static_cast<double>(SpiralPath(a, o).size()));
    }
    EXPECT_EQ(PathPointCount(plate, o, PathPattern::kRaster),
              static_cast<double>(RasterPath(plate, o).size()));
    const double made = static_cast<double>(RasterPath(disc, o).size());
    EXPECT_GE(PathPointCount(disc, o, PathPattern::kRaster), made);
    EXPECT_LE(PathPointCount(disc, o, PathPattern::kRaster), 1.5 * made + 10.0);
  }
  // Far too fine: a huge count, not an overflow.
  const RasterOptions tiny{.line_spacing_mm = 1e-300, .point_spacing_mm = 1e-300};
  EXPECT_FALSE(PathPointCount(disc, tiny, PathPattern::kRaster) < 1e300);
  EXPECT_FALSE(PathPointCount(disc, tiny, PathPattern::kSpiral) < 1e300);
}

}  // namespace
}  // namespace arcwheel::polishing
