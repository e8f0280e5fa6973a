#pragma once
// Bonnet continuous precession (method.md C, after Walker et al.).
//
// The bonnet spins about its axis P, tilted by theta from the local outward normal and precessing
// about it at w2, while the contact point feeds along a path at speed v. In the local frame
// A{a, b, c} at the bonnet centre (c = outward normal, a = feed direction projected on the tangent
// plane, b = c x a) the axis is (eqs. 1-4)
//   P_A = Rot(c, alpha) Rot(b, theta) (0, 0, 1) = (sin theta cos alpha, sin theta sin alpha, cos theta),
//   alpha = w2 t,
// and in the workpiece frame P_O = R P_A with R = [a b c] (eqs. 5-15; R is built here directly from
// the frame, which keeps beta3 <= 90 deg since c is the outward normal, and the feed angle gamma is
// the direction of a in the tangent plane).

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <span>
#include <string>
#include <vector>

#include "surfaces/surface.h"

namespace arcwheel::polishing {

struct PrecessionOptions {
  double tilt_deg = 20.0;            // theta, angle between the bonnet axis and the normal, [0, 90)
  double precession_rate_rpm = 5.0;  // w2, revolutions per minute about the normal
  double feed_mm_per_s = 5.0;        // v, speed of the contact point along the path, > 0
  double bonnet_radius_mm = 0.0;     // the bonnet centre sits this far above the contact, >= 0
  double arm_length_mm = 127.0;      // the traced point lies this far up the axis from the centre
  double time_step_s = 0.05;         // sampling interval of the trajectory, > 0
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct PrecessionSample {
  double time_s = 0.0;
  Eigen::Vector3d contact_mm = Eigen::Vector3d::Zero();       // contact point on the surface
  Eigen::Vector3d centre_mm = Eigen::Vector3d::Zero();        // bonnet centre
  Eigen::Matrix3d local_frame = Eigen::Matrix3d::Identity();  // columns a, b, c
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();            // P_O, unit
  Eigen::Vector3d traced_mm = Eigen::Vector3d::Zero();        // centre + arm_length * P_O
};

// Samples the precessing axis while the contact point moves along the polyline `path_xy_mm`
// (part-frame (x, y), heights from the surface) at the feed speed, from its start to its end.
// Throws Error{kInvalidOption, "polishing.precession"} for options out of range or a path with
// fewer than two distinct points; Error{kBadInput} if the path leaves the surface's domain.
[[nodiscard]] std::vector<PrecessionSample> PrecessionTrajectory(const surfaces::Surface& surface,
                                                                 std::span<const Eigen::Vector2d> path_xy_mm,
                                                                 const PrecessionOptions& options);

}  // namespace arcwheel::polishing
