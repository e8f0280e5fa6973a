#pragma once
// Dwell time for computer-controlled polishing (issue 5 point 3, method.md B).
//
// The removal is the convolution of the dwell with the tool's removal function: the depth removed
// at map node m is  sum_k R(x_m - x_k, y_m - y_k) t_k,  with t_k the dwell (s) at path point k and
// R the tool's removal rate (um/s, removal_function.h: a Gaussian or a measured table) in the
// part's (x, y) projection. Dwell points lie anywhere along
// the path (not on the map's grid). The dwell solves the bounded linear least-squares problem
//     minimise || A t - target ||^2  over the clear-aperture nodes,   t_min_k <= t_k <= t_max_k,
// where the bounds come from the speed limits. The dwell model (docs/polishing.md, "Dwell model"):
// the robot runs a straight TCP chord into each point (MoveL, at that point's speed), and a
// point's dwell is the time of the chord that ends at it, t_k = chord_k / speed_k, with chord_k
// the 3-D length of the TCP move (tool offset and precession included: the caller passes the
// chords). The removal of that time is counted at the point's contact (x_k, y_k). The path runs
// beyond the aperture by an extension so that the edge can be reached by the whole removal
// function (surface extension); residuals are counted inside the aperture only.
//
// A is sparse (the Gaussian is truncated at 3.5 sigma, 0.2 % of the peak; a table ends at its
// edge); the problem is solved by accelerated projected gradient (FISTA with adaptive restart),
// whose cost is the products A t and A^T r. The removal function is the same at every point, so
// when the dwell points lie on the map's grid these products are 2-D convolutions, computed with
// FFTs (removal_fft.h); otherwise (a circle's raster lines, a spiral) with the sparse matrix.
// With FFT products the gradient is preceded by inverse-filter iterations (RIFTA, Wang et al.
// 2020, "Robust iterative Fourier transform algorithm for dwell time calculation"), which reach
// a lower residual in a few tens of products (DwellOptions::inverse_filter_start).
//
// With an acceleration limit the speeds are shaped as a motion planner does: a forward and a
// backward pass cap each speed by what its neighbour allows, v_k <= sqrt(v_(k-1)^2 + 2 a L_k) and
// v_(k-1) <= sqrt(v_k^2 + 2 a L_k). Shaping only lowers speeds, i.e. lengthens dwells; those
// dwells become per-point lower bounds and the dwell is solved again, the rest of the path making
// up for the extra removal. Rounds repeat until the solved dwell needs (almost) no shaping; the
// bounds only grow, so they settle. The dwell reported is the shaped one of the last round, and
// the prediction is of that dwell.

#include <Eigen/Core>
#include <span>
#include <string>
#include <vector>

#include "polishing/removal_function.h"
#include "polishing/removal_target.h"
#include "surfaces/surface.h"

