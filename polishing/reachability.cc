#include "polishing/reachability.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <optional>

#include "core/check.h"
#include "core/error.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kReachabilityStage = "polishing.robot";
constexpr double kDegPerRad = 180.0 / std::numbers::pi;
constexpr double kTwoPi = 2.0 * std::numbers::pi;

struct Failure {
  std::size_t target = 0;
  std::string why;
  bool speed = false;  // a joint too fast (the target itself is reachable in this configuration)
};

// A branch's solution of the targets `index` (all, or a subsample when searching placements).
struct BranchRun {
  RobotPath path;
  std::optional<Failure> failure;
};

// Joint 4 or 6: the turn of `q` (+- 2 pi n) nearest `previous`.
double NearestTurn(double q, double previous) { return q + kTwoPi * std::round((previous - q) / kTwoPi); }

std::optional<std::string> LimitProblem(const JointAngles& q, const RobotKinematics& kinematics,
                                        const RobotMargins& margins) {
  for (int i = 0; i < kRobotJoints; ++i) {
    const JointLimit& l = kinematics.limits()[static_cast<std::size_t>(i)];
    const double qi = q[static_cast<std::size_t>(i)];
    const double margin_deg = std::min(qi - l.lower_rad, l.upper_rad - qi) * kDegPerRad;
    if (margin_deg < margins.min_joint_margin_deg) {
      return fmt::format("joint {} {} its limit: {:.3f} deg, limits {:.1f} .. {:.1f} deg{}", i + 1,
                         margin_deg < 0.0 ? "beyond" : "too near", qi * kDegPerRad, l.lower_rad * kDegPerRad,
                         l.upper_rad * kDegPerRad,
                         margin_deg < 0.0
                             ? std::string()
                             : fmt::format(" ({:.3f} deg inside, robot.min_joint_margin_deg = {})",
                                           margin_deg, margins.min_joint_margin_deg));
    }
  }
  const double wrist_deg = std::abs(q[4]) * kDegPerRad;
  if (wrist_deg < margins.min_wrist_margin_deg) {
    return fmt::format(
        "through the wrist singularity (joint 5): joint 5 at {:.3f} deg, within "
        "robot.min_wrist_margin_deg = {} of 0, where joints 4 and 6 line up",
        q[4] * kDegPerRad, margins.min_wrist_margin_deg);
  }
  return std::nullopt;
}

std::string OutOfReach(const RobotKinematics& kinematics, const Eigen::Isometry3d& pose) {
  const ArmGeometry& g = kinematics.model().geometry;
  const Eigen::Vector3d w = kinematics.WristCentre(pose);
  const double upper = std::hypot(g.c3_mm, g.a2_mm);
  const double front = std::hypot(std::hypot(w.x(), w.y()) - g.a1_mm, w.z() - g.c1_mm);
  return fmt::format(
      "out of reach: its wrist centre ({:.1f}, {:.1f}, {:.1f}) mm in the robot's base frame lies "
      "{:.1f} mm from axis 2, the arm reaches {:.1f} .. {:.1f} mm",
      w.x(), w.y(), w.z(), front, std::abs(upper - g.c2_mm), upper + g.c2_mm);
}

