#include "surfaces/surface.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.h"

namespace arcwheel::surfaces {
namespace {

using ::testing::HasSubstr;

// Sag of a conic in its other algebraic form, (1 - sqrt(1 - (1+k) c^2 r^2)) / ((1+k) c), k != -1.
double ConicSagOtherForm(double r2, double radius, double conic) {
  const double c = 1.0 / radius, kk = 1.0 + conic;
  return (1.0 - std::sqrt(1.0 - kk * c * c * r2)) / (kk * c);
}

// Central differences of the surface's own heights and slopes (independent of the closed forms).
void ExpectDerivativesMatchFiniteDifferences(const Surface& s, double x, double y, double tol1, double tol2) {
  const double h = 1e-3;
  const SurfacePoint p = s.Evaluate(x, y);
  const double fx = (s.Evaluate(x + h, y).z_mm - s.Evaluate(x - h, y).z_mm) / (2 * h);
  const double fy = (s.Evaluate(x, y + h).z_mm - s.Evaluate(x, y - h).z_mm) / (2 * h);
  const double fxx = (s.Evaluate(x + h, y).fx - s.Evaluate(x - h, y).fx) / (2 * h);
  const double fxy = (s.Evaluate(x, y + h).fx - s.Evaluate(x, y - h).fx) / (2 * h);
  const double fyx = (s.Evaluate(x + h, y).fy - s.Evaluate(x - h, y).fy) / (2 * h);
  const double fyy = (s.Evaluate(x, y + h).fy - s.Evaluate(x, y - h).fy) / (2 * h);
  EXPECT_NEAR(p.fx, fx, tol1) << "at " << x << ", " << y;
  EXPECT_NEAR(p.fy, fy, tol1) << "at " << x << ", " << y;
  EXPECT_NEAR(p.fxx_per_mm, fxx, tol2) << "at " << x << ", " << y;
  EXPECT_NEAR(p.fxy_per_mm, fxy, tol2) << "at " << x << ", " << y;
  EXPECT_NEAR(p.fxy_per_mm, fyx, tol2) << "at " << x << ", " << y;
  EXPECT_NEAR(p.fyy_per_mm, fyy, tol2) << "at " << x << ", " << y;
}

TEST(EvenAsphere, SphereOnAxisIsTheCircleSag) {
  const EvenAsphere sphere({.vertex_radius_mm = 1000.0, .conic = 0.0});
  for (double r : {0.0, 10.0, 150.0, 400.0}) {
    const double x = r * 0.6, y = r * 0.8;
    EXPECT_NEAR(sphere.Evaluate(x, y).z_mm, 1000.0 - std::sqrt(1000.0 * 1000.0 - r * r), 1e-12);
    // Slope of a circle: r / sqrt(R^2 - r^2), along the radius.
    const double slope = r / std::sqrt(1000.0 * 1000.0 - r * r);
    EXPECT_NEAR(std::hypot(sphere.Evaluate(x, y).fx, sphere.Evaluate(x, y).fy), slope, 1e-14);
  }
  EXPECT_NEAR(sphere.Evaluate(0, 0).fxx_per_mm, 1e-3, 1e-18);
}

TEST(EvenAsphere, ParaboloidIsExactlyQuadratic) {
  const EvenAsphere paraboloid({.vertex_radius_mm = 500.0, .conic = -1.0});
  for (double x : {-300.0, 0.0, 120.0}) {
    for (double y : {-50.0, 250.0}) {
      const SurfacePoint p = paraboloid.Evaluate(x, y);
      EXPECT_NEAR(p.z_mm, (x * x + y * y) / 1000.0, 1e-12);
      EXPECT_NEAR(p.fxx_per_mm, 2e-3, 1e-16);
      EXPECT_NEAR(p.fxy_per_mm, 0.0, 1e-16);
    }
  }
}

TEST(EvenAsphere, OffAxisSegmentIsTheParentSagShiftedToItsOrigin) {
  const double radius = 800.0, conic = -2.2, x0 = 300.0, y0 = -40.0;
  const EvenAsphere part(
      {.vertex_radius_mm = radius, .conic = conic, .off_axis_x_mm = x0, .off_axis_y_mm = y0});
  EXPECT_NEAR(part.Evaluate(0, 0).z_mm, 0.0, 1e-13);
  const double origin = ConicSagOtherForm(x0 * x0 + y0 * y0, radius, conic);
  for (double x : {-100.0, 35.0, 100.0}) {
    for (double y : {-100.0, 0.0, 80.0}) {
      const double r2 = (x + x0) * (x + x0) + (y + y0) * (y + y0);
      EXPECT_NEAR(part.Evaluate(x, y).z_mm, ConicSagOtherForm(r2, radius, conic) - origin, 1e-10);
    }
  }
}

TEST(EvenAsphere, ConvexIsTheMirrorOfConcave) {
  EvenAsphereParameters p{.vertex_radius_mm = 600.0, .conic = -0.5, .off_axis_x_mm = 100.0};
  const EvenAsphere concave(p);
  p.concave = false;
  const EvenAsphere convex(p);
  const SurfacePoint a = concave.Evaluate(40.0, -70.0), b = convex.Evaluate(40.0, -70.0);
  EXPECT_DOUBLE_EQ(a.z_mm, -b.z_mm);
  EXPECT_DOUBLE_EQ(a.fx, -b.fx);
  EXPECT_DOUBLE_EQ(a.fyy_per_mm, -b.fyy_per_mm);
}

TEST(EvenAsphere, PolynomialTermsAddPowersOfRadius) {
  const EvenAsphere base({.vertex_radius_mm = 2000.0, .conic = -0.7});
  const EvenAsphere with_terms({.vertex_radius_mm = 2000.0,
                                .conic = -0.7,
                                .even_coefficients = {1e-10, -2e-16, 0, 0, 0, 0, 0, 0, 3e-50}});
  for (double r : {50.0, 200.0}) {
    const double expected = 1e-10 * std::pow(r, 4) - 2e-16 * std::pow(r, 6) + 3e-50 * std::pow(r, 20);
    EXPECT_NEAR(with_terms.Evaluate(r, 0).z_mm - base.Evaluate(r, 0).z_mm, expected, 1e-12);
  }
}

TEST(EvenAsphere, DerivativesMatchFiniteDifferences) {
  std::mt19937 rng(20261123);
  std::uniform_real_distribution<double> where(-200.0, 200.0);
  const EvenAsphere part({.vertex_radius_mm = 800.0,
                          .conic = -2.2,
                          .even_coefficients = {3e-11, -1e-16},
                          .off_axis_x_mm = 300.0,
                          .off_axis_y_mm = 150.0,
                          .concave = false});
  // FD error: h^2 f''' / 6 ~ 1e-12 plus rounding 1e-16 * |z| / h ~ 1e-11.
  for (int k = 0; k < 50; ++k)
    ExpectDerivativesMatchFiniteDifferences(part, where(rng), where(rng), 1e-9, 1e-9);
}

TEST(EvenAsphere, ProlateEllipsoidEndsAndApertureBeyondIsRefusedNamingThePoint) {
  // k = 0 sphere of radius 100: defined for r < 100.
  const EvenAsphere ball({.vertex_radius_mm = 100.0, .conic = 0.0});
  EXPECT_TRUE(ball.InDomain(99.0, 0.0));
  EXPECT_FALSE(ball.InDomain(100.0, 1.0));
  const Aperture too_big{.shape = Aperture::Shape::kRectangle, .width_x_mm = 180.0, .width_y_mm = 180.0};
  try {
    CheckApertureInDomain(ball, too_big, 0.0, 0.0);
    FAIL() << "expected a refusal";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_THAT(e.what(), HasSubstr("point ("));
    EXPECT_THAT(e.what(), HasSubstr("outside the surface's domain"));
  }
  const Aperture fits{.shape = Aperture::Shape::kCircle, .diameter_mm = 190.0};
  EXPECT_NO_THROW(CheckApertureInDomain(ball, fits, 0.0, 0.0));
  EXPECT_THROW(EvenAsphere({.vertex_radius_mm = 0.0}), Error);
}

TEST(XyPolynomial, MatchesClosedFormAndItsDerivatives) {
  // z = 0.5 + 2e-4 x^2 y - 3e-6 y^3
  const XyPolynomial s({{0, 0, 0.5}, {2, 1, 2e-4}, {0, 3, -3e-6}});
  const double x = 13.0, y = -7.0;
  const SurfacePoint p = s.Evaluate(x, y);
  EXPECT_NEAR(p.z_mm, 0.5 + 2e-4 * x * x * y - 3e-6 * y * y * y, 1e-15);
  EXPECT_NEAR(p.fx, 4e-4 * x * y, 1e-15);
  EXPECT_NEAR(p.fy, 2e-4 * x * x - 9e-6 * y * y, 1e-15);
  EXPECT_NEAR(p.fxx_per_mm, 4e-4 * y, 1e-15);
  EXPECT_NEAR(p.fxy_per_mm, 4e-4 * x, 1e-15);
  EXPECT_NEAR(p.fyy_per_mm, -18e-6 * y, 1e-15);
  EXPECT_THROW(XyPolynomial({{-1, 0, 1.0}}), Error);
}

// A cubic in x times a cubic in y (plus lower terms): the spline must reproduce it exactly.
double Bicubic(double x, double y) {
  return 0.1 + 1e-3 * x - 2e-3 * y + 1e-4 * x * x * y - 2e-6 * x * x * x + 3e-7 * x * x * x * y * y * y +
         5e-6 * y * y * y;
}

TEST(HeightGrid, ReproducesABicubicPolynomialWithItsDerivatives) {
  HeightGridParameters g{
      .grid = {.x0_mm = -20.0, .y0_mm = -15.0, .dx_mm = 2.5, .dy_mm = 3.0, .nx = 17, .ny = 11}};
  for (int j = 0; j < g.grid.ny; ++j) {
    for (int i = 0; i < g.grid.nx; ++i)
      g.heights_mm.push_back(Bicubic(g.grid.x0_mm + i * g.grid.dx_mm, g.grid.y0_mm + j * g.grid.dy_mm));
  }
  const HeightGrid grid(g);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> ux(-20.0, 20.0), uy(-15.0, 15.0);
  for (int k = 0; k < 200; ++k) {
    const double x = ux(rng), y = uy(rng), h = 1e-5;
    const SurfacePoint p = grid.Evaluate(x, y);
    EXPECT_NEAR(p.z_mm, Bicubic(x, y), 1e-12);
    // Derivatives of the polynomial by central differences: exact up to rounding for a cubic.
    EXPECT_NEAR(p.fx, (Bicubic(x + h, y) - Bicubic(x - h, y)) / (2 * h), 1e-8);
    EXPECT_NEAR(p.fy, (Bicubic(x, y + h) - Bicubic(x, y - h)) / (2 * h), 1e-8);
  }
  ExpectDerivativesMatchFiniteDifferences(grid, 3.3, -4.4, 1e-8, 1e-7);
  EXPECT_TRUE(grid.InDomain(20.0, 15.0));
  EXPECT_FALSE(grid.InDomain(20.01, 0.0));
}

TEST(HeightGrid, InterpolatesASmoothSurfaceToSplineAccuracy) {
  // A sphere of radius 500 sampled every 5 mm: the cubic spline's error is of order
  // 5/384 h^4 max|f''''| (up to the clamped ends), with f'''' ~ 3 / R^3 growing to ~1e-7 / mm^3
  // at r = 140 mm: about 1e-6 mm.
  HeightGridParameters g{
      .grid = {.x0_mm = -100.0, .y0_mm = -100.0, .dx_mm = 5.0, .dy_mm = 5.0, .nx = 41, .ny = 41}};
  const EvenAsphere sphere({.vertex_radius_mm = 500.0, .conic = 0.0});
  for (int j = 0; j < g.grid.ny; ++j) {
    for (int i = 0; i < g.grid.nx; ++i)
      g.heights_mm.push_back(sphere.Evaluate(-100 + 5.0 * i, -100 + 5.0 * j).z_mm);
  }
  const HeightGrid grid(g);
  for (double x : {-97.3, -12.1, 0.0, 44.4, 99.0}) {
    for (double y : {-88.8, 2.5, 71.7}) {
      EXPECT_NEAR(grid.Evaluate(x, y).z_mm, sphere.Evaluate(x, y).z_mm, 2e-6);
      EXPECT_NEAR(grid.Evaluate(x, y).fxx_per_mm, sphere.Evaluate(x, y).fxx_per_mm, 1e-5);
    }
  }
}

TEST(HeightGrid, RefusesTooFewNodesAndSizeMismatch) {
  HeightGridParameters g{.grid = {.dx_mm = 1.0, .dy_mm = 1.0, .nx = 3, .ny = 5},
                         .heights_mm = std::vector<double>(15, 0.0)};
  EXPECT_THROW(HeightGrid{g}, Error);
  g.grid.nx = 4;
  try {
    HeightGrid grid(g);
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("15 heights, 4 x 5 = 20 expected"));
  }
}

TEST(Aperture, ChordsAndContainment) {
  const Aperture circle{.shape = Aperture::Shape::kCircle, .diameter_mm = 100.0};
  EXPECT_DOUBLE_EQ(circle.HalfChordAt(30.0), 40.0);
  EXPECT_DOUBLE_EQ(circle.HalfChordAt(60.0), 0.0);
  EXPECT_TRUE(circle.Contains(30.0, 40.0));
  EXPECT_FALSE(circle.Contains(30.0, 40.1));
  const Aperture rect{.width_x_mm = 430.0, .width_y_mm = 200.0};
  EXPECT_DOUBLE_EQ(rect.HalfChordAt(99.0), 215.0);
  EXPECT_DOUBLE_EQ(rect.HalfChordAt(100.0 + 1e-12), 215.0);
  EXPECT_FALSE(rect.Contains(0.0, 100.5));
}

}  // namespace
}  // namespace arcwheel::surfaces
