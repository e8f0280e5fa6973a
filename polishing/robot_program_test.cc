#include "polishing/robot_program.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/testing/testing.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using arcwheel::testing::ErrorOf;
using ::testing::HasSubstr;

using testing::ParseCsvRows;

struct Fixture {
  surfaces::EvenAsphere surface{{.vertex_radius_mm = 600.0, .conic = -1.0, .concave = false}};
  std::vector<Eigen::Vector2d> path = {{-30.0, 5.0}, {-10.0, 5.0}, {12.5, 5.0}, {40.0, 7.0}};
  DwellSolution dwell;
  Fixture() {
    dwell.dwell_s = {0.0, 0.25, 1.0 / 3.0, 0.5};
    dwell.speed_mm_s = {100.0, 80.0, 67.5, 55.036};
  }
};

TEST(PolishingPathCsv, HoldsTheSection7ColumnsAtFullPrecision) {
  const Fixture f;
  const auto points = BuildPolishingPath(f.surface, f.path, f.dwell, RobotSide::kPlusX);
  const std::vector<std::string> comments = {"surface: test"};
  std::string header;
  const auto rows = ParseCsvRows(PolishingPathCsv(points, comments), header);
  EXPECT_EQ(header, "x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s");
  ASSERT_EQ(rows.size(), f.path.size());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const auto& r = rows[k];
    ASSERT_EQ(r.size(), 9u);
    EXPECT_EQ(r[0], f.path[k].x());
    EXPECT_EQ(r[1], f.path[k].y());
    // Convex paraboloid z = -r^2 / (2 R), independent of the surface model.
    const double r2 = f.path[k].squaredNorm();
    EXPECT_NEAR(r[2], -r2 / 1200.0, 1e-12);
    const AbbQuaternion q{r[3], r[4], r[5], r[6]};
    const Eigen::Matrix3d frame = RotationFromAbbQuaternion(q);
    const Eigen::Vector3d inward =
        Eigen::Vector3d(-f.path[k].x() / 600.0, -f.path[k].y() / 600.0, -1.0).normalized();
    EXPECT_LT((frame.col(2) - inward).norm(), 1e-12);
    EXPECT_EQ(r[7], f.dwell.speed_mm_s[k]);
    EXPECT_EQ(r[8], f.dwell.dwell_s[k]);  // 1/3 reads back exactly: shortest round-trip digits
  }
}

TEST(RapidModule, DeclaresTargetsSpeedsToolAndWorkObjectAndMovesThroughEveryPoint) {
  const Fixture f;
  const auto points = BuildPolishingPath(f.surface, f.path, f.dwell, RobotSide::kPlusX);
  ToolData tool;
  tool.tcp_mm = {0.0, 0.0, 200.0};
  tool.orientation = {0.0, 1.0, 0.0, 0.0};  // half turn about x: tool y = -flange y
  tool.removal_centre_offset_mm = {1.5, -2.0};
  const WorkObject wobj{.origin_mm = {1000.0, -250.0, 400.0}, .orientation = {1.0, 0.0, 0.0, 0.0}};
  const std::vector<std::string> comments;
  const std::string text = RapidModule(points, tool, wobj, "Polish", comments);
  EXPECT_EQ(text.rfind("MODULE Polish\n", 0), 0u);
  EXPECT_NE(text.find("ENDMODULE"), std::string::npos);
  // Offset (1.5, -2) in the tool frame is (1.5, +2, 0) in the flange frame after the half turn.
  EXPECT_NE(text.find("PERS tooldata tPolish := [TRUE,[[1.5000,2.0000,200.0000],[0.000000000,1.000000000,"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("[[1000.0000,-250.0000,400.0000],[1.000000000,0.000000000,0.000000000,0.000000000]]"),
            std::string::npos);
  const std::regex target(
      R"(\[\[(-?[0-9.]+),(-?[0-9.]+),(-?[0-9.]+)\],\[(-?[0-9.]+),(-?[0-9.]+),(-?[0-9.]+),(-?[0-9.]+)\],\[0,0,0,0\])");
  std::size_t k = 0;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), target); it != std::sregex_iterator();
       ++it, ++k) {
    ASSERT_LT(k, points.size());
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(std::stod((*it)[c + 1]), points[k].position_mm[c], 0.5e-4);
    EXPECT_NEAR(std::stod((*it)[4]), points[k].orientation.q1, 0.5e-9);
    EXPECT_NEAR(std::stod((*it)[7]), points[k].orientation.q4, 0.5e-9);
  }
  EXPECT_EQ(k, points.size());
  EXPECT_NE(text.find("    [67.5000,500,5000,1000],"), std::string::npos);
  // The targets in the order main() moves to them: fly-by through 1 .. N-1, a stop point on N, and
  // no target twice (a repeat of the last would be a zero-length move).
  const std::size_t main_at = text.find("  PROC main()");
  ASSERT_NE(main_at, std::string::npos);
  EXPECT_EQ(text.substr(main_at),
            "  PROC main()\n"
            "    ConfL \\Off;\n"
            "    FOR i FROM 1 TO nPoints - 1 DO\n"
            "      MoveL pPath{i}, vPath{i}, z1, tPolish \\WObj:=wPart;\n"
            "    ENDFOR\n"
            "    MoveL pPath{nPoints}, vPath{nPoints}, fine, tPolish \\WObj:=wPart;\n"
            "  ENDPROC\n"
            "ENDMODULE\n");
}

