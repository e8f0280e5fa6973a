// End-to-end tests of `arcwheel polish` for what the robot runs, read from the written files only:
//  - the shipped precession example passes every robot check with nothing slowed, and its tool
//    turns at most 2 degrees between consecutive targets (polish.mod and polishing_path.csv);
//  - a job whose dwell speeds exceed a joint's speed is slowed there, and the removal recomputed
//    here from the written TCP chords and speeds (the Gaussian summed at each target's contact
//    point) is the prediction residual_map.csv reports; with a tight robot.max_added_residual_nm
//    the job is refused naming the target.
#include <fmt/core.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <numbers>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include "core/testing/testing.h"
#include "polishing/robot_kinematics.h"
#include "polishing/robot_model.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using arcwheel::testing::ReadText;
using arcwheel::testing::RunArcwheel;
using arcwheel::testing::SourceDir;
using arcwheel::testing::TempDir;
using arcwheel::testing::WriteText;

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

nlohmann::json Example(const std::string& name) {
  const std::filesystem::path examples = SourceDir() / "polishing" / "examples";
  nlohmann::json job = nlohmann::json::parse(ReadText(examples / name));
  job["error_map"]["file"] = (examples / "disc_map.csv").string();
  return job;
}

std::vector<std::vector<double>> Rows(const std::filesystem::path& file, const std::string& header) {
  std::string found;
  auto rows = testing::ParseCsvRows(ReadText(file), found);
  EXPECT_EQ(found, header) << file;
  return rows;
}

// polish.mod's robtargets: position and quaternion (q1 scalar first) as the controller reads them.
struct RapidTarget {
  Eigen::Vector3d position_mm;
  Eigen::Quaterniond orientation;
};

std::vector<RapidTarget> RapidTargets(const std::string& rapid) {
  const std::regex target(
      R"(\[\[([-0-9.]+),([-0-9.]+),([-0-9.]+)\],\[([-0-9.]+),([-0-9.]+),([-0-9.]+),([-0-9.]+)\],\[)");
  std::vector<RapidTarget> out;
  for (auto it = std::sregex_iterator(rapid.begin(), rapid.end(), target); it != std::sregex_iterator();
       ++it) {
    const auto& m = *it;
    out.push_back({{std::stod(m[1]), std::stod(m[2]), std::stod(m[3])},
                   Eigen::Quaterniond(std::stod(m[4]), std::stod(m[5]), std::stod(m[6]), std::stod(m[7]))});
  }
  return out;
}

// Each segment's time from the written path: its TCP chord / its speed.
std::vector<double> ChordTimesS(const std::vector<std::vector<double>>& path) {
  std::vector<double> t(path.size(), 0.0);
  for (std::size_t k = 1; k < path.size(); ++k) {
    const Eigen::Vector3d a(path[k - 1][0], path[k - 1][1], path[k - 1][2]),
        b(path[k][0], path[k][1], path[k][2]);
    t[k] = (b - a).norm() / path[k][7];
  }
  return t;
}

// The largest joint speed / its maximum over every segment, from robot_joints.csv and the times.
double LargestJointSpeedRatio(const std::vector<std::vector<double>>& joints,
                              const std::vector<double>& time_s) {
  double largest = 0.0;
  for (std::size_t k = 1; k < joints.size(); ++k) {
    for (std::size_t i = 0; i < 6; ++i) {
      const double turned_rad = std::abs(joints[k][i + 1] - joints[k - 1][i + 1]) / kDegPerRad;
      largest = std::max(largest,
                         turned_rad / time_s[k] / testing::Irb4600Kinematics().limits()[i].max_speed_rad_s);
    }
  }
  return largest;
}

