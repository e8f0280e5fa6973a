// The grinding options report every violation at once, each named by its key in the toolpath job
// (docs/grinding.md) and with the value given. The expected texts are spelled out here.

#include <gtest/gtest.h>

#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "grinding/job.h"
#include "grinding/prediction.h"
#include "grinding/toolpath.h"
#include "grinding/wheel.h"
#include "surfaces/surface.h"

namespace arcwheel::grinding {
namespace {

using Problems = std::vector<std::string>;

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();

// The message of the Error that `run` throws with `code`; fails the test if there is none.
template <class Run>
std::string ErrorMessage(ErrorCode code, Run run) {
  try {
    run();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    return e.what();
  }
  ADD_FAILURE() << "accepted";
  return "";
}

const surfaces::EvenAsphere& Sphere() {
  static const surfaces::EvenAsphere sphere({.vertex_radius_mm = 800.0});
  return sphere;
}
const surfaces::Aperture kSquare{.width_x_mm = 20.0, .width_y_mm = 20.0};
const Wheel kWheel{.arc_radius_mm = 50.0, .base_radius_mm = 150.0, .half_width_mm = 10.0};

TEST(GrindingOptions, DefaultsHaveNoProblems) {
  EXPECT_EQ(ToolpathOptions{}.Problems(), Problems{});
  EXPECT_EQ(PredictionOptions{}.Problems(), Problems{});
  EXPECT_EQ(MachineOptions{}.Problems(), Problems{});
  EXPECT_EQ(kWheel.Problems(), Problems{});
}

TEST(ToolpathOptions, ReportsEveryViolationWithItsValueNamedByTheJobKey) {
  const ToolpathOptions bad{.step_over_mm = 0.0,
                            .point_spacing_mm = -0.5,
                            .chordal_tolerance_um = -1.0,
                            .feed_mm_per_min = -100.0,
                            .depth_per_pass_um = -2.0,
                            .passes = 0,
                            .lead_in_mm = -3.0,
                            .lead_out_mm = -4.0,
                            .gouge_check_spacing_mm = 0.0,
                            .gouge_samples = 2,
                            .gouge_tolerance_mm = -0.002,
                            .threads = -1};
  EXPECT_EQ(
      bad.Problems(),
      (Problems{"path.step_over_mm = 0 violates > 0", "path.point_spacing_mm = -0.5 violates > 0",
                "path.chordal_tolerance_um = -1 violates >= 0", "path.feed_mm_per_min = -100 violates > 0",
                "path.depth_per_pass_um = -2 violates >= 0", "path.passes = 0 violates >= 1",
                "path.lead_in_mm = -3 violates >= 0", "path.lead_out_mm = -4 violates >= 0",
                "gouge_check.spacing_mm = 0 violates > 0", "gouge_check.samples = 2 violates >= 3",
                "gouge_check.tolerance_um = -2 violates >= 0", "machine.threads = -1 violates >= 0"}));
}

TEST(PredictionOptions, ReportsEveryViolationWithItsValueNamedByTheJobKey) {
  const PredictionOptions bad{.arc_radius_error_mm = kNan,
                              .runout_phase_deg = {0.0, 90.0, 400.0},
                              .runout_radial_um = {1.0, 2.0},
                              .spindle_rpm = 0.0,
                              .feed_mm_per_min = 0.0,
                              .nodes_x = 1,
                              .nodes_y = 5,
                              .threads = -2};
  EXPECT_EQ(
      bad.Problems(),
      (Problems{"prediction.arc_radius_error_mm = nan violates finite",
                "prediction runout sizes phase_deg = 3, radial_um = 2 violates equal",
                "prediction runout phase_deg[2] = 400 violates ascending within [0, 360)",
                "prediction.spindle_rpm = 0 violates > 0 (needed for runout)",
                "path.feed_mm_per_min = 0 violates > 0", "prediction.map_nodes = [1, 5] violates >= 2 each",
                "machine.threads = -2 violates >= 0"}));
}

TEST(MachineOptions, ReportsEveryViolationWithItsValueNamedByTheJobKey) {
  const MachineOptions bad{.pmac_program = 0, .decimals = 10, .retract_mm = -5.0};
  EXPECT_EQ(bad.Problems(),
            (Problems{"machine.pmac_program = 0 violates >= 1", "machine.decimals = 10 violates 1 .. 9",
                      "machine.retract_mm = -5 violates >= 0"}));
}

TEST(Wheel, ReportsEveryViolationWithItsValueNamedByTheJobKey) {
  // Total radius 40 mm below an arc radius of 50 mm; width 120 mm beyond the arc's 100 mm.
  const Wheel bad{.arc_radius_mm = 50.0, .base_radius_mm = -10.0, .half_width_mm = 60.0};
  EXPECT_EQ(bad.Problems(),
            (Problems{"wheel.total_radius_mm = 40 violates >= wheel.arc_radius_mm = 50",
                      "wheel.width_mm = 120 violates 0 < width_mm <= 2 * wheel.arc_radius_mm = 100"}));
  Wheel profile = kWheel;
  profile.profile_u_mm = {-5.0, 0.0, 0.0};
  profile.profile_error_um = {0.1, 0.2};
  EXPECT_EQ(
      profile.Problems(),
      (Problems{"wheel profile sizes u_mm = 3, error_um = 2 violates equal, and 0 or >= 2",
                "wheel profile node 2: u_mm = 0, error_um = 0 violates finite, u_mm strictly increasing"}));
  profile.profile_error_um = {0.1, kNan, 0.3};
  profile.profile_u_mm = {-5.0, 0.0, 5.0};
  EXPECT_EQ(
      profile.Problems(),
      (Problems{"wheel profile node 1: u_mm = 0, error_um = nan violates finite, u_mm strictly increasing"}));
}

TEST(GenerateToolpath, RefusesTwoBadOptionsInOneErrorNamingBothWithTheirValues) {
  const RowSink ignore{.prepare = {}, .consume = [](ToolpathRow&) {}};
  EXPECT_EQ(ErrorMessage(ErrorCode::kInvalidOption,
                         [&] {
                           (void)GenerateToolpath(Sphere(), kSquare, kWheel,
                                                  {.step_over_mm = -1.0, .passes = 0}, ignore);
                         }),
            "grinding.toolpath: path.step_over_mm = -1 violates > 0; path.passes = 0 violates >= 1");
}

TEST(GenerateToolpath, RefusesABadWheelAsBadInputNamingEveryProblem) {
  const RowSink ignore{.prepare = {}, .consume = [](ToolpathRow&) {}};
  const Wheel bad{.arc_radius_mm = 50.0, .base_radius_mm = -10.0, .half_width_mm = 0.0};
  EXPECT_EQ(
      ErrorMessage(ErrorCode::kBadInput, [&] { (void)GenerateToolpath(Sphere(), kSquare, bad, {}, ignore); }),
      "grinding.toolpath: wheel.total_radius_mm = 40 violates >= wheel.arc_radius_mm = 50; "
      "wheel.width_mm = 0 violates 0 < width_mm <= 2 * wheel.arc_radius_mm = 100");
}

TEST(PredictFormError, RefusesTwoBadOptionsInOneErrorNamingBothWithTheirValues) {
  EXPECT_EQ(ErrorMessage(ErrorCode::kInvalidOption,
                         [&] {
                           (void)PredictFormError(Sphere(), kSquare, kWheel,
                                                  {.arc_radius_error_mm = kNan, .nodes_x = 0});
                         }),
            "grinding.prediction: prediction.arc_radius_error_mm = nan violates finite; "
            "prediction.map_nodes = [0, 201] violates >= 2 each");
}

}  // namespace
}  // namespace arcwheel::grinding
