#include "frames/program_transform.h"

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::frames {
namespace {

using arcwheel::testing::ErrorMessageOf;
using ::testing::HasSubstr;

Transform QuarterTurnAndShift() {
  Transform t;
  t.linear << 0, -1, 0, 1, 0, 0, 0, 0, 1;  // 90 deg about z: (x, y) -> (-y, x)
  t.translation_mm = {100.0, 200.0, -10.0};
  return t;
}

// The message with which TransformProgram refuses `text` as bad input, moved by
// QuarterTurnAndShift(); "accepted" if it does not refuse it.
std::string RefusalOf(const std::string& text, ProgramKind kind, const std::string& file_name) {
  return ErrorMessageOf([&] { (void)TransformProgram(text, kind, QuarterTurnAndShift(), file_name); });
}

std::vector<std::string> Cells(const std::string& line) {
  std::vector<std::string> cells;
  std::stringstream stream(line);
  std::string cell;
  while (std::getline(stream, cell, ',')) cells.push_back(cell);
  return cells;
}

TEST(TransformProgram, RewritesToolpathCsvPointsAndNormalsAndKeepsEverythingElse) {
  std::mt19937 rng(9001);
  std::uniform_real_distribution<double> coordinate(-300.0, 300.0);
  Transform t;
  t.linear = Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  t.translation_mm = {12.5, -3.25, 7.0};
  std::string text =
      "# surface: test asphere\r\n# arcwheel "
      "0.1.0\r\nrow,pass,xw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min\r\n";
  std::vector<Eigen::Vector3d> points, normals;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector3d p(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d n = Eigen::Vector3d(coordinate(rng), coordinate(rng), 400.0).normalized();
    points.push_back(p);
    normals.push_back(n);
    text += fmt::format("{},{},{},{},{},{},{},{},{},{},{},1500.0\r\n", i, i % 3, p.x(), p.y(), p.z() + 50.0,
                        p.x(), p.y(), p.z(), n.x(), n.y(), n.z());
  }
  const ProgramTransformResult out = TransformProgram(text, ProgramKind::kToolpathCsv, t, "path.csv");
  EXPECT_EQ(out.points_transformed, 60);
  std::stringstream lines(out.text);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "# surface: test asphere\r");
  std::getline(lines, line);
  std::getline(lines, line);
  EXPECT_EQ(line, "row,pass,xw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min\r");
  for (int i = 0; i < 20; ++i) {
    std::getline(lines, line);
    ASSERT_EQ(line.back(), '\r');
    const auto cells = Cells(line.substr(0, line.size() - 1));
    ASSERT_EQ(cells.size(), 12u);
    EXPECT_EQ(cells[0], std::to_string(i));
    EXPECT_EQ(cells[11], "1500.0");
    const Eigen::Vector3d wheel = t.linear * (points[i] + Eigen::Vector3d(0, 0, 50)) + t.translation_mm;
    const Eigen::Vector3d contact = t.linear * points[i] + t.translation_mm;
    const Eigen::Vector3d normal = t.linear * normals[i];
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(std::stod(cells[2 + k]), wheel(k), 1e-12 * 400);
      EXPECT_NEAR(std::stod(cells[5 + k]), contact(k), 1e-12 * 400);
      EXPECT_NEAR(std::stod(cells[8 + k]), normal(k), 1e-14);
    }
  }
  // The inverse gives the original numbers back.
  const ProgramTransformResult back =
      TransformProgram(out.text, ProgramKind::kToolpathCsv, t.Inverse(), "out.csv");
  std::stringstream original(text), restored(back.text);
  std::string a, b;
  while (std::getline(original, a) && std::getline(restored, b)) {
    const auto ca = Cells(a), cb = Cells(b);
    ASSERT_EQ(ca.size(), cb.size());
    for (size_t c = 0; c < ca.size(); ++c) {
      if (ca[c] == cb[c]) continue;
      EXPECT_NEAR(std::stod(ca[c]), std::stod(cb[c]), 1e-11) << a;
    }
  }
}

TEST(TransformProgram, RefusesToolpathCsvItCannotReadNamingTheLine) {
  const auto refusal = [](const std::string& text) {
    return RefusalOf(text, ProgramKind::kToolpathCsv, "p.csv");
  };
  EXPECT_THAT(refusal("x_mm,y_mm,feed\n1,2,3\n"), HasSubstr("line 1: the header has only part of x_mm"));
  EXPECT_THAT(refusal("x_mm,y_mm,z_mm\n1,2,3\n1,2\n"), HasSubstr("line 3: 2 cells"));
  EXPECT_THAT(refusal("x_mm,y_mm,z_mm\n1,2,3\n1,nan,3\n"), HasSubstr("line 3: column 'y_mm'"));
  EXPECT_THAT(refusal("a,b\n1,2\n"), HasSubstr("no point columns"));
}