namespace arcwheel::polishing {

struct RasterOptions {
  double line_spacing_mm = 2.0;   // distance between raster lines (along y), > 0
  double point_spacing_mm = 2.0;  // largest distance between dwell points along a line, > 0
  double extension_mm = 0.0;      // the path runs this far beyond the aperture, >= 0
  // Empty when valid, else one line per violation with its value, named by the job key
  // ("path.line_spacing_mm = 0 violates > 0").
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// A zigzag raster: lines along x, stepping in y, over the aperture grown by the extension; each
// line is cut into equal steps of at most point_spacing_mm. Throws Error{kInvalidOption}.
[[nodiscard]] std::vector<Eigen::Vector2d> RasterPath(const surfaces::Aperture& aperture,
                                                      const RasterOptions& options);

// An Archimedean spiral r = pitch theta / (2 pi) from the aperture's centre outwards, pitch =
// line_spacing_mm, cut into equal arc-length steps of at most point_spacing_mm, out to the radius
// of the grown aperture (a rectangle's: its half diagonal, so the corners are covered).
// Throws Error{kInvalidOption}.
[[nodiscard]] std::vector<Eigen::Vector2d> SpiralPath(const surfaces::Aperture& aperture,
                                                      const RasterOptions& options);

enum class PathPattern { kRaster, kSpiral };

struct DwellOptions {
  double max_speed_mm_s = 100.0;  // fastest TCP speed, > 0: sets the least dwell of each point
  double min_speed_mm_s = 0.0;    // slowest TCP speed, [0, max]; 0 = no bound on dwell
  double min_dwell_s = 0.0;       // least dwell of every point after the first (controller), >= 0
  // Largest TCP acceleration, mm/s^2; 0 = no limit. The speed changes from v_(k-1) to v_k over
  // the TCP chord into point k, which takes |v_k^2 - v_(k-1)^2| / (2 chord_k); the speeds are
  // shaped to it (see above).
  double max_acceleration_mm_s2 = 0.0;
  // Per-point least dwell (s), one per path point (the first, the approach, must be 0), each
  // >= 0 and <= the point's longest dwell; empty = none. Kept even where it removes more than
  // the target.
  std::vector<double> least_dwell_s = {};
  int max_iterations = 2000;         // projected-gradient iterations, >= 1 (the job file's default too)
  double relative_tolerance = 1e-7;  // stop when the dwell changes by less than this, relative
  // Also stop when the residual norm has improved over the last stall_iterations iterations by
  // less than stall_improvement times the first residual norm (of the first solve, also in the
  // shaping rounds): further iterations only polish the prediction at the sub-nanometre level.
  // stall_iterations = 0 disables this test.
  int stall_iterations = 100;       // >= 0
  double stall_improvement = 1e-3;  // > 0
  // Shaping rounds (re-solves) allowed before the speeds count as unreachable, >= 1.
  int max_shaping_rounds = 20;
  // A round settles when shaping its dwell adds at most this depth (peak rate x added dwell) at
  // any point, um, > 0 (1 nm: below what the solve itself resolves on a polished map).
  double shaping_tolerance_um = 1e-3;
  // Compute the removal products as FFT convolutions when every dwell point lies on a node of the
  // target map's grid (removal_fft.h): the same products, far faster on large maps. false: always
  // the sparse matrix, the reference the FFT products are tested against.
  bool fft_products = true;
  // With FFT products: start from an inverse filter of the target (RIFTA-style, removal_fft.h
  // FftRemoval::InverseFilter) when it fits better than the correlation start, and take the step
  // from the kernel's spectrum (an exact bound of the gradient's Lipschitz constant) instead of 50
  // power iterations. The stall test keeps the correlation start's residual as its reference.
  // false: the correlation start and power iteration of the sparse path, the same iteration as
  // the sparse reference (to rounding).
  bool inverse_filter_start = true;
  // Empty when valid, else one line per violation with its value, named by the job key
  // ("machine.max_speed_mm_s = -3 violates > 0"). least_dwell_s is checked against the path by
  // SolveDwell.
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct DwellSolution {
  std::vector<double> dwell_s;     // one per path point
  std::vector<double> speed_mm_s;  // TCP speed into each point (the first: max speed, no dwell)
  std::vector<double> chord_mm;    // length of the TCP chord ending at each point (first: 0)
  ErrorMap predicted_removal_um;   // over the aperture nodes; NaN elsewhere
  ErrorMap residual_um;            // target - removal over the aperture; NaN elsewhere
  MapStatistics before;            // of the target (= the error) in the aperture
  MapStatistics after;             // of the residual in the aperture
  double total_time_s = 0.0;
  double max_acceleration_mm_s2 = 0.0;  // largest acceleration the speeds imply (see DwellOptions)
  int iterations = 0;                   // projected-gradient iterations, all rounds
  int shaping_rounds = 0;               // re-solves after shaping the speeds (0: none needed)
  bool converged = false;
  long nonzeros = 0;          // entries of the removal matrix (rate > 0), whichever way its products ran
  bool fft_products = false;  // the products ran as FFT convolutions (DwellOptions::fft_products)
};

// Solves the dwell for a removal target (RemovalTarget) along a path whose contact points are
// `path_xy_mm` (where the removal function is centred) and whose TCP moves into each point are
// straight chords of `chord_mm` (one per point, >= 0 and finite; chord_mm[0] = 0, the approach):
// dwell_s[k] * speed_mm_s[k] = chord_mm[k] wherever the speed is below the maximum.
// Throws Error{kInvalidOption, "polishing.dwell"} for options out of range (a Gaussian's too) or
// speeds that cannot be met (min > max, a least_dwell_s above the point's longest dwell);
// Error{kBadInput, "polishing.removal"} for a malformed table; Error{kBadInput,
// "polishing.dwell"} for an empty aperture, when running
// the path at the maximum speed (or the least dwell) already removes more than the target
// somewhere (naming the point and the uniform layer that would make it reachable), or when the
// speeds shaped to the maximum acceleration do not settle within max_shaping_rounds (naming the
// point that still needed shaping).
[[nodiscard]] DwellSolution SolveDwell(const ErrorMap& target, const surfaces::Aperture& aperture,
                                       std::span<const Eigen::Vector2d> path_xy_mm,
                                       std::span<const double> chord_mm, const RemovalFunction& removal,
                                       const DwellOptions& options);

// The same for a path that the TCP runs in the plane of its contact points (a flat part without
// precession): the chords are the (x, y) steps between the points.
[[nodiscard]] DwellSolution SolveDwell(const ErrorMap& target, const surfaces::Aperture& aperture,
                                       std::span<const Eigen::Vector2d> path_xy_mm,
                                       const RemovalFunction& removal, const DwellOptions& options);

// The removal (um) of `dwell_s` (s) at the contact points `contact_xy_mm` over the aperture nodes
// of `like` (NaN elsewhere): the products SolveDwell predicts with (FFT convolutions when the
// points lie on the map's grid, else the sparse matrix), for a path the robot runs as written.
[[nodiscard]] ErrorMap RemovalOfDwell(const ErrorMap& like, const surfaces::Aperture& aperture,
                                      std::span<const Eigen::Vector2d> contact_xy_mm,
                                      std::span<const double> dwell_s, const RemovalFunction& removal);

// The (x, y) steps between consecutive points (first: 0): the chords of a path in a plane.
[[nodiscard]] std::vector<double> PlanarChordsMm(std::span<const Eigen::Vector2d> path_xy_mm);

}  // namespace arcwheel::polishing
