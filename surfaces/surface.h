#pragma once
// Surfaces to grind and polish, as heights z = f(x, y) in the part's local frame (mm), with exact first and
// second derivatives. The part lies below the surface (z decreases into the material); the wheel
// comes from above, so the unit upward normal is n = (-fx, -fy, 1) / sqrt(fx^2 + fy^2 + 1).
//
// Three kinds:
//  - EvenAsphere: an even asphere about a parent axis (vertex radius, conic, A4..A20), optionally an
//    off-axis segment whose local origin sits at (x0, y0) in the parent frame; concave or convex.
//  - XyPolynomial: a freeform z = sum c_ij x^i y^j.
//  - HeightGrid: heights on a regular grid, interpolated by a C2 bicubic spline.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "surfaces/grid_spec.h"

namespace arcwheel::surfaces {

// Height and derivatives of a surface at one (x, y).
struct SurfacePoint {
  double z_mm = 0.0;
  double fx = 0.0;          // dz/dx
  double fy = 0.0;          // dz/dy
  double fxx_per_mm = 0.0;  // d2z/dx2
  double fxy_per_mm = 0.0;  // d2z/dxdy
  double fyy_per_mm = 0.0;  // d2z/dy2
};

class Surface {
 public:
  virtual ~Surface() = default;
  // Height and exact derivatives at local (x, y). Precondition: InDomain(x, y).
  [[nodiscard]] virtual SurfacePoint Evaluate(double x_mm, double y_mm) const = 0;
  // True where the surface is defined (the asphere's sag is real; the grid covers the point).
  [[nodiscard]] virtual bool InDomain(double x_mm, double y_mm) const = 0;
  // One line naming the surface and its parameters, for file headers.
  [[nodiscard]] virtual std::string Describe() const = 0;
};

struct EvenAsphereParameters {
  // Vertex radius of curvature R0 (> 0). The vertex curvature is 1 / R0.
  double vertex_radius_mm = 0.0;
  // Conic constant k (0 sphere, -1 paraboloid, < -1 hyperboloid).
  double conic = 0.0;
  // A4, A6, ..., A20: coefficient of r^4, r^6, ..., r^20 (mm^(1-2i)). Missing terms are zero.
  std::vector<double> even_coefficients{};
  // Position of the local origin in the parent frame (off-axis distance in x and y).
  double off_axis_x_mm = 0.0;
  double off_axis_y_mm = 0.0;
  // Concave: the surface rises away from the parent axis (z = +sag); convex: z = -sag.
  bool concave = true;
};

// Even asphere: sag(r) = c r^2 / (1 + sqrt(1 - (1 + k) c^2 r^2)) + sum_i A_2i r^2i, c = 1 / R0,
// r^2 = (x + x0)^2 + (y + y0)^2. The local height is z = s (sag(x, y) - sag(0, 0)) with s = +1
// for concave and -1 for convex, so that the local origin lies at z = 0.
class EvenAsphere final : public Surface {
 public:
  // Throws Error{kBadInput, "grinding.surface"} for R0 <= 0, more than 9 coefficients, or an
  // off-axis origin outside the sag's domain.
  explicit EvenAsphere(const EvenAsphereParameters& parameters);
  [[nodiscard]] SurfacePoint Evaluate(double x_mm, double y_mm) const override;
  [[nodiscard]] bool InDomain(double x_mm, double y_mm) const override;
  [[nodiscard]] std::string Describe() const override;
  [[nodiscard]] const EvenAsphereParameters& parameters() const { return parameters_; }
  // Parent-axis sag and its first two derivatives with respect to u = r^2.
  struct SagOfU {
    double sag_mm, dsag_du, d2sag_du2;
  };
  [[nodiscard]] SagOfU SagOfRadiusSquared(double u_mm2) const;

 private:
  EvenAsphereParameters parameters_;
  double curvature_per_mm_;
  double sag_at_origin_mm_;
  double sign_;
};

struct XyPolynomialTerm {
  int x_power = 0;
  int y_power = 0;
  double coefficient = 0.0;  // mm^(1 - x_power - y_power)
};

// Freeform z = sum c_ij x^i y^j in local coordinates; defined everywhere.
class XyPolynomial final : public Surface {
 public:
  // Throws Error{kBadInput} for negative powers or powers above 20.
  explicit XyPolynomial(std::vector<XyPolynomialTerm> terms);
  [[nodiscard]] SurfacePoint Evaluate(double x_mm, double y_mm) const override;
  [[nodiscard]] bool InDomain(double, double) const override { return true; }
  [[nodiscard]] std::string Describe() const override;

 private:
  std::vector<XyPolynomialTerm> terms_;
  int max_x_power_ = 0;
  int max_y_power_ = 0;
};

// Heights on a regular grid: heights_mm[grid.Index(i, j)] is z at (grid.X(i), grid.Y(j)).
struct HeightGridParameters {
  GridSpec grid{};
  std::vector<double> heights_mm{};
};

// Tensor-product cubic spline through the grid heights: C2, exact for any surface that is a cubic
// in x times a cubic in y (end slopes come from the cubic through the 4 end nodes). Between nodes
// each cell is a bicubic Hermite patch on the spline's values, slopes and cross slopes.
class HeightGrid final : public Surface {
 public:
  // Throws Error{kBadInput} for fewer than 4 x 4 nodes, non-positive spacing, a size mismatch or a
  // non-finite height.
  explicit HeightGrid(HeightGridParameters parameters);
  [[nodiscard]] SurfacePoint Evaluate(double x_mm, double y_mm) const override;
  [[nodiscard]] bool InDomain(double x_mm, double y_mm) const override;
  [[nodiscard]] std::string Describe() const override;

 private:
  HeightGridParameters p_;
  std::vector<double> slope_x_;   // dz/dx at the nodes
  std::vector<double> slope_y_;   // dz/dy at the nodes
  std::vector<double> slope_xy_;  // d2z/dxdy at the nodes
};

// The part of the surface to grind, centred on the local origin.
struct Aperture {
  enum class Shape { kRectangle, kCircle };
  Shape shape = Shape::kRectangle;
  double width_x_mm = 0.0;   // rectangle: full size along x
  double width_y_mm = 0.0;   // rectangle: full size along y
  double diameter_mm = 0.0;  // circle
  [[nodiscard]] double HalfX() const;
  [[nodiscard]] double HalfY() const;
  [[nodiscard]] bool Contains(double x_mm, double y_mm) const;
  // Half-length of the chord at y: 0 outside a circle; a rectangle's half width at any y.
  [[nodiscard]] double HalfChordAt(double y_mm) const;
  [[nodiscard]] std::string Describe() const;
};

// Checks that the surface is defined over the aperture grown by `margin_x_mm` / `margin_y_mm`.
// Throws Error{kBadInput, "grinding.surface"} naming the first point off the domain.
void CheckApertureInDomain(const Surface& surface, const Aperture& aperture, double margin_x_mm,
                           double margin_y_mm);

}  // namespace arcwheel::surfaces
