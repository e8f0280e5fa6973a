#pragma once
// Reference circles of a 2D profile (ISO 12181-2 associations): least squares, minimum zone
// (Chebyshev), maximum inscribed and minimum circumscribed, for full circles and arcs.
//
// Least squares: the geometric (orthogonal distance) circle, from the algebraic (Kasa) circle by
// Gauss-Newton steps on 3 x 3 normal equations. The minimum zone, maximum inscribed and minimum
// circumscribed circles are solved as the linear programmes they are about a centre (the radial
// distances change by -u_i . delta when the centre moves by delta), by a simplex method whose basis
// is the set of support points, relinearised until the centre stops moving; the last circle is
// then computed exactly through its support points and CERTIFIED by its optimality condition:
//   - minimum zone: four support points alternating outer, inner, outer, inner in angle about the
//     centre (a first-degree trigonometric polynomial has at most two zeros per turn, so no move
//     of the centre can narrow the zone), every point within the two circles;
//   - maximum inscribed / minimum circumscribed: three (or two) support points on the circle with
//     the centre inside their triangle (on their chord), every point outside / inside the circle.
// A result that misses its condition is not returned as a reference (status kNotCertified).
//
// On an arc whose points all lie within half a turn about the centre the inscribed circle grows
// without bound and the smallest enclosing circle is the one on the arc's chord: neither is a
// reference for the arc's form, and both are refused (status kNotDefined). Least squares and
// minimum zone are defined on arcs of any length.

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace arcwheel::characteristics {

enum class Association { kLeastSquares, kMinimumZone, kMaximumInscribed, kMinimumCircumscribed };

// "least-squares", "minimum-zone", "maximum-inscribed", "minimum-circumscribed": the spelling of
// the command line, the tolerance file and the outputs.
[[nodiscard]] std::string_view AssociationName(Association association);
// ISO 12181-2's abbreviations without the trailing "CI": "LS", "MZ", "MI", "MC".
[[nodiscard]] std::string_view AssociationAbbreviation(Association association);
// The association of a name as AssociationName spells it; nullopt for any other text.
[[nodiscard]] std::optional<Association> ParseAssociation(std::string_view name);
// Every name, for messages: "least-squares, minimum-zone, maximum-inscribed or minimum-circumscribed".
[[nodiscard]] std::string AssociationNames();

enum class AssociationStatus {
  kCertified,     // the circle meets its optimality condition (least squares: converged)
  kNotDefined,    // no such reference circle for these points (an arc within half a turn)
  kDegenerate,    // fewer than 3 distinct points, or all on one line
  kNotCertified,  // the solver stopped short of the optimality condition
};

struct AssociationOptions {
  Association association = Association::kLeastSquares;
  // Relinearisations of the minimum zone, inscribed and circumscribed problems, >= 1. Profiles
  // whose form error is small against their radius need two or three.
  int max_relinearisations = 30;
  // Empty when valid, else one line per violation: "max_relinearisations = 0 violates >= 1".
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct AssociatedCircle {
  Association association = Association::kLeastSquares;
  double center_x_mm = 0.0;
  double center_y_mm = 0.0;
  // The reference circle: least squares, inscribed or circumscribed; for the minimum zone the mean
  // circle (inner + outer) / 2, from which ISO 12181-1 takes RONp, RONv and RONq.
  double radius_mm = 0.0;
  // Smallest and largest distance of a point from the centre: for the minimum zone its inner and
  // outer circle, whose difference is the zone width.
  double radius_inner_mm = 0.0;
  double radius_outer_mm = 0.0;
  // Indices of the points on the reference circles (none for least squares): minimum zone four,
  // in angle order, alternately on the outer and inner circle; inscribed and circumscribed two or
  // three.
  std::vector<int> support_indices;
  // For each support point, whether it lies on the outer circle (minimum zone) or the reference.
  std::vector<bool> support_on_outer;
  int n = 0;
  AssociationStatus status = AssociationStatus::kNotCertified;
  std::string message = "AssociateCircle was not called.";
  [[nodiscard]] bool IsCertified() const { return status == AssociationStatus::kCertified; }
  [[nodiscard]] double zone_width_mm() const { return radius_outer_mm - radius_inner_mm; }
};

// Why x, y cannot carry a circle ("fewer than 3 distinct points", "all 12 points lie on one
// line"), or "" when they can. Collinear means every point within 1e-12 of the points' spread of
// the line through them.
[[nodiscard]] std::string CircleDataProblem(std::span<const double> x_mm, std::span<const double> y_mm);

// The reference circle of the points (x_i, y_i) by options.association. Pure; a result whatever
// the points (see status). Throws Error{kInvalidOption, "characteristics.association"} for invalid
// options and Error{kInternal} when x and y differ in length.
[[nodiscard]] AssociatedCircle AssociateCircle(std::span<const double> x_mm, std::span<const double> y_mm,
                                               const AssociationOptions& options);

}  // namespace arcwheel::characteristics
