// End-to-end tests of `arcwheel polish` with a robot in the job: the shipped example run, read back
// from polish.mod and robot_joints.csv and checked against KDL; refusals; --place-workobject.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/testing/testing.h"
#include "polishing/reachability.h"
#include "polishing/robot_kinematics.h"
#include "polishing/robot_model.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using arcwheel::testing::RunArcwheel;
using arcwheel::testing::SourceDir;
using arcwheel::testing::TempDir;
using arcwheel::testing::WriteText;

using testing::kDeg;

std::string ReadText(const std::filesystem::path& path) {
  std::stringstream text;
  text << std::ifstream(path).rdbuf();
  return text.str();
}

// The shipped example job with its map named by absolute path, so that it runs from `dir`.
nlohmann::json ExampleJob() {
  const std::filesystem::path examples = SourceDir() / "polishing" / "examples";
  nlohmann::json job = nlohmann::json::parse(ReadText(examples / "disc_job.json"));
  job["error_map"]["file"] = (examples / "disc_map.csv").string();
  return job;
}

Eigen::Isometry3d Pose(const Eigen::Vector3d& p, const Eigen::Vector4d& q_wxyz) {
  Eigen::Isometry3d t = Eigen::Isometry3d::Identity();
  t.linear() = Eigen::Quaterniond(q_wxyz[0], q_wxyz[1], q_wxyz[2], q_wxyz[3]).normalized().toRotationMatrix();
  t.translation() = p;
  return t;
}

TEST(PolishRobot, TheShippedExampleRunsAndEveryJointSolutionReproducesItsTargetThroughKdl) {
  TempDir dir;
  const nlohmann::json job = ExampleJob();
  const auto result = testing::PolishJob(dir, job);
  ASSERT_EQ(result.exit_status, 0) << result.output;
  // The frames as the job gives them: the work object in the world (the robot's base at the world
  // origin), the TCP in the flange.
  const std::vector<double> origin = job["workobject"]["origin_mm"].get<std::vector<double>>();
  const std::vector<double> tcp = job["tool"]["tcp_mm"].get<std::vector<double>>();
  const std::vector<double> offset = job["tool"]["removal_centre_offset_mm"].get<std::vector<double>>();
  Eigen::Isometry3d world_from_work = Eigen::Isometry3d::Identity();
  world_from_work.translation() = Eigen::Vector3d(origin[0], origin[1], origin[2]);
  Eigen::Isometry3d flange_from_tcp = Eigen::Isometry3d::Identity();
  flange_from_tcp.translation() = Eigen::Vector3d(tcp[0] + offset[0], tcp[1] + offset[1], tcp[2]);

  std::string header;
  const auto path = polishing::testing::ParseCsvRows(ReadText(dir / "out" / "polishing_path.csv"), header);
  std::string joints_header;
  const auto joints =
      polishing::testing::ParseCsvRows(ReadText(dir / "out" / "robot_joints.csv"), joints_header);
  EXPECT_EQ(joints_header, "target,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg");
  ASSERT_EQ(joints.size(), path.size());
  ASSERT_GT(path.size(), 100u);
  for (std::size_t k = 0; k < path.size(); ++k) {
    const auto& p = path[k];
    const Eigen::Isometry3d tcp_in_base =
        world_from_work * Pose({p[0], p[1], p[2]}, {p[3], p[4], p[5], p[6]});
    JointAngles q{};
    for (std::size_t i = 0; i < 6; ++i) q[i] = joints[k][i + 1] * kDeg;
    const Eigen::Isometry3d reached = testing::Irb4600Kinematics().ForwardKdl(q) * flange_from_tcp;
    // 1e-6 mm and 1e-9 rad (the CSVs hold shortest round-trip doubles; the joints' degrees cost
    // about 1e-13 rad).
    EXPECT_LT((reached.translation() - tcp_in_base.translation()).norm(), 1e-6) << "target " << k + 1;
    EXPECT_LT(Eigen::AngleAxisd(reached.linear().transpose() * tcp_in_base.linear()).angle(), 1e-9)
        << "target " << k + 1;
  }
  const nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "polish_summary.json"));
  ASSERT_TRUE(summary.contains("robot")) << summary.dump(2);
  EXPECT_EQ(summary["robot"]["model"], "ABB IRB 4600-40/2.55");
  EXPECT_GE(summary["robot"]["wrist_margin_deg"].get<double>(), 10.0);
  for (const double m : summary["robot"]["min_limit_margin_deg"].get<std::vector<double>>())
    EXPECT_GE(m, 5.0);
  EXPECT_LE(summary["robot"]["largest_joint_speed_ratio"].get<double>(), 0.9);
}

