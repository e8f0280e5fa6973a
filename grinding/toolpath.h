#pragma once
// Parallel-grinding toolpath: wheel-centre control points for an arc-profile wheel whose axis is
// parallel to Y, in rows along the feed axis X at constant wheel-centre Y (method.md A.8, eq. 5).
//
// For a contact point (X, Y, Z = f(X, Y)) with slopes fx, fy (eq. 5):
//   N3 = sqrt(fx^2 + fy^2 + 1),  N2 = sqrt(fx^2 + 1)
//   Xw = X - Ra fx / N3 - Rb fx / N2,   Yw = Y - Ra fy / N3,   Zw = Z + Ra / N3 + Rb / N2.
// The arc centre is the contact plus Ra along the unit upward normal n; the wheel centre is the arc
// centre plus Rb along d = (-fx, 0, 1) / N2, the normal's direction in the wheel's XZ plane.
//
// Rows keep Yw constant: for each target (Xw, Yw) the contact (X, Y) is found by Newton's method on
// eq. 5 with its exact Jacobian (it needs the surface's second derivatives), so rows are straight
// to the solver tolerance (1e-11 mm) instead of wandering with the surface slope.

#include <Eigen/Core>
#include <functional>
#include <string>
#include <vector>

#include "grinding/wheel.h"
#include "surfaces/surface.h"

