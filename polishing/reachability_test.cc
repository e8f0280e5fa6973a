#include "polishing/reachability.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>
#include <vector>

#include "core/error.h"
#include "polishing/robot_model.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using testing::kDeg;

// Flange poses along a straight line in joint space from `a` to `b` (deg), through KDL: targets a
// robot reaches by construction, whatever the closed form says.
std::vector<Eigen::Isometry3d> JointLine(const JointAngles& a_deg, const JointAngles& b_deg, int n) {
  std::vector<Eigen::Isometry3d> poses;
  for (int k = 0; k < n; ++k) {
    JointAngles q{};
    for (std::size_t i = 0; i < 6; ++i) q[i] = (a_deg[i] + (b_deg[i] - a_deg[i]) * k / (n - 1)) * kDeg;
    poses.push_back(testing::Irb4600Kinematics().ForwardKdl(q));
  }
  return poses;
}

std::string RefusalOf(std::span<const Eigen::Isometry3d> poses, double segment_s = 1.0,
                      const RobotMargins& margins = {}) {
  const std::vector<double> times(poses.size(), segment_s);
  try {
    (void)SolveRobotPath(testing::Irb4600Kinematics(), margins, poses, times, "job.json");
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    return e.what();
  }
  return "";
}

TEST(SolveRobotPath, SolvesAReachablePathInOneConfigurationWithItsMargins) {
  const auto poses = JointLine({-20, 10, -5, 30, 40, -60}, {25, 30, 10, -30, 70, 60}, 40);
  const std::vector<double> times(poses.size(), 1.0);
  const RobotPath path = SolveRobotPath(testing::Irb4600Kinematics(), {}, poses, times, "job.json");
  ASSERT_EQ(path.joints_rad.size(), poses.size());
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const Eigen::Isometry3d back = testing::Irb4600Kinematics().ForwardKdl(path.joints_rad[k]);
    EXPECT_LT((back.translation() - poses[k].translation()).norm(), 1e-6) << k;
    EXPECT_LT(Eigen::AngleAxisd(back.linear().transpose() * poses[k].linear()).angle(), 1e-9) << k;
    EXPECT_EQ(path.confdata[k][3], path.branch.Cfx());
  }
  // The path's own joints: in front of axis 1 and the lower arm, joint 5 positive (cfx 0) keeps
  // the largest margins. Joint 5 runs 40 .. 70 deg: its smallest |q5| is 40 deg; joint 2 reaches
  // 10 deg at its nearest to the lower limit of -90 deg (margin 100 deg, the upper 150 - 30 = 120).
  EXPECT_EQ(path.branch.Cfx(), 0);
  EXPECT_NEAR(path.wrist_margin_deg, 40.0, 1e-6);
  EXPECT_NEAR(path.min_limit_margin_deg[1], 100.0, 1e-6);
  // Joint 1 turns 45 deg over 39 segments of 1 s: 45 / 39 deg/s against 175 deg/s.
  EXPECT_NEAR(path.max_speed_ratio[0], 45.0 / 39.0 / 175.0, 1e-9);
}

TEST(SolveRobotPath, RefusesAPathThroughTheWristSingularityNamingJoint5) {
  // Joint 5 from +30 to -30 deg with joint 3 at 50 deg: in front of axis 1 and of the lower arm the
  // wrist passes its singularity (with joint 5 of either sign); the other configurations would put
  // joint 3 beyond its range (-180 .. +75 deg) or joint 2 below -90 deg, so none avoids it.
  const auto poses = JointLine({0, 20, 50, 10, 30, 0}, {0, 20, 50, 10, -31, 0}, 31);
  const std::string why = RefusalOf(poses);
  EXPECT_NE(why.find("through the wrist singularity (joint 5)"), std::string::npos) << why;
  // It fails where |joint 5| first falls below the 10 deg margin: 30 - 61 k / 30 < 10 from k = 10
  // (target 11, joint 5 at 9.67 deg).
  EXPECT_NE(why.find("path target 11:"), std::string::npos) << why;
}

