#include "polishing/robot_program.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>

#include "core/check.h"
#include "core/error.h"
#include "core/version.h"
#include "schema/polish_outputs.h"

namespace arcwheel::polishing {
namespace {

std::string Quaternion9(const AbbQuaternion& q) {
  return fmt::format("[{:.9f},{:.9f},{:.9f},{:.9f}]", q.q1, q.q2, q.q3, q.q4);
}

void CheckPrecession(const PathPrecession& precession) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "polishing.path", precession.Problems());
}

// The outward (upward) unit normal: minus the tool's z, which points into the part.
Eigen::Vector3d OutwardNormal(const surfaces::Surface& surface, const Eigen::Vector2d& p) {
  const surfaces::SurfacePoint sp = surface.Evaluate(p.x(), p.y());
  return Eigen::Vector3d(-sp.fx, -sp.fy, 1.0).normalized();
}

}  // namespace

std::vector<Eigen::Vector3d> TcpPositionsMm(const surfaces::Surface& surface,
                                            std::span<const Eigen::Vector2d> path_xy_mm,
                                            const PathPrecession& precession) {
  CheckPrecession(precession);
  std::vector<Eigen::Vector3d> tcp;
  tcp.reserve(path_xy_mm.size());
  for (std::size_t k = 0; k < path_xy_mm.size(); ++k) {
    const Eigen::Vector2d& p = path_xy_mm[k];
    if (!surface.InDomain(p.x(), p.y())) {
      throw Error(ErrorCode::kBadInput, "polishing.path",
                  fmt::format("path point {} ({}, {}) mm is off the surface {}", k, p.x(), p.y(),
                              surface.Describe()));
    }
    Eigen::Vector3d position(p.x(), p.y(), surface.Evaluate(p.x(), p.y()).z_mm);
    if (precession.enabled) position += precession.bonnet_radius_mm * OutwardNormal(surface, p);
    tcp.push_back(position);
  }
  return tcp;
}

std::vector<double> TcpChordsMm(std::span<const Eigen::Vector3d> tcp_mm) {
  std::vector<double> chord_mm(tcp_mm.size(), 0.0);
  for (std::size_t k = 1; k < tcp_mm.size(); ++k) chord_mm[k] = (tcp_mm[k] - tcp_mm[k - 1]).norm();
  return chord_mm;
}

namespace {

constexpr double kRadPerDeg = std::numbers::pi / 180.0;

// The shortest rotation taking direction `from` onto `to`, as Eigen's Quaternion::FromTwoVectors
// computes it for directions less than 180 degrees apart (its arithmetic, to the bit). Its branch
// for opposite directions solves an SVD that the tilt (< 90 degrees) never reaches, and compiling
// that SVD took a third of this library's heaviest unity batch.
Eigen::Quaterniond RotationBetween(const Eigen::Vector3d& from, const Eigen::Vector3d& to) {
  const Eigen::Vector3d v0 = from.normalized(), v1 = to.normalized();
  const double c = v1.dot(v0);
  ARCWHEEL_CHECK(c > -0.5) << "directions " << c << " apart in cosine";
  const Eigen::Vector3d axis = v0.cross(v1);
  const double s = std::sqrt((1.0 + c) * 2.0);
  const Eigen::Vector3d vec = axis * (1.0 / s);
  return Eigen::Quaterniond(s * 0.5, vec.x(), vec.y(), vec.z());
}

// The precession's fixed parts: tilt and rate in radians.
struct Precessor {
  const surfaces::Surface& surface;
  RobotSide side;
  const PathPrecession& precession;
  double tilt_rad = precession.tilt_deg * kRadPerDeg;
  double rate_rad_s = precession.precession_rate_rpm * 2.0 * std::numbers::pi / 60.0;

