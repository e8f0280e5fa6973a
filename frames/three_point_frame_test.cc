#include "frames/three_point_frame.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "core/error.h"

namespace arcwheel::frames {
namespace {

TEST(ThreePointFrame, RecoversAKnownRotatedAndShiftedFrame) {
  // A workpiece frame with known axes: rotate the machine axes by 30 deg about (1, 2, 3).
  const Eigen::Matrix3d axes =
      Eigen::AngleAxisd(0.5236, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Vector3d origin(250.0, -120.0, 33.0);
  const Eigen::Vector3d p2 = origin + 180.0 * axes.col(0);
  const Eigen::Vector3d p3 = origin + 40.0 * axes.col(0) + 95.0 * axes.col(1);
  const WorkpieceFrame frame = ThreePointFrame(origin, p2, p3);
  EXPECT_TRUE(frame.axes.isApprox(axes, 1e-12));
  EXPECT_TRUE(frame.origin_mm.isApprox(origin, 1e-15));
  // The method.md formulas: P' = P1 + [i j k] P and P = [i j k]^T (P' - P1).
  const Eigen::Vector3d p_in_workpiece(12.0, -7.0, 3.5);
  const Eigen::Vector3d p_in_machine = origin + axes * p_in_workpiece;
  EXPECT_TRUE(frame.MachineFromWorkpiece().ApplyToPoint(p_in_workpiece).isApprox(p_in_machine, 1e-13));
  EXPECT_TRUE(frame.WorkpieceFromMachine().ApplyToPoint(p_in_machine).isApprox(p_in_workpiece, 1e-11));
  // P3 lies in the workpiece XY plane with positive y.
  const Eigen::Vector3d p3_in_workpiece = frame.WorkpieceFromMachine().ApplyToPoint(p3);
  EXPECT_NEAR(p3_in_workpiece.z(), 0.0, 1e-11);
  EXPECT_GT(p3_in_workpiece.y(), 0.0);
}

TEST(ThreePointFrame, RefusesCoincidentAndCollinearPoints) {
  const Eigen::Vector3d p1(0, 0, 0), p2(100, 0, 0);
  EXPECT_THROW((void)ThreePointFrame(p1, p1 + Eigen::Vector3d(1e-4, 0, 0), Eigen::Vector3d(0, 50, 0)), Error);
  EXPECT_THROW((void)ThreePointFrame(p1, p2, p1), Error);
  EXPECT_THROW((void)ThreePointFrame(p1, p2, Eigen::Vector3d(300, 0.01, 0)), Error);   // 0.002 deg
  EXPECT_THROW((void)ThreePointFrame(p1, p2, Eigen::Vector3d(-300, 0.01, 0)), Error);  // on the -X side
  try {
    (void)ThreePointFrame(p1, p2, Eigen::Vector3d(50, 0, 0));
    ADD_FAILURE() << "three collinear points were accepted";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kBadInput);
    EXPECT_NE(std::string(error.what()).find("collinear"), std::string::npos);
  }
  EXPECT_NO_THROW((void)ThreePointFrame(p1, p2, Eigen::Vector3d(300, 1.0, 0)));  // 0.19 deg
}

TEST(PmacAxisDefinitions, ReproduceTheMotorCountsOfTheFrame) {
  const Eigen::Matrix3d axes = Eigen::AngleAxisd(0.25, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d origin(100.0, 50.0, -20.0);
  const WorkpieceFrame frame =
      ThreePointFrame(origin, origin + axes.col(0) * 50.0, origin + axes.col(1) * 50.0);
  const PmacAxisOptions options{
      .coordinate_system = 2, .motors = {4, 5, 6}, .counts_per_mm = {10000.0, 10000.0, -5000.0}};
  const auto lines = PmacAxisDefinitions(frame.MachineFromWorkpiece(), options);
  ASSERT_EQ(lines.size(), 4u);
  EXPECT_EQ(lines[0], "&2");
  // cos(0.25) = 0.968912421710645, sin(0.25) = 0.247403959254523.
  EXPECT_EQ(lines[1], "#4->9689.124217X-2474.039593Y+0Z+1000000");
  EXPECT_EQ(lines[2], "#5->2474.039593X+9689.124217Y+0Z+500000");
  EXPECT_EQ(lines[3], "#6->0X+0Y-5000Z+100000");
  EXPECT_THROW((void)PmacAxisDefinitions(frame.MachineFromWorkpiece(), {.motors = {1, 1, 2}}), Error);
}

}  // namespace
}  // namespace arcwheel::frames
