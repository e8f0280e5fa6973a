#include "polishing/removal_target.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <limits>

#include "core/error.h"

namespace arcwheel::polishing {
namespace {

// The 460 mm focusing lens of method.md B: y^2 = 3522.35573 x - 0.16398 x^2 + 1.97121e-4 x^3
// - 6.87809e-6 x^4 + 2.37036e-7 x^5, x along the axis.
constexpr std::array<double, 6> kLens = {0.0, 3522.35573, -0.16398, 1.97121e-4, -6.87809e-6, 2.37036e-7};

// Independent sag: bisection on the polynomial over [0, 50] mm (the lens sag is below 16 mm).
double BisectedSagMm(double y_mm) {
  double lo = 0.0, hi = 50.0;
  for (int k = 0; k < 200; ++k) {
    const double mid = 0.5 * (lo + hi);
    double v = 0.0, power = 1.0;
    for (const double c : kLens) {
      v += c * power;
      power *= mid;
    }
    (v > y_mm * y_mm ? hi : lo) = mid;
  }
  return lo;
}

TEST(PolynomialProfileSag, MatchesBisectionAcrossTheLens) {
  for (double y = -230.0; y <= 230.0; y += 7.5) {
    EXPECT_NEAR(PolynomialProfileSagMm(kLens, y), BisectedSagMm(y), 1e-10) << "y = " << y;
  }
}

TEST(RemovalTarget, ClosestSphereOfTheLensNeeds14Point2Micrometres) {
  // Error of a 1767.657 mm sphere tangent at the vertex against the asphere, on a 2D grid of the
  // 460 mm aperture (rotational symmetry: radius r = sqrt(x^2 + y^2)).
  const surfaces::Aperture aperture{.shape = surfaces::Aperture::Shape::kCircle, .diameter_mm = 460.0};
  ErrorMap error{
      .grid = {.x0_mm = -230.0, .y0_mm = -230.0, .dx_mm = 2.5, .dy_mm = 2.5, .nx = 185, .ny = 185}};
  for (int j = 0; j < error.grid.ny; ++j) {
    for (int i = 0; i < error.grid.nx; ++i) {
      const double r = std::hypot(error.grid.X(i), error.grid.Y(j));
      error.error_um.push_back(r <= 230.0
                                   ? 1e3 * (SphereSagMm(1767.657, r) - PolynomialProfileSagMm(kLens, r))
                                   : std::numeric_limits<double>::quiet_NaN());
    }
  }
  const ErrorMap target = RemovalTarget(error, aperture, {});
  const MapStatistics stats = StatisticsInAperture(target, aperture);
  EXPECT_NEAR(stats.pv_um, 14.2, 0.1);
  // The same figure from the independent profile, finely sampled along a radius.
  double deepest_um = 0.0;
  for (double r = 0.0; r <= 230.0; r += 0.25) {
    deepest_um = std::min(deepest_um, 1e3 * (SphereSagMm(1767.657, r) - BisectedSagMm(r)));
  }
  EXPECT_NEAR(-deepest_um, 14.2, 0.1);
  EXPECT_NEAR(stats.pv_um, -deepest_um, 0.01);  // the 2.5 mm grid misses the deepest ring by < 10 nm
  double lowest = std::numeric_limits<double>::infinity();
  for (const double v : target.error_um)
    if (std::isfinite(v)) lowest = std::min(lowest, v);
  EXPECT_EQ(lowest, 0.0);
}

TEST(RemovalTarget, AddsTheUniformLayerAndBlanksOutsideTheAperture) {
  const surfaces::Aperture aperture{
      .shape = surfaces::Aperture::Shape::kRectangle, .width_x_mm = 2.0, .width_y_mm = 2.0};
  const ErrorMap error{.grid = {.x0_mm = -2.0, .y0_mm = 0.0, .dx_mm = 1.0, .dy_mm = 1.0, .nx = 5, .ny = 1},
                       .error_um = {9.0, -1.0, 3.0, 2.0, -7.0}};
  const ErrorMap target = RemovalTarget(error, aperture, {.uniform_layer_um = 0.5});
  EXPECT_TRUE(std::isnan(target.error_um[0]));
  EXPECT_DOUBLE_EQ(target.error_um[1], 0.5);
  EXPECT_DOUBLE_EQ(target.error_um[2], 4.5);
  EXPECT_DOUBLE_EQ(target.error_um[3], 3.5);
  EXPECT_TRUE(std::isnan(target.error_um[4]));
}

TEST(RemovalTarget, RefusesAnEmptyAperture) {
  const surfaces::Aperture aperture{.shape = surfaces::Aperture::Shape::kCircle, .diameter_mm = 1.0};
  const ErrorMap error{.grid = {.x0_mm = 10.0, .y0_mm = 10.0, .nx = 2, .ny = 1}, .error_um = {1.0, 2.0}};
  try {
    (void)RemovalTarget(error, aperture, {});
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_NE(std::string(e.what()).find("empty aperture"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace arcwheel::polishing