BranchRun RunBranch(const RobotKinematics& kinematics, const RobotMargins& margins,
                    std::span<const Eigen::Isometry3d> poses, std::span<const double> segment_time_s,
                    std::span<const std::size_t> index, const ArmBranch& branch, bool check_speed) {
  BranchRun run;
  RobotPath& path = run.path;
  path.branch = branch;
  path.min_limit_margin_deg.fill(std::numeric_limits<double>::infinity());
  path.wrist_margin_deg = std::numeric_limits<double>::infinity();
  path.joints_rad.reserve(index.size());
  const auto& limits = kinematics.limits();
  for (std::size_t n = 0; n < index.size(); ++n) {
    const std::size_t k = index[n];
    std::optional<JointAngles> q = kinematics.Inverse(poses[k], branch);
    if (!q) {
      run.failure = Failure{k, OutOfReach(kinematics, poses[k])};
      return run;
    }
    for (const std::size_t i : {std::size_t{3}, std::size_t{5}}) {
      // The first target takes the turn nearest the middle of the joint's range.
      const double previous =
          n == 0 ? 0.5 * (limits[i].lower_rad + limits[i].upper_rad) : path.joints_rad.back()[i];
      (*q)[i] = NearestTurn((*q)[i], previous);
    }
    if (std::optional<std::string> why = LimitProblem(*q, kinematics, margins)) {
      run.failure = Failure{k, std::move(*why)};
      return run;
    }
    if (check_speed && n > 0) {
      const JointAngles& before = path.joints_rad.back();
      const double t = segment_time_s[k];
      for (std::size_t i = 0; i < static_cast<std::size_t>(kRobotJoints); ++i) {
        const double moved = std::abs((*q)[i] - before[i]);
        const double ratio = moved == 0.0 ? 0.0
                             : t > 0.0    ? moved / t / limits[i].max_speed_rad_s
                                          : std::numeric_limits<double>::infinity();
        path.max_speed_ratio[i] = std::max(path.max_speed_ratio[i], ratio);
        if (ratio > margins.max_joint_speed_ratio) {
          run.failure = Failure{
              k,
              fmt::format("joint {} too fast: it turns {:.4f} deg in the {:.4g} s of the segment into the "
                          "target, {:.1f} deg/s, {:.3f} of its maximum {:.0f} deg/s "
                          "(robot.max_joint_speed_ratio = {})",
                          i + 1, moved * kDegPerRad, t, t > 0.0 ? moved / t * kDegPerRad : 0.0, ratio,
                          limits[i].max_speed_rad_s * kDegPerRad, margins.max_joint_speed_ratio),
              true};
          return run;
        }
      }
    }
    for (std::size_t i = 0; i < static_cast<std::size_t>(kRobotJoints); ++i) {
      const double margin =
          std::min((*q)[i] - limits[i].lower_rad, limits[i].upper_rad - (*q)[i]) * kDegPerRad;
      path.min_limit_margin_deg[i] = std::min(path.min_limit_margin_deg[i], margin);
    }
    path.wrist_margin_deg = std::min(path.wrist_margin_deg, std::abs((*q)[4]) * kDegPerRad);
    path.joints_rad.push_back(*q);
  }
  const auto largest = std::max_element(path.max_speed_ratio.begin(), path.max_speed_ratio.end());
  path.largest_speed_ratio = *largest;
  path.largest_speed_joint = static_cast<int>(largest - path.max_speed_ratio.begin()) + 1;
  for (std::size_t i = 0; i < static_cast<std::size_t>(kRobotJoints); ++i)
    path.limits_deg[i] = {limits[i].lower_rad * kDegPerRad, limits[i].upper_rad * kDegPerRad};
  path.confdata.reserve(path.joints_rad.size());
  for (const JointAngles& q : path.joints_rad)
    path.confdata.push_back({JointQuadrant(q[0]), JointQuadrant(q[3]), JointQuadrant(q[5]), branch.Cfx()});
  return run;
}

std::vector<std::size_t> AllTargets(std::size_t n) {
  std::vector<std::size_t> index(n);
  for (std::size_t k = 0; k < n; ++k) index[k] = k;
  return index;
}

// Every configuration on `index`; the best that runs them, or the failures of all eight.
struct Solved {
  std::optional<RobotPath> best;
  std::vector<Failure> failures;  // per cfx, when none runs them
};

Solved SolveAll(const RobotKinematics& kinematics, const RobotMargins& margins,
                std::span<const Eigen::Isometry3d> poses, std::span<const double> segment_time_s,
                std::span<const std::size_t> index, bool check_speed) {
  Solved solved;
  double best_slack = -std::numeric_limits<double>::infinity();
  for (int cfx = 0; cfx < 8; ++cfx) {
    BranchRun run =
        RunBranch(kinematics, margins, poses, segment_time_s, index, ArmBranch::FromCfx(cfx), check_speed);
    if (run.failure) {
      solved.failures.push_back(std::move(*run.failure));
      continue;
    }
    const double slack = MarginSlackDeg(run.path, margins);
    if (slack > best_slack) {
      best_slack = slack;
      solved.best = std::move(run.path);
    }
  }
  return solved;
}