TEST(PolishRobot, PolishModsConfdataIsTheConfigurationOfTheJointsAtEveryTarget) {
  TempDir dir;
  const auto result = testing::PolishJob(dir, ExampleJob());
  ASSERT_EQ(result.exit_status, 0) << result.output;
  const std::string rapid = ReadText(dir / "out" / "polish.mod");
  EXPECT_NE(rapid.find("ConfL \\On;"), std::string::npos);
  EXPECT_EQ(rapid.find("ConfL \\Off;"), std::string::npos);
  // Each robtarget: [[x,y,z],[q1,q2,q3,q4],[cf1,cf4,cf6,cfx],[9E9,...]].
  const std::regex target(
      R"(\[\[[-0-9.]+,[-0-9.]+,[-0-9.]+\],\[[-0-9.,]+\],\[(-?\d+),(-?\d+),(-?\d+),(\d+)\],)");
  std::vector<std::array<int, 4>> confdata;
  for (auto it = std::sregex_iterator(rapid.begin(), rapid.end(), target); it != std::sregex_iterator();
       ++it) {
    confdata.push_back({std::stoi((*it)[1]), std::stoi((*it)[2]), std::stoi((*it)[3]), std::stoi((*it)[4])});
  }
  std::string header;
  const auto joints = polishing::testing::ParseCsvRows(ReadText(dir / "out" / "robot_joints.csv"), header);
  ASSERT_EQ(confdata.size(), joints.size());
  const nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "polish_summary.json"));
  const int cfx = summary["robot"]["cfx"].get<int>();
  for (std::size_t k = 0; k < joints.size(); ++k) {
    // ABB's quadrants, floor(angle / 90 deg), of joints 1, 4 and 6, and the one cfx of the path.
    EXPECT_EQ(confdata[k][0], static_cast<int>(std::floor(joints[k][1] / 90.0))) << "target " << k + 1;
    EXPECT_EQ(confdata[k][1], static_cast<int>(std::floor(joints[k][4] / 90.0))) << "target " << k + 1;
    EXPECT_EQ(confdata[k][2], static_cast<int>(std::floor(joints[k][6] / 90.0))) << "target " << k + 1;
    EXPECT_EQ(confdata[k][3], cfx) << "target " << k + 1;
    // cfx bit 0: joint 5 negative.
    EXPECT_EQ((cfx & 1) != 0, joints[k][5] < 0.0) << "target " << k + 1;
  }
}

TEST(PolishRobot, TheShippedExampleMovedFiveMetresAwayIsRefusedNamingReach) {
  TempDir dir;
  nlohmann::json job = ExampleJob();
  job["workobject"]["origin_mm"][0] = job["workobject"]["origin_mm"][0].get<double>() + 5000.0;
  const auto result = testing::PolishJob(dir, job);
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_NE(result.output.find("path target 1 "), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("out of reach"), std::string::npos) << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "a refused run leaves no output folder";
}

TEST(PolishRobot, RefusesABadRobotSectionNamingEveryProblem) {
  TempDir dir;
  WriteText(dir / "broken.urdf", "<robot name='x'><link name='base_link'>");
  nlohmann::json job = ExampleJob();
  job["robot"] = {{"model", "ABB IRB 9999"},
                  {"base", {{"origin_mm", {0, 0, 0}}, {"quaternion", {1, 0.2, 0, 0}}}},
                  {"min_wrist_margin_deg", 95},
                  {"max_joint_speed_ratio", 0}};
  auto result = testing::PolishJob(dir, job);
  EXPECT_EQ(result.exit_status, 3) << result.output;
  for (const char* problem :
       {"robot.model = 'ABB IRB 9999' is not a robot arcwheel knows (known: ABB IRB 4600-40/2.55)",
        "robot.base.quaternion", "is not a rigid transform", "robot.min_wrist_margin_deg = 95",
        "robot.max_joint_speed_ratio = 0"}) {
    EXPECT_NE(result.output.find(problem), std::string::npos) << problem << "\n" << result.output;
  }
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
  job["robot"] = {{"model", "ABB IRB 4600-40/2.55"},
                  {"urdf", (dir / "broken.urdf").string()},
                  {"base", {{"matrix", {1, 0, 0, 0, 0, 2, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1}}}}};
  result = testing::PolishJob(dir, job);
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_NE(result.output.find("broken.urdf' does not parse"), std::string::npos) << result.output;
  EXPECT_NE(result.output.find("robot.base.matrix is not a rigid transform"), std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(PolishRobot, PlaceWorkobjectProposesAnOriginWhereTheJobThenRuns) {
  TempDir dir;
  nlohmann::json job = ExampleJob();
  job["workobject"]["origin_mm"] = {4000.0, 0.0, 450.0};  // out of reach
  const auto proposal = testing::PolishJob(dir, job, "--place-workobject");
  ASSERT_EQ(proposal.exit_status, 0) << proposal.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "the proposal writes nothing";
  const std::regex origin(R"("origin_mm": \[([-0-9.]+), ([-0-9.]+), ([-0-9.]+)\])");
  std::smatch m;
  ASSERT_TRUE(std::regex_search(proposal.output, m, origin)) << proposal.output;
  EXPECT_NE(proposal.output.find("wrist singularity"), std::string::npos) << proposal.output;
  job["workobject"]["origin_mm"] = {std::stod(m[1]), std::stod(m[2]), std::stod(m[3])};
  const auto run = testing::PolishJob(dir, job);
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "polish_summary.json"));
  EXPECT_GE(summary["robot"]["wrist_margin_deg"].get<double>(), 10.0);
}

}  // namespace
}  // namespace arcwheel::polishing