  // The target over contact (x, y), the tool precessed to the phase of `elapsed_s` since the
  // first target.
  [[nodiscard]] PolishingPoint At(const Eigen::Vector2d& xy, double elapsed_s) const {
    if (!surface.InDomain(xy.x(), xy.y())) {
      throw Error(
          ErrorCode::kBadInput, "polishing.path",
          fmt::format("path point ({}, {}) mm is off the surface {}", xy.x(), xy.y(), surface.Describe()));
    }
    const Eigen::Matrix3d part_from_tool = ToolFrameAt(surface, xy.x(), xy.y(), side);
    const Eigen::Vector3d c = -part_from_tool.col(2), a = part_from_tool.col(0);
    const double alpha = rate_rad_s * elapsed_s;
    const Eigen::Vector3d axis = std::sin(tilt_rad) * std::cos(alpha) * a +
                                 std::sin(tilt_rad) * std::sin(alpha) * c.cross(a) + std::cos(tilt_rad) * c;
    PolishingPoint point;
    point.contact_xy_mm = xy;
    point.position_mm = Eigen::Vector3d(xy.x(), xy.y(), surface.Evaluate(xy.x(), xy.y()).z_mm) +
                        precession.bonnet_radius_mm * c;
    point.orientation =
        AbbQuaternionFromRotation(RotationBetween(-c, -axis).toRotationMatrix() * part_from_tool);
    return point;
  }

  // Steps for a segment of `dwell_s` between contacts a and b: the tool turns by at most the
  // axis's arc on its cone, 2 sin(theta / 2) w2 t (the frame's twist about the axis included),
  // plus the normal's turn.
  [[nodiscard]] int Steps(const Eigen::Vector2d& a, const Eigen::Vector2d& b, double dwell_s) const {
    const double cone_rad = 2.0 * std::sin(0.5 * tilt_rad) * std::abs(rate_rad_s) * dwell_s;
    const Eigen::Vector3d na = -ToolFrameAt(surface, a.x(), a.y(), side).col(2);
    const Eigen::Vector3d nb = -ToolFrameAt(surface, b.x(), b.y(), side).col(2);
    const double normal_rad = std::acos(std::clamp(na.dot(nb), -1.0, 1.0));
    const double turn_deg = (cone_rad + normal_rad) / kRadPerDeg;
    return std::max(1, static_cast<int>(std::ceil(turn_deg / precession.max_step_deg - 1e-12)));
  }
};

void CheckDwellChords(std::span<const Eigen::Vector3d> tcp, const DwellSolution& dwell) {
  if (dwell.chord_mm.empty()) return;
  // A dwell solved on other chords (another precession, or the contact points' steps) would
  // make the robot's times differ from the dwell the prediction assumed.
  const std::vector<double> chord_mm = TcpChordsMm(tcp);
  ARCWHEEL_CHECK(dwell.chord_mm.size() == chord_mm.size()) << dwell.chord_mm.size() << " chords";
  for (std::size_t k = 0; k < chord_mm.size(); ++k) {
    ARCWHEEL_CHECK(std::abs(dwell.chord_mm[k] - chord_mm[k]) <= 1e-12 * (1.0 + chord_mm[k]))
        << "the dwell was solved for a TCP chord of " << dwell.chord_mm[k] << " mm into point " << k
        << ", the robot runs " << chord_mm[k] << " mm";
  }
}

}  // namespace