// Every joint at least 5 deg inside its limits and |joint 5| >= 10 deg (the job's default margins).
void ExpectWithinLimits(const std::vector<std::vector<double>>& joints) {
  for (std::size_t k = 0; k < joints.size(); ++k) {
    for (std::size_t i = 0; i < 6; ++i) {
      const JointLimit& l = testing::Irb4600Kinematics().limits()[i];
      EXPECT_GE(joints[k][i + 1], l.lower_rad * kDegPerRad + 5.0) << "target " << k + 1 << " joint " << i + 1;
      EXPECT_LE(joints[k][i + 1], l.upper_rad * kDegPerRad - 5.0) << "target " << k + 1 << " joint " << i + 1;
    }
    EXPECT_GE(std::abs(joints[k][5]), 10.0) << "target " << k + 1;
  }
}

TEST(PolishPrecession,
     TheShippedExampleRunsEveryRobotCheckWithNothingSlowedAndTurnsAtMostTwoDegreesPerTarget) {
  TempDir dir;
  const nlohmann::json job = Example("disc_precession_job.json");
  ASSERT_TRUE(job.contains("precession"));
  EXPECT_EQ(job["precession"]["tilt_deg"], 20);
  EXPECT_EQ(job["precession"]["precession_rate_rpm"], 5);
  EXPECT_EQ(job["precession"]["bonnet_radius_mm"], 40);
  const auto result = testing::PolishJob(dir, job);
  ASSERT_EQ(result.exit_status, 0) << result.output;

  const std::vector<RapidTarget> rapid = RapidTargets(ReadText(dir / "out" / "polish.mod"));
  const auto path = Rows(dir / "out" / "polishing_path.csv", "x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s");
  const auto joints =
      Rows(dir / "out" / "robot_joints.csv", "target,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg");
  ASSERT_GT(rapid.size(), 100u);
  ASSERT_EQ(rapid.size(), path.size());
  ASSERT_EQ(joints.size(), path.size());
  double largest_rapid_deg = 0.0, largest_csv_deg = 0.0, largest_tilt_change_deg = 0.0;
  for (std::size_t k = 1; k < rapid.size(); ++k) {
    largest_rapid_deg = std::max(largest_rapid_deg,
                                 rapid[k - 1].orientation.angularDistance(rapid[k].orientation) * kDegPerRad);
    const Eigen::Quaterniond a(path[k - 1][3], path[k - 1][4], path[k - 1][5], path[k - 1][6]);
    const Eigen::Quaterniond b(path[k][3], path[k][4], path[k][5], path[k][6]);
    largest_csv_deg = std::max(largest_csv_deg, a.angularDistance(b) * kDegPerRad);
    // The tool axis against the part's z axis: it changes smoothly from the first target on.
    const double tilt_a = std::acos(-a.toRotationMatrix()(2, 2)),
                 tilt_b = std::acos(-b.toRotationMatrix()(2, 2));
    largest_tilt_change_deg = std::max(largest_tilt_change_deg, std::abs(tilt_b - tilt_a) * kDegPerRad);
  }
  EXPECT_LE(largest_rapid_deg, 2.0);
  EXPECT_LE(largest_csv_deg, 2.0);
  EXPECT_LE(largest_tilt_change_deg, 2.0);
  // The precession is there: the tool axis leans 20 deg +- the part's slope from the part's z axis
  // at every target; the slope r / sqrt(R^2 - (1 + k) r^2) of the asphere (R 400 mm, k -0.5) is
  // at most 5.15 deg out to the path's 36 mm.
  for (std::size_t k = 0; k < path.size(); ++k) {
    const Eigen::Quaterniond q(path[k][3], path[k][4], path[k][5], path[k][6]);
    const double lean_deg = std::acos(-q.toRotationMatrix()(2, 2)) * kDegPerRad;
    EXPECT_NEAR(lean_deg, 20.0, 5.2) << "target " << k + 1;
  }
  // Every robot check, from the written joints and times: limits, wrist, joint speeds.
  ExpectWithinLimits(joints);
  EXPECT_LE(LargestJointSpeedRatio(joints, ChordTimesS(path)), 0.9);
  const nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "polish_summary.json"));
  EXPECT_TRUE(summary["robot"]["slowed_segments"].empty()) << summary["robot"].dump(2);
  EXPECT_EQ(summary["robot"]["added_time_s"], 0.0);
}

