#include "grinding/prediction.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <limits>
#include <memory>
#include <numbers>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/testing/testing.h"

namespace arcwheel::grinding {

using surfaces::Aperture;
using surfaces::EvenAsphere;
using surfaces::Surface;
using surfaces::SurfacePoint;
using surfaces::XyPolynomial;

namespace {

Wheel PaperWheel() {  // fig. 7: Ra = 50 mm on a 400 mm wheel
  return Wheel{.arc_radius_mm = 50.0, .base_radius_mm = 150.0, .half_width_mm = 10.0};
}

EvenAsphere Fig7Asphere(bool concave = true) {
  return EvenAsphere({.vertex_radius_mm = 800.0, .conic = -2.2, .off_axis_x_mm = 300.0, .concave = concave});
}

// Written here from method.md eq. 5, independent of the library.
Eigen::Vector3d WheelCentre(const Surface& s, const Wheel& w, double x, double y) {
  const SurfacePoint p = s.Evaluate(x, y);
  const double n3 = std::sqrt(p.fx * p.fx + p.fy * p.fy + 1), n2 = std::sqrt(p.fx * p.fx + 1);
  return {x - w.arc_radius_mm * p.fx / n3 - w.base_radius_mm * p.fx / n2, y - w.arc_radius_mm * p.fy / n3,
          p.z_mm + w.arc_radius_mm / n3 + w.base_radius_mm / n2};
}

// Lowest point over (x, y) of a torus wheel (arc ra, base rb) centred at c.
double Bottom(double ra, double rb, const Eigen::Vector3d& c, double x, double y) {
  const double t = y - c.y();
  if (std::abs(t) >= ra) return std::numeric_limits<double>::infinity();
  const double rim = rb + std::sqrt(ra * ra - t * t);
  const double a = x - c.x();
  if (std::abs(a) >= rim) return std::numeric_limits<double>::infinity();
  return c.z() - std::sqrt(rim * rim - a * a);
}

// Envelope of the real wheel (Ra + d, Rb - d) over the nominal path, by brute force: the lowest
// real-wheel bottom over (x, y) among wheel poses for contacts on ever finer grids around (x, y).
double BruteForceGroundZ(const Surface& s, const Wheel& nominal, double d_ra, double x, double y) {
  double best = std::numeric_limits<double>::infinity(), bx = x, by = y;
  for (double step : {0.05, 0.002, 0.0001}) {
    const double cx = bx, cy = by;
    for (int i = -30; i <= 30; ++i) {
      for (int j = -30; j <= 30; ++j) {
        const double px = cx + i * step, py = cy + j * step;
        const double z = Bottom(nominal.arc_radius_mm + d_ra, nominal.base_radius_mm - d_ra,
                                WheelCentre(s, nominal, px, py), x, y);
        if (z < best) {
          best = z;
          bx = px;
          by = py;
        }
      }
    }
  }
  return best;
}

double MaxAbs(const std::vector<double>& v) {
  double m = 0.0;
  for (double e : v) {
    if (std::isfinite(e)) m = std::max(m, std::abs(e));
  }
  return m;
}

TEST(PredictFormError, ZeroWheelErrorLeavesTheSurfaceWithinOneNanometre) {
  const Aperture square{.width_x_mm = 200.0, .width_y_mm = 200.0};
  const EvenAsphere concave_off = Fig7Asphere(true), convex_off = Fig7Asphere(false);
  const EvenAsphere concave_on({.vertex_radius_mm = 800.0, .conic = -2.2});
  const EvenAsphere convex_on({.vertex_radius_mm = 800.0, .conic = -2.2, .concave = false});
  for (const Surface* s : std::vector<const Surface*>{&concave_off, &convex_off, &concave_on, &convex_on}) {
    const FormPrediction p = PredictFormError(*s, square, PaperWheel(), {.nodes_x = 41, .nodes_y = 41});
    EXPECT_LT(MaxAbs(p.error_um), 1e-3) << s->Describe();
    EXPECT_LT(p.pv_um, 1e-3);
    // And independently: the nominal wheel's envelope over the nominal path is the surface.
    for (double x : {-80.0, 0.0, 90.0}) {
      for (double y : {-70.0, 60.0}) {
        EXPECT_NEAR(BruteForceGroundZ(*s, PaperWheel(), 0.0, x, y), s->Evaluate(x, y).z_mm, 1e-6)
            << s->Describe() << " at " << x << ", " << y;
      }
    }
  }
}

TEST(PredictFormError, ArcRadiusErrorMatchesTheBruteForceEnvelope) {
  const Aperture square{.width_x_mm = 200.0, .width_y_mm = 200.0};
  const EvenAsphere concave = Fig7Asphere(true), convex = Fig7Asphere(false);
  for (const Surface* s : std::vector<const Surface*>{&concave, &convex}) {
    for (double d_ra : {0.2, -0.1}) {
      const FormPrediction p = PredictFormError(*s, square, PaperWheel(),
                                                {.arc_radius_error_mm = d_ra, .nodes_x = 5, .nodes_y = 5});
      for (size_t j : {0u, 1u, 4u}) {
        for (size_t i : {0u, 2u, 3u}) {
          const double x = p.x_mm[i], y = p.y_mm[j];
          const double brute_um =
              1e3 * (BruteForceGroundZ(*s, PaperWheel(), d_ra, x, y) - s->Evaluate(x, y).z_mm);
          EXPECT_NEAR(p.error_um[j * 5 + i], brute_um, 1e-3) << s->Describe() << " dRa " << d_ra;
        }
      }
    }
  }
}

TEST(PredictFormError, Fig7ErrorGrowsLinearlyWithTheRadiusErrorAsFyToTheSecond) {
  // Paper fig. 7: R0 = 800 mm, k = -2.2, 300 mm off axis (here along x), Ra = 50 mm.
  const Aperture square{.width_x_mm = 200.0, .width_y_mm = 200.0};
  const EvenAsphere part = Fig7Asphere();
  std::vector<double> pv;
  for (double d_ra : {0.05, 0.1, 0.2}) {
    const FormPrediction p = PredictFormError(part, square, PaperWheel(),
                                              {.arc_radius_error_mm = d_ra, .nodes_x = 21, .nodes_y = 21});
    pv.push_back(p.pv_um);
    std::printf("fig. 7 part: dRa = %.2f mm -> PV %.3f um, RMS %.3f um (%.3f / %.3f um after tilt)\n", d_ra,
                p.pv_um, p.rms_um, p.pv_after_tilt_um, p.rms_after_tilt_um);
    for (size_t k = 0; k < p.error_um.size(); ++k) {
      const double x = p.x_mm[k % 21], y = p.y_mm[k / 21];
      const SurfacePoint s = part.Evaluate(x, y);
      // First order: a normal error dRa (N2/N3 - 1), i.e. a height error dRa (N2 - N3).
      const double first_order_um =
          1e3 * d_ra * (std::sqrt(1 + s.fx * s.fx) - std::sqrt(1 + s.fx * s.fx + s.fy * s.fy));
      EXPECT_NEAR(p.error_um[k], first_order_um, 0.02 * std::abs(first_order_um) + 1e-3);
    }
  }
  EXPECT_NEAR(pv[1] / pv[0], 2.0, 0.02);
  EXPECT_NEAR(pv[2] / pv[1], 2.0, 0.02);
  // Cylinder: on the x axis (fy = 0) nothing; it grows with y^2 across the part.
  const FormPrediction p = PredictFormError(part, square, PaperWheel(),
                                            {.arc_radius_error_mm = 0.1, .nodes_x = 21, .nodes_y = 21});
  EXPECT_LT(std::abs(p.error_um[10 * 21 + 3]), 1e-3);
  EXPECT_LT(p.error_um[20 * 21 + 10], -0.1);
  // Keeping the base radius instead (the total radius errs too) offsets the surface along its
  // normal by exactly -dRa: a height error of -dRa N3.
  const FormPrediction offset = PredictFormError(
      part, square, PaperWheel(),
      {.arc_radius_error_mm = 0.1, .keep_total_radius = false, .nodes_x = 21, .nodes_y = 21});
  for (size_t k = 0; k < offset.error_um.size(); k += 5) {
    const SurfacePoint s = part.Evaluate(offset.x_mm[k % 21], offset.y_mm[k / 21]);
    EXPECT_NEAR(offset.error_um[k] / std::sqrt(1 + s.fx * s.fx + s.fy * s.fy), -100.0, 0.05);
  }
}

TEST(PredictFormError, RunoutRippleMatchesTheBruteForceEnvelopeAlongTheFeed) {
  // A flat part, an eccentric wheel with 2 um TIR, 1432 rpm, 6000 mm/min: 4.19 mm per turn.
  const XyPolynomial flat({});
  const Aperture strip{.width_x_mm = 40.0, .width_y_mm = 2.0};
  PredictionOptions o{.spindle_rpm = 1432.0, .feed_mm_per_min = 6000.0, .nodes_x = 401, .nodes_y = 3};
  SetEccentricRunout(2.0, o);
  const FormPrediction p = PredictFormError(flat, strip, PaperWheel(), o);
  const double per_turn = 6000.0 / 1432.0, radius = 200.0;
  for (size_t i = 0; i < p.x_mm.size(); i += 7) {
    const double x = p.x_mm[i];
    double lowest = std::numeric_limits<double>::infinity();
    for (double s = x - 3.0; s <= x + 3.0; s += per_turn / 4000.0) {
      const double rim = radius + 1e-3 * std::cos(2.0 * std::numbers::pi * s / per_turn);
      lowest = std::min(lowest, radius - std::sqrt(rim * rim - (x - s) * (x - s)));
    }
    EXPECT_NEAR(p.error_um[1 * 401 + i], 1e3 * lowest, 2e-3) << "x = " << x;
  }
  // The feed per turn is long against the runout (its scallop 4.19^2 / 1600 = 11 um): the ripple
  // is close to the full runout.
  EXPECT_GT(p.ripple_pv_um, 1.6);
  EXPECT_LE(p.ripple_pv_um, 2.0 + 1e-9);
}

TEST(PredictFormError, RefusesInvalidOptions) {
  PredictionOptions o{.nodes_x = 1};
  EXPECT_THROW((void)PredictFormError(Fig7Asphere(), {.width_x_mm = 10, .width_y_mm = 10}, PaperWheel(), o),
               Error);
  o = {.runout_phase_deg = {0.0}, .runout_radial_um = {1.0}};
  try {
    (void)PredictFormError(Fig7Asphere(), {.width_x_mm = 10, .width_y_mm = 10}, PaperWheel(), o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), ::testing::HasSubstr("prediction.spindle_rpm"));
  }
}

TEST(WritePredictionHdf5, WritesTheMapAndItsFigures) {
  const testing::TempDir dir;
  const FormPrediction p =
      PredictFormError(Fig7Asphere(), {.width_x_mm = 100, .width_y_mm = 60}, PaperWheel(),
                       {.arc_radius_error_mm = 0.1, .nodes_x = 11, .nodes_y = 7});
  WritePredictionHdf5(p, dir / "prediction.h5", "surface", "wheel");
  const hdf5::File file = hdf5::File::OpenReadOnly(dir / "prediction.h5");
  EXPECT_EQ(file.Shape("/error_um"), (std::vector<hsize_t>{7, 11}));
  EXPECT_EQ(file.ReadDoubles("/error_um"), p.error_um);
  EXPECT_DOUBLE_EQ(*file.ReadAttributeDouble("/", "pv_um"), p.pv_um);
  // The grid attributes place node (i, j) where the prediction computed it.
  const double x0 = *file.ReadAttributeDouble("/", "x0_mm"), dx = *file.ReadAttributeDouble("/", "dx_mm");
  const double y0 = *file.ReadAttributeDouble("/", "y0_mm"), dy = *file.ReadAttributeDouble("/", "dy_mm");
  for (size_t i = 0; i < p.x_mm.size(); ++i) EXPECT_NEAR(x0 + static_cast<double>(i) * dx, p.x_mm[i], 1e-12);
  for (size_t j = 0; j < p.y_mm.size(); ++j) EXPECT_NEAR(y0 + static_cast<double>(j) * dy, p.y_mm[j], 1e-12);
  EXPECT_EQ(*file.ReadAttributeString("/", "schema_version"), "1.0");
  EXPECT_EQ(*file.ReadAttributeString("/", "wheel"), "wheel");
}

}  // namespace
}  // namespace arcwheel::grinding
