#include "frames/three_point_frame.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numbers>
#include <set>

#include "core/error.h"

namespace arcwheel::frames {
namespace {

constexpr const char* kThreePointFrameStage = "frames.three_point";

std::string Point(const Eigen::Vector3d& p) { return fmt::format("({}, {}, {})", p.x(), p.y(), p.z()); }

// A PMAC number: fixed decimals with trailing zeros (and a bare point) removed.
std::string PmacNumber(double value, int decimals) {
  std::string text = fmt::format("{:.{}f}", value, decimals);
  if (text.find('.') != std::string::npos) {
    while (text.back() == '0') text.pop_back();
    if (text.back() == '.') text.pop_back();
  }
  if (text == "-0") text = "0";
  return text;
}

std::string Signed(const std::string& number) { return number.front() == '-' ? number : "+" + number; }

}  // namespace

std::vector<std::string> ThreePointFrameOptions::Problems() const {
  std::vector<std::string> problems;
  if (!(min_separation_mm > 0.0))
    problems.push_back(fmt::format("--min-separation-mm = {} violates > 0", min_separation_mm));
  if (!(min_angle_deg > 0.0 && min_angle_deg < 90.0))
    problems.push_back(fmt::format("--min-angle-deg = {} violates (0, 90)", min_angle_deg));
  return problems;
}

Transform WorkpieceFrame::MachineFromWorkpiece() const {
  Transform t;
  t.model = TransformModel::kRigid3d;
  t.linear = axes;
  t.translation_mm = origin_mm;
  return t;
}

Transform WorkpieceFrame::WorkpieceFromMachine() const { return MachineFromWorkpiece().Inverse(); }

WorkpieceFrame ThreePointFrame(const Eigen::Vector3d& p1_mm, const Eigen::Vector3d& p2_mm,
                               const Eigen::Vector3d& p3_mm, const ThreePointFrameOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kThreePointFrameStage, options.Problems());
  if (!p1_mm.allFinite() || !p2_mm.allFinite() || !p3_mm.allFinite()) {
    throw Error(ErrorCode::kBadInput, kThreePointFrameStage, "a probed point has a non-finite coordinate");
  }
  const Eigen::Vector3d along_x = p2_mm - p1_mm;
  const Eigen::Vector3d in_plane = p3_mm - p1_mm;
  if (along_x.norm() < options.min_separation_mm) {
    throw Error(
        ErrorCode::kBadInput, kThreePointFrameStage,
        fmt::format("the origin P1 {} and the +X point P2 {} coincide ({:.3g} mm apart, minimum {} mm)",
                    Point(p1_mm), Point(p2_mm), along_x.norm(), options.min_separation_mm));
  }
  if (in_plane.norm() < options.min_separation_mm) {
    throw Error(
        ErrorCode::kBadInput, kThreePointFrameStage,
        fmt::format("the origin P1 {} and the XY-plane point P3 {} coincide ({:.3g} mm apart, minimum {} mm)",
                    Point(p1_mm), Point(p3_mm), in_plane.norm(), options.min_separation_mm));
  }
  const Eigen::Vector3d i = along_x.normalized();
  const double angle_deg = std::atan2(i.cross(in_plane).norm(), i.dot(in_plane)) * 180.0 / std::numbers::pi;
  if (std::min(angle_deg, 180.0 - angle_deg) < options.min_angle_deg) {
    throw Error(ErrorCode::kBadInput, kThreePointFrameStage,
                fmt::format("P1 {}, P2 {} and P3 {} are collinear (angle {:.3g} deg at P1, minimum {} deg)",
                            Point(p1_mm), Point(p2_mm), Point(p3_mm), angle_deg, options.min_angle_deg));
  }
  const Eigen::Vector3d j = (in_plane - i.dot(in_plane) * i).normalized();
  WorkpieceFrame frame;
  frame.origin_mm = p1_mm;
  frame.axes.col(0) = i;
  frame.axes.col(1) = j;
  frame.axes.col(2) = i.cross(j);
  frame.angle_p2_p3_deg = angle_deg;
  return frame;
}

std::vector<std::string> PmacAxisOptions::Problems() const {
  std::vector<std::string> problems;
  if (coordinate_system < 1)
    problems.push_back(fmt::format("--coordinate-system = {} violates >= 1", coordinate_system));
  if (std::set<int>(motors.begin(), motors.end()).size() != 3 ||
      *std::min_element(motors.begin(), motors.end()) < 1) {
    problems.push_back(fmt::format("--motors = {} violates distinct and >= 1", fmt::join(motors, ",")));
  }
  if (!std::all_of(counts_per_mm.begin(), counts_per_mm.end(),
                   [](double counts) { return std::isfinite(counts) && counts != 0.0; })) {
    problems.push_back(
        fmt::format("--counts-per-mm = {} violates finite and non-zero", fmt::join(counts_per_mm, ",")));
  }
  if (decimals < 0 || decimals > 12)
    problems.push_back(fmt::format("--pmac-decimals = {} violates [0, 12]", decimals));
  return problems;
}

std::vector<std::string> PmacAxisDefinitions(const Transform& machine_from_workpiece,
                                             const PmacAxisOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "frames.pmac", options.Problems());
  const Eigen::Matrix3d linear = machine_from_workpiece.scale * machine_from_workpiece.linear;
  std::vector<std::string> lines = {fmt::format("&{}", options.coordinate_system)};
  constexpr std::array<char, 3> kAxes = {'X', 'Y', 'Z'};
  for (int n = 0; n < 3; ++n) {
    std::string line = fmt::format("#{}->", options.motors[n]);
    for (int k = 0; k < 3; ++k) {
      const std::string number = PmacNumber(options.counts_per_mm[n] * linear(n, k), options.decimals);
      line += (k == 0 ? number : Signed(number)) + kAxes[k];
    }
    line += Signed(
        PmacNumber(options.counts_per_mm[n] * machine_from_workpiece.translation_mm(n), options.decimals));
    lines.push_back(line);
  }
  return lines;
}

}  // namespace arcwheel::frames