// The documented removal function of the example: its peak rate and FWHM, zero beyond 3.5 sigma.
double ExampleRateUmPerS(const nlohmann::json& job, double dx_mm, double dy_mm) {
  const double peak = job["removal_function"]["peak_rate_um_per_s"].get<double>();
  const double sigma =
      job["removal_function"]["fwhm_mm"].get<double>() / (2.0 * std::sqrt(2.0 * std::log(2.0)));
  const double r2 = dx_mm * dx_mm + dy_mm * dy_mm;
  return r2 > 3.5 * sigma * 3.5 * sigma ? 0.0 : peak * std::exp(-r2 / (2.0 * sigma * sigma));
}

// The removal at each residual_map.csv node from the written path: each chord's time at the
// contact point it ends at (without precession the TCP is the contact point).
std::vector<double> RemovalFromPath(const nlohmann::json& job, const std::vector<std::vector<double>>& path,
                                    const std::vector<std::vector<double>>& nodes) {
  const std::vector<double> time_s = ChordTimesS(path);
  std::vector<double> removal(nodes.size(), 0.0);
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    for (std::size_t k = 1; k < path.size(); ++k)
      removal[n] += ExampleRateUmPerS(job, nodes[n][0] - path[k][0], nodes[n][1] - path[k][1]) * time_s[k];
  }
  return removal;
}

constexpr char kResidualHeader[] = "x_mm,y_mm,target_um,removal_um,residual_um";
constexpr char kPathHeader[] = "x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s";
// A joint speed limit the example's dwell speeds exceed along part of the path.
constexpr double kSlowJointSpeedRatio = 0.03;