std::string Describe(std::size_t k, std::span<const Eigen::Vector3d> target_mm) {
  if (k < target_mm.size()) {
    return fmt::format("path target {} ({:.3f}, {:.3f}, {:.3f}) mm in the work object", k + 1,
                       target_mm[k].x(), target_mm[k].y(), target_mm[k].z());
  }
  return fmt::format("path target {}", k + 1);
}

}  // namespace

std::vector<Eigen::Isometry3d> FlangePosesInBase(std::span<const PolishingPoint> points, const ToolData& tool,
                                                 const WorkObject& work_object,
                                                 const Eigen::Isometry3d& world_from_base) {
  Eigen::Isometry3d world_from_work_object = Eigen::Isometry3d::Identity();
  world_from_work_object.linear() = RotationFromAbbQuaternion(work_object.orientation);
  world_from_work_object.translation() = work_object.origin_mm;
  Eigen::Isometry3d flange_from_tcp = Eigen::Isometry3d::Identity();
  flange_from_tcp.linear() = RotationFromAbbQuaternion(tool.orientation);
  flange_from_tcp.translation() = tool.CorrectedTcpMm();
  const Eigen::Isometry3d base_from_work_object = world_from_base.inverse() * world_from_work_object;
  const Eigen::Isometry3d tcp_from_flange = flange_from_tcp.inverse();
  std::vector<Eigen::Isometry3d> poses;
  poses.reserve(points.size());
  for (const PolishingPoint& p : points) {
    Eigen::Isometry3d work_object_from_tcp = Eigen::Isometry3d::Identity();
    work_object_from_tcp.linear() = RotationFromAbbQuaternion(p.orientation);
    work_object_from_tcp.translation() = p.position_mm;
    poses.push_back(base_from_work_object * work_object_from_tcp * tcp_from_flange);
  }
  return poses;
}

double MarginSlackDeg(const RobotPath& path, const RobotMargins& margins) {
  if (path.largest_speed_ratio > margins.max_joint_speed_ratio) return -1.0;
  const double joint = *std::min_element(path.min_limit_margin_deg.begin(), path.min_limit_margin_deg.end());
  return std::min(joint - margins.min_joint_margin_deg, path.wrist_margin_deg - margins.min_wrist_margin_deg);
}

RobotPath SolveRobotPath(const RobotKinematics& kinematics, const RobotMargins& margins,
                         std::span<const Eigen::Isometry3d> poses, std::span<const double> segment_time_s,
                         const std::string& job_name, std::span<const Eigen::Vector3d> target_mm) {
  ARCWHEEL_CHECK(segment_time_s.size() == poses.size()) << segment_time_s.size() << " times";
  if (poses.empty()) return {};
  const std::vector<std::size_t> all = AllTargets(poses.size());
  Solved solved = SolveAll(kinematics, margins, poses, segment_time_s, all, true);
  if (solved.best) return std::move(*solved.best);
  // The configuration that gets furthest along the path names the failure.
  const auto furthest =
      std::max_element(solved.failures.begin(), solved.failures.end(),
                       [](const Failure& a, const Failure& b) { return a.target < b.target; });
  const int furthest_cfx = static_cast<int>(furthest - solved.failures.begin());
  // Is every target reachable on its own, in some configuration?
  bool each_alone = true;
  std::optional<int> alone_cfx;
  for (std::size_t k = 0; k < poses.size() && each_alone; ++k) {
    const std::size_t one[] = {k};
    Solved single = SolveAll(kinematics, margins, poses, segment_time_s, one, false);
    each_alone = single.best.has_value();
    if (k == furthest->target && single.best) alone_cfx = single.best->branch.Cfx();
  }
  const std::string robot = std::string(kinematics.model().name);
  // A joint too fast is not cured by another configuration: named as it is.
  if (each_alone && !furthest->speed) {
    throw Error(
        ErrorCode::kBadInput, kReachabilityStage,
        fmt::format("'{}': the path needs a configuration change: no one arm configuration of {} runs "
                    "every target; the one that gets furthest (cfx {}) stops at {}: {}{}",
                    job_name, robot, furthest_cfx, Describe(furthest->target, target_mm), furthest->why,
                    alone_cfx ? fmt::format("; that target alone needs cfx {}", *alone_cfx) : ""));
  }
  throw Error(
      ErrorCode::kBadInput, kReachabilityStage,
      fmt::format("'{}': {} cannot run the path: {}: {} (in the arm configuration that gets furthest, "
                  "cfx {}; the others stop there or earlier)",
                  job_name, robot, Describe(furthest->target, target_mm), furthest->why, furthest_cfx));
}

