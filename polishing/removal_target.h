#pragma once
// Error maps and the removal target (issue 5 point 2, method.md B).
//
// An error map is the measured or predicted form error on a regular grid of the part frame's
// (x, y), in micrometres along the surface height (positive = material above the nominal surface,
// i.e. material to remove). Polishing only removes material, so the removal target is the error
// minus its minimum over the clear aperture, plus an optional uniform layer (which lets the tool
// run everywhere at a finite speed).

#include <span>
#include <string>
#include <vector>

#include "surfaces/grid_spec.h"
#include "surfaces/surface.h"

namespace arcwheel::polishing {

// error_um[grid.Index(i, j)] is the error at (grid.X(i), grid.Y(j)); NaN where there is no data.
struct ErrorMap {
  surfaces::GridSpec grid{};
  std::vector<double> error_um{};
  [[nodiscard]] double At(int i, int j) const { return error_um[grid.Index(i, j)]; }
};

// PV (max - min) and RMS about the mean of the finite values of a map inside the aperture.
struct MapStatistics {
  double pv_um = 0.0;
  double rms_um = 0.0;
  int nodes = 0;
};
[[nodiscard]] MapStatistics StatisticsInAperture(const ErrorMap& map, const surfaces::Aperture& aperture);

struct RemovalTargetOptions {
  // Uniform depth added to the whole aperture (um), >= 0.
  double uniform_layer_um = 0.0;
  // Empty when valid, else one line per violation naming the job key and the value, e.g.
  // "removal_target.uniform_layer_um = -1 violates >= 0".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

// Removal target: error - min(error over the aperture) + uniform layer inside the aperture, NaN
// outside it. Throws Error{kBadInput, "polishing.target"} if the aperture holds no finite node
// ("empty aperture"), Error{kInvalidOption} for a negative layer or a malformed grid.
[[nodiscard]] ErrorMap RemovalTarget(const ErrorMap& error, const surfaces::Aperture& aperture,
                                     const RemovalTargetOptions& options);

// The paper's trial profile (method.md B) is written as y^2 = sum_i c_i x^i with x along the
// axis (the sag) and y the radius. Returns the sag x at radius |y| (mm) by Newton's method from
// the vertex sphere, taking the branch through the vertex (c_0 = 0, c_1 > 0). Throws
// Error{kBadInput, "polishing.target"} if the profile has no such branch out to |y|.
[[nodiscard]] double PolynomialProfileSagMm(std::span<const double> coefficients, double y_mm);

// Sag of a sphere of radius R tangent at the vertex: R - sqrt(R^2 - y^2). Precondition: |y| < R.
[[nodiscard]] double SphereSagMm(double radius_mm, double y_mm);

}  // namespace arcwheel::polishing
