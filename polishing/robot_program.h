#pragma once
// The polishing path as the robot runs it, and its two outputs (issue 5 points 5-6):
//  - the path CSV of formats.md section 7: x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s at full precision;
//  - an ABB RAPID module: tooldata of the head, wobjdata of the part frame, one robtarget per
//    point (position and ABB quaternion) and MoveL with per-segment speeddata.

#include <Eigen/Core>
#include <array>
#include <span>
#include <string>
#include <vector>

#include "polishing/dwell.h"
#include "polishing/tool_frame.h"
#include "surfaces/surface.h"

namespace arcwheel::polishing {

struct PolishingPoint {
  Eigen::Vector3d position_mm = Eigen::Vector3d::Zero();    // TCP = contact point, part frame
  AbbQuaternion orientation;                                // tool frame in the part frame
  double speed_mm_s = 0.0;                                  // TCP speed into this point
  double dwell_s = 0.0;                                     // time of the TCP chord into this point
  Eigen::Vector2d contact_xy_mm = Eigen::Vector2d::Zero();  // where the removal of that time falls
  std::size_t dwell_point = 0;  // the dwell point (path point) whose segment this target lies on
};

// Bonnet continuous precession along the robot path (method.md C). At a target the bonnet axis is
// P_O = [a b c] (sin theta cos alpha, sin theta sin alpha, cos theta) with c the outward normal,
// a the x axis of ToolFrameAt (on the tangent plane, a function of the slopes only, so it turns
// smoothly along any path), b = c x a and alpha = w2 t, t the time since the first target. The
// tilt and the phase are continuous along the whole path, lead-in and lead-out (the extension)
// included: the phase is measured from a direction that does not jump where the feed direction
// does (a raster's turns), and the bonnet precesses at full tilt from the first target to the
// last, so the footprint the dwell assumed holds wherever the removal reaches the aperture
// (docs/polishing.md, "Precession"). The tool frame of ToolFrameAt is turned by the smallest
// rotation taking its z (-c) to -P_O, and the target is the bonnet centre, contact +
// bonnet_radius c (the TCP of the tooldata is then the bonnet centre): a spherical bonnet touches
// the surface at the same point at any tilt.
struct PathPrecession {
  bool enabled = false;
  double tilt_deg = 20.0;            // theta, [0, 90)
  double precession_rate_rpm = 5.0;  // w2, finite
  double bonnet_radius_mm = 0.0;     // >= 0
  // A segment whose tool turns more than this (the precession over its dwell plus the normal's
  // turn) is cut into targets this far apart, deg, (0, 45].
  double max_step_deg = 1.0;
  // Empty when valid (or not enabled), else one line per violation naming the job key and the
  // value, e.g. "precession.tilt_deg = 90 violates 0 <= tilt_deg < 90".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The TCP positions the robot runs through, part frame: the contact point on the surface, or with
// precession the bonnet centre, contact + bonnet_radius_mm along the outward normal. The robot moves
// between them on straight chords (MoveL); the removal-centre offset is in the tooldata
// (ToolData::CorrectedTcpMm), so it moves no target. Throws Error{kBadInput, "polishing.path"}
// naming the first point off the surface.
[[nodiscard]] std::vector<Eigen::Vector3d> TcpPositionsMm(const surfaces::Surface& surface,
                                                          std::span<const Eigen::Vector2d> path_xy_mm,
                                                          const PathPrecession& precession = {});

// The 3-D lengths of the TCP chords into each position (first: 0, the approach): what SolveDwell
// divides by the speeds.
[[nodiscard]] std::vector<double> TcpChordsMm(std::span<const Eigen::Vector3d> tcp_mm);

// Places the tool on the surface at each path point (ToolFrameAt, or precessed) with the dwell
// solution's speed and dwell, which must have been solved on the chords of TcpPositionsMm for the
// same precession (checked when the solution carries its chords). With precession a segment whose
// tool would turn more than max_step_deg is cut into m equal steps of the contact's (x, y): each
// intermediate target is the bonnet centre over its own contact point with its own normal, and
// the segment keeps its time: its steps run at the speed that covers their path in it (faster
// than the dwell's speed by the curvature of the bonnet centres' path, about 1e-6 for 2 mm steps
// at 440 mm), each step's dwell_s its chord / that speed, each phase that of its time.
// Throws Error{kBadInput, "polishing.path"} naming the first point off the surface,
// Error{kInvalidOption} for precession options out of range.
[[nodiscard]] std::vector<PolishingPoint> BuildPolishingPath(const surfaces::Surface& surface,
                                                             std::span<const Eigen::Vector2d> path_xy_mm,
                                                             const DwellSolution& dwell, RobotSide side,
                                                             const PathPrecession& precession = {});

struct ToolData {
  // Nominal TCP (the removal centre) in the flange frame, mm, and the tool frame's orientation.
  Eigen::Vector3d tcp_mm = Eigen::Vector3d(0.0, 0.0, 150.0);
  AbbQuaternion orientation;
  // Measured offset of the true removal centre from the nominal TCP, in the tool's x-y plane (mm),
  // from the force-sensor calibration (method.md D, `arcwheel headcenter`). Added to the TCP so
  // that the robot brings the true removal centre onto the path.
  Eigen::Vector2d removal_centre_offset_mm = Eigen::Vector2d::Zero();
  double mass_kg = 5.0;  // > 0
  Eigen::Vector3d centre_of_gravity_mm = Eigen::Vector3d(0.0, 0.0, 75.0);
  [[nodiscard]] Eigen::Vector3d CorrectedTcpMm() const;
  // Empty when valid, else one line per violation naming the job key and the value, e.g.
  // "tool.mass_kg = 0 violates > 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// The part frame in the robot's user frame (the frames issue's workobject): origin and rotation.
struct WorkObject {
  Eigen::Vector3d origin_mm = Eigen::Vector3d::Zero();
  AbbQuaternion orientation;
};

// CSV text per formats.md section 7; `comments` become leading "# " lines.
[[nodiscard]] std::string PolishingPathCsv(std::span<const PolishingPoint> points,
                                           std::span<const std::string> comments);

// RAPID module text. Positions are written to 0.1 um (4 decimals) and quaternions to 9 decimals,
// as RAPID's num holds about 7 significant digits; the module header says so. `confdata` gives
// each target's [cf1, cf4, cf6, cfx] (a robot's solution of the path, reachability.h), one per
// point: the program then runs under ConfL \On, the robot keeping that configuration. Empty: every
// target [0,0,0,0] under ConfL \Off (the controller picks the configuration nearest its own).
[[nodiscard]] std::string RapidModule(std::span<const PolishingPoint> points, const ToolData& tool,
                                      const WorkObject& work_object, const std::string& module_name,
                                      std::span<const std::string> comments,
                                      std::span<const std::array<int, 4>> confdata = {});

}  // namespace arcwheel::polishing