namespace arcwheel::grinding {

struct ControlPoint {
  Eigen::Vector3d wheel_centre_mm = Eigen::Vector3d::Zero();  // (Xw, Yw, Zw)
  Eigen::Vector3d contact_mm = Eigen::Vector3d::Zero();       // (X, Y, Z) on the surface
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();          // unit upward surface normal
};

// Eq. 5 at contact (x, y): the wheel centre for the surface point there. With a measured profile,
// Ra is replaced by the profile's effective radius at the contact's axial offset u = Ra fy / N3.
// Precondition: surface.InDomain(x, y).
[[nodiscard]] ControlPoint ControlPointForContact(const surfaces::Surface& surface, const Wheel& wheel,
                                                  double x_mm, double y_mm);

// Lowest point of the wheel (a solid disc with a toroidal rim, width limited to the wheel's
// half width) above (x, y) when its centre is at `wheel_centre_mm`; +infinity where the wheel does
// not reach over (x, y). The wheel is ideal (circle of radius Ra); `extra_base_radius_mm` grows
// Rb and `extra_arc_radius_mm` grows Ra (used to model a wheel with errors).
[[nodiscard]] double WheelBottomZ(const Wheel& wheel, const Eigen::Vector3d& wheel_centre_mm, double x_mm,
                                  double y_mm, double extra_arc_radius_mm = 0.0,
                                  double extra_base_radius_mm = 0.0);

// Signed distance (mm) from `point_mm` to the ideal torus of the wheel placed at
// `wheel_centre_mm` (negative inside the rim).
[[nodiscard]] double DistanceToTorus(const Wheel& wheel, const Eigen::Vector3d& wheel_centre_mm,
                                     const Eigen::Vector3d& point_mm);

// Solves eq. 5 backwards: the contact whose wheel centre has the given (Xw, Yw). `guess` is a
// contact (x, y) to start from. Throws Error{kBadInput, "grinding.toolpath"} naming the target if
// Newton's method fails (the wheel cannot follow the surface there).
[[nodiscard]] ControlPoint SolveContactForWheelCentre(const surfaces::Surface& surface, const Wheel& wheel,
                                                      double xw_mm, double yw_mm, Eigen::Vector2d guess_mm);
// The same with the contact's X fixed and Yw given: used for row ends.
[[nodiscard]] ControlPoint SolveContactOnRow(const surfaces::Surface& surface, const Wheel& wheel,
                                             double contact_x_mm, double yw_mm, Eigen::Vector2d guess_mm);

// Jacobian d(Xw, Yw) / d(X, Y) of eq. 5 at contact (x, y), from the surface's exact second
// derivatives (the slope of a measured profile is neglected).
[[nodiscard]] Eigen::Matrix2d Eq5Jacobian(const surfaces::Surface& surface, const Wheel& wheel, double x_mm,
                                          double y_mm);

// Hessian (1/mm) of the wheel's lower surface W(x, y) minus the surface's Hessian, at the contact
// of `point` (the wheel placed at its centre). Positive definite: the wheel clears the surface
// around the contact.
[[nodiscard]] Eigen::Matrix2d ClearanceHessian(const surfaces::Surface& surface, const Wheel& wheel,
                                               const ControlPoint& point);

// Smallest eigenvalue (1/mm) of ClearanceHessian: negative means that in some direction the
// surface (concave there) is more curved than the wheel, which then cuts in beside the contact.
[[nodiscard]] double LocalClearanceCurvature(const surfaces::Surface& surface, const Wheel& wheel,
                                             const ControlPoint& point);

// Smallest gap between the wheel placed at `point` and the surface, over a samples x samples grid
// of surface points under the wheel's footprint inside the aperture (across the wheel's usable
// width; along X over the wheel's reach, denser near the contact). The wheel is the torus of the
// profile's radius at the contact. A negative gap is a gouge of that depth.
struct GougeProbe {
  double min_gap_mm = 0.0;
  double x_mm = 0.0;  // where the smallest gap is
  double y_mm = 0.0;
};
[[nodiscard]] GougeProbe ProbeGouge(const surfaces::Surface& surface, const surfaces::Aperture& aperture,
                                    const Wheel& wheel, const ControlPoint& point, int samples);

struct ToolpathOptions {
  // Distance between rows (wheel-centre Y), mm, > 0. Rows are spread evenly, never wider.
  double step_over_mm = 1.0;
  // Largest distance between control points along a row (wheel-centre X), mm, > 0.
  double point_spacing_mm = 0.5;
  // If > 0: spacing along a row is chosen so that the straight move between control points
  // departs from the true wheel-centre curve by at most this (um), never above point_spacing_mm.
  double chordal_tolerance_um = 0.0;
  double feed_mm_per_min = 1000.0;  // > 0
  // Depth of cut per pass (um, >= 0) and number of passes (>= 1); the last pass is the surface.
  double depth_per_pass_um = 0.0;
  int passes = 1;
  // Contacts run this far past the aperture's edge at the start and end of each row (mm, >= 0).
  double lead_in_mm = 5.0;
  double lead_out_mm = 5.0;
  // Alternate the feed direction row by row (true) or always feed towards +X (false).
  bool zigzag = true;
  // Gouge check. Every control point gets the exact local check (the wheel's curvature against
  // the surface's at the contact, and the contact within the wheel's usable arc). On a grid of
  // about this spacing (mm, > 0: every few rows, along each row and at its ends) the wheel is
  // also checked against `gouge_samples` x `gouge_samples` surface points under its footprint.
  double gouge_check_spacing_mm = 10.0;
  int gouge_samples = 21;
  // Allowed cut below the surface in the gouge check, mm.
  double gouge_tolerance_mm = 1e-6;
  // Worker threads; 0 = all hardware threads.
  int threads = 0;
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct ToolpathRow {
  int pass = 0;
  int row = 0;                       // index within the pass
  bool reversed = false;             // fed towards -X
  double z_offset_mm = 0.0;          // stock left by this pass (added to Zw and to the contact's z)
  std::vector<ControlPoint> points;  // in machining order, z offset applied
  // Free for the sink's `prepare` step (e.g. formatted output). Row objects are reused from block
  // to block: the strings arrive cleared but keep their capacity.
  std::vector<std::string> text;
};

// Two callbacks: `prepare` runs on a worker thread (any order, may be empty) and `consume` on the
// calling thread in machining order. Rows are produced in blocks, so memory stays bounded.
struct RowSink {
  std::function<void(ToolpathRow&)> prepare;
  std::function<void(ToolpathRow&)> consume;
};

struct ToolpathSummary {
  int passes = 0;
  int rows_per_pass = 0;
  long long control_points = 0;  // over all passes
  double first_row_yw_mm = 0.0;
  double row_pitch_mm = 0.0;
  double max_row_deviation_mm = 0.0;  // max |Yw - row's Yw| over all points
  long long gouge_checks = 0;         // global checks done
  double min_gouge_gap_mm = 0.0;      // smallest wheel-to-surface gap off the contact found
  double min_local_clearance_per_mm = 0.0;
};

// Rows are built in blocks of this many per worker thread; a block's rows are held at once.
inline constexpr int kRowsInFlightPerWorker = 8;

// Generates the toolpath row by row and hands each row to `sink`. Throws
// Error{kBadInput, "grinding.toolpath"} naming the point where the wheel cannot reach the surface,
// would leave its usable arc, or would gouge; Error{kInvalidOption} for invalid options.
ToolpathSummary GenerateToolpath(const surfaces::Surface& surface, const surfaces::Aperture& aperture,
                                 const Wheel& wheel, const ToolpathOptions& options, const RowSink& sink);

}  // namespace arcwheel::grinding