TEST(BuildPolishingPath, PrecessesTheBonnetAxisAboutTheNormalAtTheTiltAndRateInStepsOfAtMostOneDegree) {
  const Fixture f;
  const PathPrecession precession{
      .enabled = true, .tilt_deg = 20.0, .precession_rate_rpm = 5.0, .bonnet_radius_mm = 40.0};
  const auto points = BuildPolishingPath(f.surface, f.path, f.dwell, RobotSide::kPlusX, precession);
  // 30 deg/s over dwells of up to 0.5 s turns the axis 15 deg on its 20 deg cone: cut into steps.
  ASSERT_GT(points.size(), 3 * f.path.size());
  const double w2 = 5.0 * 2.0 * std::numbers::pi / 60.0;
  double elapsed = 0.0;
  std::size_t path_point = 0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    elapsed += points[k].dwell_s;
    // Independent outward normal of the convex paraboloid z = -r^2 / 1200, and its tool x axis
    // (1, 0, f_x) towards +x.
    const Eigen::Vector2d p = points[k].contact_xy_mm;
    const Eigen::Vector3d up = Eigen::Vector3d(p.x() / 600.0, p.y() / 600.0, 1.0).normalized();
    const Eigen::Vector3d a = Eigen::Vector3d(1.0, 0.0, -p.x() / 600.0).normalized();
    const Eigen::Vector3d contact(p.x(), p.y(), -p.squaredNorm() / 1200.0);
    EXPECT_LT((points[k].position_mm - (contact + 40.0 * up)).norm(), 1e-12);
    const Eigen::Matrix3d frame = RotationFromAbbQuaternion(points[k].orientation);
    const Eigen::Vector3d axis = -frame.col(2);
    EXPECT_NEAR(std::acos(axis.dot(up)), 20.0 * std::numbers::pi / 180.0, 1e-9);
    // The precession angle measured from tool x on the tangent plane, whatever the feed does.
    const Eigen::Vector3d tangential = axis - axis.dot(up) * up;
    const double alpha = std::atan2(tangential.dot(up.cross(a)), tangential.dot(a));
    EXPECT_NEAR(std::remainder(alpha - w2 * elapsed, 2.0 * std::numbers::pi), 0.0, 1e-9) << k;
    EXPECT_LT((frame.transpose() * frame - Eigen::Matrix3d::Identity()).norm(), 1e-12);
    if (k > 0) {
      const Eigen::Matrix3d before = RotationFromAbbQuaternion(points[k - 1].orientation);
      EXPECT_LE(Eigen::AngleAxisd(before.transpose() * frame).angle(), std::numbers::pi / 180.0) << k;
      // Each step lies on its segment, and the segment's last step on the path point.
      EXPECT_TRUE(points[k].dwell_point == path_point || points[k].dwell_point == path_point + 1) << k;
      path_point = points[k].dwell_point;
      EXPECT_NEAR(points[k].dwell_s * points[k].speed_mm_s,
                  (points[k].position_mm - points[k - 1].position_mm).norm(), 1e-12);
    }
  }
  EXPECT_EQ(path_point, f.path.size() - 1);
  EXPECT_EQ(points.back().contact_xy_mm, f.path.back());
  // Each segment keeps its time: its steps' speed is their path's length over it.
  EXPECT_NEAR(elapsed, f.dwell.dwell_s[1] + f.dwell.dwell_s[2] + f.dwell.dwell_s[3], 1e-12);
  EXPECT_THROW((void)BuildPolishingPath(f.surface, f.path, f.dwell, RobotSide::kPlusX,
                                        {.enabled = true, .tilt_deg = 95.0}),
               Error);
}

