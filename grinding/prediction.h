#pragma once
// Form error a real wheel prints into the part when it follows a toolpath computed for the nominal
// wheel (method.md A.8: "an error in Ra ... prints a cylinder-, sphere- or saddle-shaped low-order
// error"; "runout prints a ripple along the feed with the wheel's period").
//
// Low-order error (arc radius). The nominal path places the wheel centre c(P) for every contact P
// (eq. 5). Swept over a dense path, the wheel's lower envelope is the Minkowski sum of the
// wheel-centre surface and the wheel; its point belonging to c(P) is c(P) plus the wheel's support
// point in direction -n, n the normal at P (offset surfaces share normals). For a torus of arc
// radius Ra' and base radius Rb' that support point is -Ra' n - Rb' d, d = (-fx, 0, 1) / N2, so the
// ground surface passes through
//     Q = P + (Ra - Ra') n + (Rb - Rb') d,
// exactly, for a path whose step-over and point spacing tend to zero. With the wheel's total
// radius fixed by the touch-off (the default), Rb' = Rb - (Ra' - Ra) and Q = P + dRa (d - n): to
// first order a normal error dRa (N2 / N3 - 1), which vanishes where fy = 0 and grows as fy^2.
// The map reports the height error Qz - f(x, y) at each node (x, y), for the contact P whose Q
// lies over the node.
//
// Ripple (runout). At phase phi the wheel's rim stands eps(phi) further out along d. Along a row the
// wheel centre advances feed / rpm per turn; near a node the gap between the wheel and the surface
// grows as (W_xx - f_xx) dx^2 / 2 with the contact shift dx, so the ground height there is
//     min over s of [ (W_xx - f_xx) (s dX/dXw)^2 / 2 - eps(phi(Xw + s)) N2 ],
// s the wheel-centre offset along the row and phi(Xw) = 360 rpm Xw / feed degrees (all rows start
// in phase at Xw = 0). The nominal wheel (eps = 0) gives exactly zero.

#include <filesystem>
#include <string>
#include <vector>

#include "grinding/wheel.h"
#include "surfaces/surface.h"

namespace arcwheel::grinding {

struct PredictionOptions {
  // Real arc radius minus the nominal one used for the path, mm.
  double arc_radius_error_mm = 0.0;
  // True: the total radius is right (set by touch-off), so the base radius errs by -dRa.
  // False: the base radius is right and the total radius errs by +dRa.
  bool keep_total_radius = true;
  // Radial runout of the rim: eps(phi) sampled at `runout_phase_deg` (ascending, within
  // [0, 360)), in um, positive = rim further out. Empty: no runout. Interpolated linearly, periodic.
  std::vector<double> runout_phase_deg{};
  std::vector<double> runout_radial_um{};
  double spindle_rpm = 0.0;  // > 0 when there is runout
  // Profile error of the real wheel that the path's wheel does not follow (e.g. the wheel model's
  // p(u) under a pure-arc path): deviation from the arc along its normal, um, positive = rim
  // standing out, at axial offsets u (mm, ascending) from the arc centre; linear between nodes,
  // the end values beyond them. Empty: none. A rim standing out by p at the contact, whose axial
  // offset is u = Ra fy / N3 (eq. 5), cuts the surface p deeper along the normal: a height error
  // of -p(u) N3 at the node (first order).
  std::vector<double> profile_u_mm{};
  std::vector<double> profile_error_um{};
  double feed_mm_per_min = 1000.0;
  // Map nodes over the aperture's bounding box; nodes outside the aperture are NaN.
  int nodes_x = 201;
  int nodes_y = 201;
  int threads = 0;  // 0 = all hardware threads
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// Runout of a wheel whose rim is a circle off the spindle axis: eps = TIR / 2 cos(phi), 360 nodes.
void SetEccentricRunout(double total_indicated_runout_um, PredictionOptions& options);

struct FormPrediction {
  std::vector<double> x_mm;          // [nodes_x]
  std::vector<double> y_mm;          // [nodes_y]
  std::vector<double> error_um;      // [nodes_y * nodes_x], row-major in y; NaN outside the aperture
  std::vector<double> low_order_um;  // the arc-radius part alone, same layout
  double pv_um = 0.0;
  double rms_um = 0.0;  // about the mean
  // After removing the least-squares plane (piston and tilt: the part's alignment).
  double pv_after_tilt_um = 0.0;
  double rms_after_tilt_um = 0.0;
  double ripple_pv_um = 0.0;   // PV of the runout part alone
  double profile_pv_um = 0.0;  // PV of the profile-error part alone (0 without one)
};

// Throws Error{kInvalidOption, "grinding.prediction"} for invalid options and
// Error{kBadInput} when a node lies off the surface's domain.
[[nodiscard]] FormPrediction PredictFormError(const surfaces::Surface& surface,
                                              const surfaces::Aperture& aperture, const Wheel& wheel,
                                              const PredictionOptions& options);

// Writes the map as a grid map (schema/grid_map.h, the layout `arcwheel polish` reads): error_um,
// low_order_um, x_mm, y_mm and the grid attributes at the root, the PV/RMS figures and the surface
// and wheel descriptions as root attributes (through the caller's atomic staging). Throws
// Error{kIo}.
void WritePredictionHdf5(const FormPrediction& prediction, const std::filesystem::path& path,
                         const std::string& surface_description, const std::string& wheel_description);

}  // namespace arcwheel::grinding