std::vector<PolishingPoint> BuildPolishingPath(const surfaces::Surface& surface,
                                               std::span<const Eigen::Vector2d> path_xy_mm,
                                               const DwellSolution& dwell, RobotSide side,
                                               const PathPrecession& precession) {
  if (dwell.dwell_s.size() != path_xy_mm.size() || dwell.speed_mm_s.size() != path_xy_mm.size()) {
    throw Error(
        ErrorCode::kInvalidOption, "polishing.path",
        fmt::format("{} path points but a dwell solution for {}", path_xy_mm.size(), dwell.dwell_s.size()));
  }
  const std::vector<Eigen::Vector3d> tcp = TcpPositionsMm(surface, path_xy_mm, precession);
  CheckDwellChords(tcp, dwell);
  std::vector<PolishingPoint> points;
  points.reserve(path_xy_mm.size());
  if (!precession.enabled) {
    for (std::size_t k = 0; k < path_xy_mm.size(); ++k) {
      const Eigen::Vector2d& p = path_xy_mm[k];
      PolishingPoint point;
      point.position_mm = tcp[k];
      point.orientation = AbbQuaternionFromRotation(ToolFrameAt(surface, p.x(), p.y(), side));
      point.speed_mm_s = dwell.speed_mm_s[k];
      point.dwell_s = dwell.dwell_s[k];
      point.contact_xy_mm = p;
      point.dwell_point = k;
      points.push_back(point);
    }
    return points;
  }
  const Precessor precessor{surface, side, precession};
  PolishingPoint first = precessor.At(path_xy_mm[0], 0.0);
  first.position_mm = tcp[0];
  first.speed_mm_s = dwell.speed_mm_s[0];
  first.dwell_s = dwell.dwell_s[0];
  points.push_back(first);
  double elapsed_s = dwell.dwell_s[0];
  for (std::size_t k = 1; k < path_xy_mm.size(); ++k) {
    const Eigen::Vector2d &a = path_xy_mm[k - 1], &b = path_xy_mm[k];
    const int steps = precessor.Steps(a, b, dwell.dwell_s[k]);
    const std::size_t segment_start = points.size();
    // The steps' contacts, then their bonnet centres, then the time of each along the segment.
    double length_mm = 0.0;
    for (int s = 1; s <= steps; ++s) {
      const double u = static_cast<double>(s) / steps;
      PolishingPoint point = precessor.At(s == steps ? b : Eigen::Vector2d((1.0 - u) * a + u * b), 0.0);
      if (s == steps) point.position_mm = tcp[k];  // the dwell point itself, as TcpPositionsMm placed it
      length_mm += (point.position_mm - points.back().position_mm).norm();
      point.dwell_point = k;
      points.push_back(point);
    }
    // One step: the segment's own speed and dwell. Several: the segment's time kept, at the speed
    // that runs the steps' (slightly longer) path in it.
    const double speed_mm_s =
        steps == 1 || !(dwell.dwell_s[k] > 0.0) ? dwell.speed_mm_s[k] : length_mm / dwell.dwell_s[k];
    double along_s = 0.0;
    for (std::size_t j = segment_start; j < points.size(); ++j) {
      PolishingPoint& point = points[j];
      point.speed_mm_s = speed_mm_s;
      point.dwell_s =
          steps == 1 ? dwell.dwell_s[k] : (point.position_mm - points[j - 1].position_mm).norm() / speed_mm_s;
      along_s += point.dwell_s;
      point.orientation = precessor.At(point.contact_xy_mm, elapsed_s + along_s).orientation;
    }
    elapsed_s += along_s;
  }
  return points;
}

Eigen::Vector3d ToolData::CorrectedTcpMm() const {
  const Eigen::Matrix3d flange_from_tool = RotationFromAbbQuaternion(orientation);
  return tcp_mm +
         flange_from_tool * Eigen::Vector3d(removal_centre_offset_mm.x(), removal_centre_offset_mm.y(), 0.0);
}

std::string PolishingPathCsv(std::span<const PolishingPoint> points, std::span<const std::string> comments) {
  fmt::memory_buffer out;
  for (const std::string& c : comments) fmt::format_to(std::back_inserter(out), "# {}\n", c);
  fmt::format_to(std::back_inserter(out), "{}\n", fmt::join(schema::polish::path::kColumns, ","));
  for (const PolishingPoint& p : points) {
    // "{}" is the shortest representation that reads back to the same double.
    fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},{},{},{}\n", p.position_mm.x(),
                   p.position_mm.y(), p.position_mm.z(), p.orientation.q1, p.orientation.q2, p.orientation.q3,
                   p.orientation.q4, p.speed_mm_s, p.dwell_s);
  }
  return fmt::to_string(out);
}