WorkObjectProposal ProposeWorkObjectOrigin(const RobotKinematics& kinematics, const RobotMargins& margins,
                                           std::span<const PolishingPoint> points, const ToolData& tool,
                                           const WorkObject& work_object,
                                           const Eigen::Isometry3d& world_from_base,
                                           std::span<const double> segment_time_s,
                                           const std::string& job_name) {
  WorkObjectProposal proposal;
  if (points.empty()) return proposal;
  // A subsample of at most 200 targets, the first and last included, for the search.
  std::vector<std::size_t> sample;
  const std::size_t stride = std::max<std::size_t>(1, points.size() / 200);
  for (std::size_t k = 0; k < points.size(); k += stride) sample.push_back(k);
  if (sample.back() != points.size() - 1) sample.push_back(points.size() - 1);
  std::vector<PolishingPoint> sampled;
  for (const std::size_t k : sample) sampled.push_back(points[k]);
  const std::vector<std::size_t> compact = AllTargets(sampled.size());
  const std::vector<double> no_times(sampled.size(), 0.0);
  const ArmGeometry& g = kinematics.model().geometry;
  const double reach = g.c2_mm + std::hypot(g.c3_mm, g.a2_mm);
  auto score = [&](const Eigen::Vector3d& origin_in_base) {
    WorkObject w = work_object;
    w.origin_mm = world_from_base * origin_in_base;
    const std::vector<Eigen::Isometry3d> poses = FlangePosesInBase(sampled, tool, w, world_from_base);
    ++proposal.candidates;
    Solved s = SolveAll(kinematics, margins, poses, no_times, compact, false);
    return s.best ? MarginSlackDeg(*s.best, margins) : -std::numeric_limits<double>::infinity();
  };
  Eigen::Vector3d best = Eigen::Vector3d::Zero();
  double best_score = -std::numeric_limits<double>::infinity();
  const double step0 = 200.0;
  for (double x = -reach; x <= reach; x += step0) {
    for (double y = -reach; y <= reach; y += step0) {
      for (double z = -0.5 * reach; z <= reach; z += step0) {
        const Eigen::Vector3d c(x, y, z);
        if (std::hypot(x, y) > reach + 200.0) continue;
        const double s = score(c);
        if (s > best_score) {
          best_score = s;
          best = c;
        }
      }
    }
  }
  for (const double step : {50.0, 10.0}) {
    const Eigen::Vector3d centre = best;
    for (int i = -3; i <= 3; ++i) {
      for (int j = -3; j <= 3; ++j) {
        for (int l = -3; l <= 3; ++l) {
          const Eigen::Vector3d c = centre + step * Eigen::Vector3d(i, j, l);
          const double s = score(c);
          if (s > best_score) {
            best_score = s;
            best = c;
          }
        }
      }
    }
  }
  proposal.origin_mm = world_from_base * best;
  WorkObject placed = work_object;
  placed.origin_mm = proposal.origin_mm;
  if (!std::isfinite(best_score)) {
    throw Error(ErrorCode::kBadInput, kReachabilityStage,
                fmt::format("'{}': no work-object origin within reach of {} lets it run the path with this "
                            "orientation (tried {} origins)",
                            job_name, kinematics.model().name, proposal.candidates));
  }
  const std::vector<Eigen::Isometry3d> poses = FlangePosesInBase(points, tool, placed, world_from_base);
  proposal.path = SolveRobotPath(kinematics, margins, poses, segment_time_s, job_name);
  proposal.slack_deg = MarginSlackDeg(proposal.path, margins);
  return proposal;
}

}  // namespace arcwheel::polishing