TEST(PolishTimeScaling, SegmentsTooFastForAJointAreSlowedAndTheReportedRemovalIsTheWrittenPathsRemoval) {
  TempDir fast_dir, slow_dir;
  const nlohmann::json fast_job = Example("disc_job.json");
  ASSERT_EQ(testing::PolishJob(fast_dir, fast_job).exit_status, 0);
  nlohmann::json job = fast_job;
  job["robot"]["max_joint_speed_ratio"] = kSlowJointSpeedRatio;
  job["robot"]["max_added_residual_nm"] = 1e6;
  const auto result = testing::PolishJob(slow_dir, job);
  ASSERT_EQ(result.exit_status, 0) << result.output;

  const auto fast_path = Rows(fast_dir / "out" / "polishing_path.csv", kPathHeader);
  const auto path = Rows(slow_dir / "out" / "polishing_path.csv", kPathHeader);
  const auto joints =
      Rows(slow_dir / "out" / "robot_joints.csv", "target,j1_deg,j2_deg,j3_deg,j4_deg,j5_deg,j6_deg");
  const auto fast_nodes = Rows(fast_dir / "out" / "residual_map.csv", kResidualHeader);
  const auto nodes = Rows(slow_dir / "out" / "residual_map.csv", kResidualHeader);
  ASSERT_EQ(path.size(), fast_path.size());
  ASSERT_EQ(nodes.size(), fast_nodes.size());
  const nlohmann::json summary = nlohmann::json::parse(ReadText(slow_dir / "out" / "polish_summary.json"));
  const nlohmann::json& slowed = summary["robot"]["slowed_segments"];
  ASSERT_FALSE(slowed.empty()) << summary["robot"].dump(2);

  // Slowed where the summary says, to exactly what the joint allows; the targets are not moved.
  const std::vector<double> time_s = ChordTimesS(path), fast_time_s = ChordTimesS(fast_path);
  EXPECT_LE(LargestJointSpeedRatio(joints, time_s), kSlowJointSpeedRatio * (1.0 + 1e-6));
  std::vector<bool> listed(path.size(), false);
  for (const nlohmann::json& s : slowed) {
    const std::size_t k = s["target"].get<std::size_t>() - 1;
    listed[k] = true;
    EXPECT_NEAR(s["planned_s"].get<double>(), fast_time_s[k], 1e-9 * fast_time_s[k]);
    EXPECT_NEAR(s["slowed_s"].get<double>(), time_s[k], 1e-9 * time_s[k]);
    EXPECT_GT(time_s[k], fast_time_s[k]);
    const auto i = s["joint"].get<std::size_t>();
    const double turned_rad = std::abs(joints[k][i] - joints[k - 1][i]) / kDegPerRad;
    EXPECT_NEAR(turned_rad / time_s[k] / testing::Irb4600Kinematics().limits()[i - 1].max_speed_rad_s,
                kSlowJointSpeedRatio, 1e-6);
  }
  double added_time_s = 0.0;
  for (std::size_t k = 0; k < path.size(); ++k) {
    for (std::size_t c = 0; c < 3; ++c) EXPECT_EQ(path[k][c], fast_path[k][c]) << "target " << k + 1;
    if (!listed[k]) {
      EXPECT_NEAR(time_s[k], fast_time_s[k], 1e-9 * (1.0 + fast_time_s[k])) << "target " << k + 1;
    }
    added_time_s += time_s[k] - fast_time_s[k];
  }
  EXPECT_NEAR(summary["robot"]["added_time_s"].get<double>(), added_time_s, 1e-6 * added_time_s);

  // The reported prediction is the removal of the written path, recomputed here.
  const std::vector<double> removal = RemovalFromPath(job, path, nodes);
  double largest_difference = 0.0, most_added_nm = 0.0, squares = 0.0;
  std::size_t most_at = 0;
  for (std::size_t n = 0; n < nodes.size(); ++n) {
    largest_difference = std::max({largest_difference, std::abs(nodes[n][3] - removal[n]),
                                   std::abs(nodes[n][4] - (nodes[n][2] - removal[n]))});
    const double added_nm = (nodes[n][3] - fast_nodes[n][3]) * 1e3;
    squares += added_nm * added_nm;
    if (added_nm > most_added_nm) {
      most_added_nm = added_nm;
      most_at = n;
    }
  }
  EXPECT_LE(largest_difference, 1e-9);
  const nlohmann::json& added = summary["robot"]["added_removal"];
  EXPECT_GT(most_added_nm, 0.01);
  EXPECT_NEAR(added["max_nm"].get<double>(), most_added_nm, 1e-6 * most_added_nm);
  EXPECT_NEAR(added["rms_nm"].get<double>(), std::sqrt(squares / static_cast<double>(nodes.size())),
              1e-6 * most_added_nm);
  EXPECT_EQ(added["max_at_mm"][0].get<double>(), nodes[most_at][0]);
  EXPECT_EQ(added["max_at_mm"][1].get<double>(), nodes[most_at][1]);

  // With a tolerance below that, refused naming a slowed target, and nothing written.
  TempDir tight_dir;
  job["robot"]["max_added_residual_nm"] = 0.5 * most_added_nm;
  const auto refused = testing::PolishJob(tight_dir, job);
  EXPECT_EQ(refused.exit_status, 3) << refused.output;
  EXPECT_NE(refused.output.find("robot.max_added_residual_nm"), std::string::npos) << refused.output;
  std::smatch m;
  ASSERT_TRUE(std::regex_search(refused.output, m, std::regex(R"(path target (\d+) \()"))) << refused.output;
  EXPECT_TRUE(listed.at(std::stoul(m[1]) - 1)) << refused.output;
  EXPECT_FALSE(std::filesystem::exists(tight_dir / "out"));
}

}  // namespace
}  // namespace arcwheel::polishing