std::string RapidModule(std::span<const PolishingPoint> points, const ToolData& tool,
                        const WorkObject& work_object, const std::string& module_name,
                        std::span<const std::string> comments, std::span<const std::array<int, 4>> confdata) {
  ARCWHEEL_CHECK(confdata.empty() || confdata.size() == points.size())
      << confdata.size() << " confdata for " << points.size() << " points";
  fmt::memory_buffer out;
  auto line = [&out](const std::string& text) { fmt::format_to(std::back_inserter(out), "{}\n", text); };
  line(fmt::format("MODULE {}", module_name));
  line(fmt::format("  ! arcwheel {} polishing program: {} points", kVersion, points.size()));
  for (const std::string& c : comments) line(fmt::format("  ! {}", c));
  line("  ! Positions rounded to 0.1 um, quaternions to 9 decimals (RAPID num precision).");
  const Eigen::Vector3d tcp = tool.CorrectedTcpMm();
  line(fmt::format("  ! TCP {:.4f},{:.4f},{:.4f} mm includes the removal-centre offset {:.4f},{:.4f} mm.",
                   tcp.x(), tcp.y(), tcp.z(), tool.removal_centre_offset_mm.x(),
                   tool.removal_centre_offset_mm.y()));
  line(fmt::format(
      "  PERS tooldata tPolish := "
      "[TRUE,[[{:.4f},{:.4f},{:.4f}],{}],[{:.4f},[{:.4f},{:.4f},{:.4f}],[1,0,0,0],0,0,0]];",
      tcp.x(), tcp.y(), tcp.z(), Quaternion9(tool.orientation), tool.mass_kg, tool.centre_of_gravity_mm.x(),
      tool.centre_of_gravity_mm.y(), tool.centre_of_gravity_mm.z()));
  line(fmt::format(
      "  PERS wobjdata wPart := [FALSE,TRUE,\"\",[[{:.4f},{:.4f},{:.4f}],{}],[[0,0,0],[1,0,0,0]]];",
      work_object.origin_mm.x(), work_object.origin_mm.y(), work_object.origin_mm.z(),
      Quaternion9(work_object.orientation)));
  line(fmt::format("  CONST num nPoints := {};", points.size()));
  line(fmt::format("  CONST robtarget pPath{{{}}} := [", points.size()));
  for (std::size_t k = 0; k < points.size(); ++k) {
    const PolishingPoint& p = points[k];
    const std::array<int, 4> conf = confdata.empty() ? std::array<int, 4>{0, 0, 0, 0} : confdata[k];
    line(fmt::format("    [[{:.4f},{:.4f},{:.4f}],{},[{},{},{},{}],[9E9,9E9,9E9,9E9,9E9,9E9]]{}",
                     p.position_mm.x(), p.position_mm.y(), p.position_mm.z(), Quaternion9(p.orientation),
                     conf[0], conf[1], conf[2], conf[3], k + 1 < points.size() ? "," : "];"));
  }
  // speeddata: TCP speed (mm/s), reorientation (deg/s), linear and rotational external axes.
  line(fmt::format("  CONST speeddata vPath{{{}}} := [", points.size()));
  for (std::size_t k = 0; k < points.size(); ++k) {
    line(fmt::format("    [{:.4f},500,5000,1000]{}", points[k].speed_mm_s,
                     k + 1 < points.size() ? "," : "];"));
  }
  // Fly-by (z1) through every point but the last, so that the TCP keeps its speed from segment
  // to segment; the last move is a stop point (fine), so that the program ends with the tool
  // exactly on the last target. Each target is moved to once: no zero-length repeat of the last.
  line("  PROC main()");
  // With the robot's solution the configuration is held (and checked by the controller).
  line(confdata.empty() ? "    ConfL \\Off;" : "    ConfL \\On;");
  line("    FOR i FROM 1 TO nPoints - 1 DO");
  line("      MoveL pPath{i}, vPath{i}, z1, tPolish \\WObj:=wPart;");
  line("    ENDFOR");
  line("    MoveL pPath{nPoints}, vPath{nPoints}, fine, tPolish \\WObj:=wPart;");
  line("  ENDPROC");
  line("ENDMODULE");
  return fmt::to_string(out);
}

std::vector<std::string> PathPrecession::Problems() const {
  std::vector<std::string> problems;
  if (!enabled) return problems;
  if (!(tilt_deg >= 0.0 && tilt_deg < 90.0)) {
    problems.push_back(fmt::format("precession.tilt_deg = {} violates 0 <= tilt_deg < 90", tilt_deg));
  }
  if (!std::isfinite(precession_rate_rpm)) {
    problems.push_back(
        fmt::format("precession.precession_rate_rpm = {} violates finite", precession_rate_rpm));
  }
  if (!(bonnet_radius_mm >= 0.0)) {
    problems.push_back(fmt::format("precession.bonnet_radius_mm = {} violates >= 0", bonnet_radius_mm));
  }
  if (!(max_step_deg > 0.0 && max_step_deg <= 45.0))
    problems.push_back(
        fmt::format("precession.max_step_deg = {} violates 0 < max_step_deg <= 45", max_step_deg));
  return problems;
}

std::vector<std::string> ToolData::Problems() const {
  if (mass_kg > 0.0) return {};
  return {fmt::format("tool.mass_kg = {} violates > 0", mass_kg)};
}

}  // namespace arcwheel::polishing