TEST(SolveRobotPath, RefusesAJointBeyondItsSpecifiedLimit) {
  // Joint 3 ends at 78 deg: beyond its upper limit of 75 deg, in every configuration.
  const auto poses = JointLine({0, 10, 40, 0, 50, 0}, {0, 10, 78, 0, 50, 0}, 20);
  const std::string why = RefusalOf(poses, 1.0, {.min_joint_margin_deg = 0.0});
  EXPECT_NE(why.find("joint 3 beyond its limit"), std::string::npos) << why;
}

TEST(SolveRobotPath, RefusesAJointTooFastForItsSpecifiedSpeed) {
  // Joint 6 turns 10 deg per segment; at 0.02 s a segment that is 500 deg/s, over its 360 deg/s.
  const auto poses = JointLine({0, 10, 0, 0, 50, 0}, {0, 10, 0, 0, 50, 100}, 11);
  const std::string why = RefusalOf(poses, 0.02, {.max_joint_speed_ratio = 1.0});
  EXPECT_NE(why.find("joint 6 too fast"), std::string::npos) << why;
  EXPECT_EQ(why.find("configuration change"), std::string::npos) << "no other configuration turns it slower";
  // At 0.05 s (200 deg/s) it runs.
  EXPECT_EQ(RefusalOf(poses, 0.05, {.max_joint_speed_ratio = 1.0}), "");
}

TEST(SolveRobotPath, RefusesAPathThatNeedsAConfigurationChange) {
  // First a target far in front (joints 0, 80, -20: the wrist 2040 mm ahead of axis 1, low), which
  // the arm reaches only facing it: turned round (behind axis 1) the lower arm would have to lean
  // back below joint 2's -90 deg limit. Then targets behind the robot on both sides of the base's
  // -x axis, reached with joint 1 at -3 .. 3 deg leaning back (joint 2 -80 deg): facing them, joint
  // 1 would pass through +-180 deg, its limit. No one configuration reaches all; each alone is.
  std::vector<Eigen::Isometry3d> poses = JointLine({0, 80, -20, 0, 45, 0}, {0, 80, -20, 0, 45, 0}, 2);
  const auto behind = JointLine({-3, -80, 0, 0, 60, 0}, {3, -80, 0, 0, 60, 0}, 7);
  poses.insert(poses.end(), behind.begin(), behind.end());
  const std::string why = RefusalOf(poses, 100.0);
  EXPECT_NE(why.find("needs a configuration change"), std::string::npos) << why;
}

TEST(SolveRobotPath, RefusesATargetOutOfReach) {
  std::vector<Eigen::Isometry3d> poses = JointLine({0, 10, 0, 0, 50, 0}, {0, 20, 0, 0, 50, 0}, 3);
  for (Eigen::Isometry3d& p : poses) p.translation().x() += 5000.0;
  const std::string why = RefusalOf(poses);
  EXPECT_NE(why.find("path target 1"), std::string::npos) << why;
  EXPECT_NE(why.find("out of reach"), std::string::npos) << why;
}

TEST(RobotMargins, NamesEveryThresholdOutOfRange) {
  const std::vector<std::string> p =
      RobotMargins{.min_joint_margin_deg = -1, .min_wrist_margin_deg = 90, .max_joint_speed_ratio = 1.5}
          .Problems();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("robot.min_joint_margin_deg = -1"), std::string::npos);
  EXPECT_NE(p[1].find("robot.min_wrist_margin_deg = 90"), std::string::npos);
  EXPECT_NE(p[2].find("robot.max_joint_speed_ratio = 1.5"), std::string::npos);
}

TEST(RigidTransformProblem, AcceptsARotationAndNamesWhatIsNot) {
  Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
  m.topLeftCorner<3, 3>() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  m(0, 3) = 500.0;
  EXPECT_FALSE(RigidTransformProblem(m));
  Eigen::Matrix4d scaled = m;
  scaled.topLeftCorner<3, 3>() *= 1.01;
  EXPECT_TRUE(RigidTransformProblem(scaled));
  Eigen::Matrix4d mirrored = m;
  mirrored.col(0) *= -1.0;
  EXPECT_NE(RigidTransformProblem(mirrored).value_or("").find("reflection"), std::string::npos);
}

}  // namespace
}  // namespace arcwheel::polishing