TEST(TcpChordsMm, AreTheBonnetCentreStepsWithPrecessionAndTheContactStepsWithout) {
  const Fixture f;
  const PathPrecession precession{.enabled = true, .bonnet_radius_mm = 40.0};
  const std::vector<double> plain = TcpChordsMm(TcpPositionsMm(f.surface, f.path));
  const std::vector<double> precessed = TcpChordsMm(TcpPositionsMm(f.surface, f.path, precession));
  ASSERT_EQ(plain.size(), f.path.size());
  ASSERT_EQ(precessed.size(), f.path.size());
  EXPECT_EQ(plain[0], 0.0);
  EXPECT_EQ(precessed[0], 0.0);
  // Independent: the convex paraboloid z = -r^2 / 1200 and its outward normal.
  auto contact = [](const Eigen::Vector2d& p) -> Eigen::Vector3d {
    return Eigen::Vector3d(p.x(), p.y(), -p.squaredNorm() / 1200.0);
  };
  auto centre = [&](const Eigen::Vector2d& p) -> Eigen::Vector3d {
    return contact(p) + 40.0 * Eigen::Vector3d(p.x() / 600.0, p.y() / 600.0, 1.0).normalized();
  };
  for (std::size_t k = 1; k < f.path.size(); ++k) {
    EXPECT_NEAR(plain[k], (contact(f.path[k]) - contact(f.path[k - 1])).norm(), 1e-12);
    EXPECT_NEAR(precessed[k], (centre(f.path[k]) - centre(f.path[k - 1])).norm(), 1e-12);
    EXPECT_GT(precessed[k], plain[k]);  // the centres ride 40 mm further out on a convex part
  }
}

TEST(BuildPolishingPath, RefusesADwellSolvedOnOtherChordsThanTheRobotRuns) {
  Fixture f;
  f.dwell.chord_mm = TcpChordsMm(TcpPositionsMm(f.surface, f.path));
  EXPECT_NO_THROW((void)BuildPolishingPath(f.surface, f.path, f.dwell, RobotSide::kPlusX));
  // The same dwell on the bonnet centres' longer chords would not take the times it predicts.
  EXPECT_THROW((void)BuildPolishingPath(f.surface, f.path, f.dwell, RobotSide::kPlusX,
                                        {.enabled = true, .bonnet_radius_mm = 40.0}),
               Error);
}

TEST(BuildPolishingPath, RefusesAPointOffTheSurface) {
  Fixture f;
  const surfaces::EvenAsphere small({.vertex_radius_mm = 35.0});
  EXPECT_THAT(ErrorOf([&] { (void)BuildPolishingPath(small, f.path, f.dwell, RobotSide::kPlusX); }).what(),
              HasSubstr("path point 3 (40, 7) mm is off the surface"));
}

}  // namespace
}  // namespace arcwheel::polishing