TEST(TransformProgram, RewritesGcodeMovesAndKeepsCommentsAndOtherWords) {
  const std::string program =
      "%\n"
      "O1000 (PART FRAME, X Y Z IN MM)\n"
      "G21 G90 G17\n"
      "G0 X0 Y0 Z50 (rapid to start)\n"
      "N20 G1 X10.5 Y-3 Z2 F500\n"
      "X20 ; modal move along X\n"
      "G1 Z1.5\n"
      "G1X1Y1Z1\n"
      "M30\n"
      "%\n";
  const ProgramTransformResult out =
      TransformProgram(program, ProgramKind::kGcode, QuarterTurnAndShift(), "p.nc");
  // (x, y, z) -> (100 - y, 200 + x, z - 10).
  EXPECT_EQ(out.text,
            "%\n"
            "O1000 (PART FRAME, X Y Z IN MM)\n"
            "G21 G90 G17\n"
            "G0 X100.0 Y200.0 Z40.0 (rapid to start)\n"
            "N20 G1 X103.0 Y210.5 Z-8.0 F500\n"
            "X103.0 Y220.0 ; modal move along X\n"
            "G1 Z-8.5\n"
            "G1X99.0Y201.0Z-9.0\n"
            "M30\n"
            "%\n");
  EXPECT_EQ(out.points_transformed, 5);
}

TEST(TransformProgram, RefusesGcodeItCannotTransformNamingTheLine) {
  const auto refusal = [](const std::string& text) { return RefusalOf(text, ProgramKind::kGcode, "p.nc"); };
  EXPECT_THAT(refusal("G90\nG0 X0 Y0 Z0\nG91\nG1 X1\n"), HasSubstr("'p.nc' line 3: G91"));
  EXPECT_THAT(refusal("G0 X0 Y0 Z0\nG2 X1 Y1 I1 J0\n"), HasSubstr("line 2: G2"));
  EXPECT_THAT(refusal("G0 X0 Y0 Z0\nG1 X1 A30\n"), HasSubstr("line 2: rotary axis word A"));
  EXPECT_THAT(refusal("G1 X10\n"), HasSubstr("line 1: the new X needs a source position"));
  EXPECT_THAT(refusal("X10 Y10 Z10\n"), HasSubstr("line 1: X/Y/Z words before any G0/G1"));
  EXPECT_THAT(refusal("G0 X0 Y0 Z0\nG1 X#100\n"), HasSubstr("line 2: X is not followed by a literal number"));
}

TEST(TransformProgram, KeepsTheProgramsResolutionUnlessToldOtherwise) {
  Transform shift;
  shift.translation_mm = {0.5, 0.0, -0.00004};
  const std::string program = "G90\nG1 X1.250 Y-2.5000 Z0.0000\n";
  EXPECT_EQ(TransformProgram(program, ProgramKind::kGcode, shift, "p.nc").text,
            "G90\nG1 X1.7500 Y-2.5000 Z0.0000\n");
  EXPECT_EQ(TransformProgram(program, ProgramKind::kGcode, shift, "p.nc", {.decimals = 6}).text,
            "G90\nG1 X1.750000 Y-2.500000 Z-0.000040\n");
  EXPECT_THROW((void)TransformProgram(program, ProgramKind::kGcode, shift, "p.nc", {.decimals = 0}), Error);
}

TEST(TransformProgram, RewritesOnlyTheMotionProgramOfAPmacFile) {
  Transform shift;
  shift.translation_mm = {1.0, 2.0, 3.0};
  const std::string program =
      "&1\n"
      "#1->10000X\n"
      "OPEN PROG 10 CLEAR\n"
      "LINEAR ABS\n"
      "TM100\n"
      "X10 Y20 Z5 ; start\n"
      "X15\n"
      "DWELL 100\n"
      "CLOSE\n"
      "X99\n";
  const ProgramTransformResult out = TransformProgram(program, ProgramKind::kPmac, shift, "p.pmc");
  EXPECT_EQ(out.text,
            "&1\n"
            "#1->10000X\n"
            "OPEN PROG 10 CLEAR\n"
            "LINEAR ABS\n"
            "TM100\n"
            "X11.0000 Y22.0000 Z8.0000 ; start\n"
            "X16.0000\n"
            "DWELL 100\n"
            "CLOSE\n"
            "X99\n");
  EXPECT_THROW((void)TransformProgram("OPEN PROG 1\nINC\nX1\nCLOSE\n", ProgramKind::kPmac, shift, "p.pmc"),
               Error);
  EXPECT_THROW(
      (void)TransformProgram("OPEN PROG 1\nCIRCLE1\nX1 Y1 I1\nCLOSE\n", ProgramKind::kPmac, shift, "p.pmc"),
      Error);
  EXPECT_THROW((void)TransformProgram("OPEN PROG 1\nX(P1)\nCLOSE\n", ProgramKind::kPmac, shift, "p.pmc"),
               Error);
}

TEST(TransformProgram, GcodeRoundTripThroughTheInverseRestoresTheProgram) {
  Transform t;
  t.linear = Eigen::AngleAxisd(0.3, Eigen::Vector3d(0.2, 0.1, 1).normalized()).toRotationMatrix();
  t.translation_mm = {500.0, -250.0, 30.0};
  const std::string program = "G90\nG0 X1.25 Y2.5 Z3.0\nG1 X4.0 Y5.0 Z6.0 F100\nG1 X7.0 Y8.0 Z9.0\n";
  const auto there = TransformProgram(program, ProgramKind::kGcode, t, "p.nc", {.decimals = 9});
  const auto back = TransformProgram(there.text, ProgramKind::kGcode, t.Inverse(), "q.nc", {.decimals = 2});
  EXPECT_EQ(back.text, "G90\nG0 X1.25 Y2.50 Z3.00\nG1 X4.00 Y5.00 Z6.00 F100\nG1 X7.00 Y8.00 Z9.00\n");
}

}  // namespace
}  // namespace arcwheel::frames
