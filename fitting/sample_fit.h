#pragma once
// Per-phase arc fits from every valid sample (issue 29; method.md A.5, formats.md 3.1).
//
// Each phase node c_j owns the samples whose phase within the turn lies within half a node
// spacing of it. Its circle is the geometric least-squares circle of those of its samples that
// lie inside the band, each at its own axial position; a sample's small phase offset d from the
// node is taken into account by the local slope of the wheel along the phase, from the circles
// of the two neighbouring nodes: the sample is moved to the node as
//   rho - d * (S_{j+1}(y) - S_{j-1}(y)) / (2 * node spacing),   S_k(y) = b_k + sqrt(r_k^2 - (y - a_k)^2).
// One pass over the samples, in the order the scan holds them and on two workers, reduces them
// to runs: a node's samples on one turn, which lie within 1/360 of a pitch of each other along
// the axis, and stand in the fit as their centroid weighted by their count (the circle's residual
// is linear over a run to 1e-12 of itself). The fits are then a Kasa pass and Gauss-Newton
// passes over the runs; the band is centred on the mean arc centre of the pass before, and is
// read as the interval (docs/processing.md, step 6: each run weighs the band length it stands
// for, with a quadrature's weights at the band's edges).
//
// Each node's covariance is sigma^2 (J^T W J)^-1 (J^T W N^-1 W J) (J^T W J)^-1 at the solution,
// W the runs' weights, N their sample counts, sigma the per-sample noise (the nodes share no
// samples, so the mean's variance is the sum of theirs over n^2).
//
// The map for display and for runout and roundness comes from the same samples: rho(c_j, y_m)
// is the node's circle at y_m plus the mean residual (slope-corrected) of the node's samples
// within half an axial step of y_m, moved to y_m along the phases' mean residual profile (the runs
// lie up to half a pitch from y_m, by an amount that moves with the phase); NaN where there are
// none. `arc_error_um` is the
// peak-to-valley of the runs' residuals in the band (one point a turn, as a section's points).

#include <span>

#include "fitting/wheel_fit.h"
#include "processing/helix_geometry.h"
#include "processing/wheel_map.h"

namespace arcwheel::fitting {

// `rho_mm` per sample (NaN = invalid or despiked), in the order `geometry` addresses them.
// Sets the map's values (map.rho_mm, at the nodes that processing::PlanWheelMap laid out) to the
// sample-based map described above and their typical sigma (map.map_sigma_mm: the median over the
// cells with a value of sigma / sqrt(the cell's samples)), and returns the fits and every metric
// of WheelFit from them. Throws as FitWheel.
[[nodiscard]] WheelFit FitWheelToSamples(std::span<const double> rho_mm,
                                         const processing::HelixGeometry& geometry, processing::WheelMap& map,
                                         const WheelFitOptions& options);
[[nodiscard]] WheelFit FitWheelToSamples(std::span<const float> rho_mm,
                                         const processing::HelixGeometry& geometry, processing::WheelMap& map,
                                         const WheelFitOptions& options);

}  // namespace arcwheel::fitting
