#include "polishing/time_scaling.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "core/check.h"
#include "core/error.h"
#include "polishing/dwell.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kTimeScalingStage = "polishing.robot";
// A lengthened segment takes this much more than the joint's bare time, so that the check of the
// slowed path, which divides the same numbers the other way, never finds it a rounding too fast.
constexpr double kTimeRoundingMargin = 1e-9;

// The segment's least time and the joint that sets it.
struct JointTime {
  double time_s = 0.0;
  int joint = 1;
};

JointTime LeastTime(const RobotKinematics& kinematics, const RobotMargins& margins, const JointAngles& from,
                    const JointAngles& to) {
  JointTime least;
  for (std::size_t i = 0; i < static_cast<std::size_t>(kRobotJoints); ++i) {
    const double allowed_rad_s = margins.max_joint_speed_ratio * kinematics.limits()[i].max_speed_rad_s;
    const double time_s = std::abs(to[i] - from[i]) / allowed_rad_s * (1.0 + kTimeRoundingMargin);
    if (time_s > least.time_s) least = {time_s, static_cast<int>(i) + 1};
  }
  return least;
}

AddedRemoval Figures(const ErrorMap& added_um) {
  AddedRemoval figures;
  double low = std::numeric_limits<double>::infinity(), high = -low, squares = 0.0;
  long nodes = 0;
  for (int j = 0; j < added_um.grid.ny; ++j) {
    for (int i = 0; i < added_um.grid.nx; ++i) {
      const double v = added_um.At(i, j) * 1e3;
      if (!std::isfinite(v)) continue;
      low = std::min(low, v);
      if (v > high) {
        high = v;
        figures.max_at_mm = {added_um.grid.X(i), added_um.grid.Y(j)};
      }
      squares += v * v;
      ++nodes;
    }
  }
  if (nodes == 0) return figures;
  figures.pv_nm = high - low;
  figures.rms_nm = std::sqrt(squares / static_cast<double>(nodes));
  figures.max_nm = high;
  return figures;
}

// The slowed segment whose added time adds the most removal at `xy`.
const SlowedSegment& MostAt(const std::vector<SlowedSegment>& slowed, std::span<const PolishingPoint> points,
                            const RemovalFunction& removal, const Eigen::Vector2d& xy) {
  const auto added_at = [&](const SlowedSegment& s) {
    const Eigen::Vector2d d = xy - points[s.target].contact_xy_mm;
    return removal.RateUmPerS(d.x(), d.y()) * (s.slowed_s - s.planned_s);
  };
  return *std::max_element(slowed.begin(), slowed.end(), [&](const SlowedSegment& a, const SlowedSegment& b) {
    return added_at(a) < added_at(b);
  });
}

}  // namespace

TimeScaling SlowDownToJointSpeeds(std::vector<PolishingPoint>& points, const RobotKinematics& kinematics,
                                  const RobotPath& path, const ErrorMap& target,
                                  const surfaces::Aperture& aperture, const RemovalFunction& removal,
                                  const RobotMargins& margins, const std::string& job_name) {
  ARCWHEEL_CHECK(path.joints_rad.size() == points.size())
      << path.joints_rad.size() << " joint sets for " << points.size() << " targets";
  TimeScaling scaling;
  std::vector<double> added_s(points.size(), 0.0);
  std::vector<Eigen::Vector2d> contact(points.size());
  for (std::size_t k = 0; k < points.size(); ++k) {
    contact[k] = points[k].contact_xy_mm;
    PolishingPoint& p = points[k];
    if (k == 0 || !(p.dwell_s > 0.0)) continue;  // the approach; a standstill has no speed to lower
    const JointTime least = LeastTime(kinematics, margins, path.joints_rad[k - 1], path.joints_rad[k]);
    if (!(least.time_s > p.dwell_s)) continue;
    scaling.slowed.push_back({k, least.joint, p.dwell_s, least.time_s});
    added_s[k] = least.time_s - p.dwell_s;
    scaling.added_time_s += added_s[k];
    p.speed_mm_s *= p.dwell_s / least.time_s;  // the same chord in the longer time
    p.dwell_s = least.time_s;
  }
  if (scaling.slowed.empty()) return scaling;
  scaling.added = Figures(RemovalOfDwell(target, aperture, contact, added_s, removal));
  if (scaling.added.max_nm > margins.max_added_residual_nm) {
    const SlowedSegment& worst = MostAt(scaling.slowed, points, removal, scaling.added.max_at_mm);
    const Eigen::Vector3d& p = points[worst.target].position_mm;
    throw Error(
        ErrorCode::kBadInput, kTimeScalingStage,
        fmt::format("'{}': path target {} ({:.3f}, {:.3f}, {:.3f}) mm in the work object: joint {} too fast "
                    "for the dwell's speed; slowed from {:.4g} s to {:.4g} s it adds, with the other {} "
                    "slowed segments, {:.3f} nm of removal at ({:.3f}, {:.3f}) mm, more than "
                    "robot.max_added_residual_nm = {} (raise it, or place the work object where the "
                    "joints turn less: --place-workobject)",
                    job_name, worst.target + 1, p.x(), p.y(), p.z(), worst.joint, worst.planned_s,
                    worst.slowed_s, scaling.slowed.size() - 1, scaling.added.max_nm,
                    scaling.added.max_at_mm.x(), scaling.added.max_at_mm.y(), margins.max_added_residual_nm));
  }
  return scaling;
}

}  // namespace arcwheel::polishing
