#include "grinding/toolpath.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <random>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::grinding {

using surfaces::Aperture;
using surfaces::EvenAsphere;
using surfaces::EvenAsphereParameters;
using surfaces::Surface;
using surfaces::SurfacePoint;
using surfaces::XyPolynomial;
using surfaces::XyPolynomialTerm;

namespace {

using arcwheel::testing::ErrorMessageOf;
using arcwheel::testing::ErrorOf;
using ::testing::HasSubstr;

Wheel TestWheel() {
  return Wheel{
      .arc_radius_mm = 50.0, .base_radius_mm = 150.0, .half_width_mm = 10.0, .description = "test wheel"};
}

struct Case {
  std::string name;
  std::shared_ptr<Surface> surface;
  Aperture aperture;
};

std::vector<Case> Cases() {
  const Aperture square{.width_x_mm = 120.0, .width_y_mm = 80.0};
  const Aperture disc{.shape = Aperture::Shape::kCircle, .diameter_mm = 100.0};
  return {
      {"concave on axis",
       std::make_shared<EvenAsphere>(EvenAsphereParameters{.vertex_radius_mm = 800.0, .conic = -2.2}),
       square},
      {"concave off axis",
       std::make_shared<EvenAsphere>(EvenAsphereParameters{
           .vertex_radius_mm = 800.0, .conic = -2.2, .off_axis_x_mm = 300.0, .off_axis_y_mm = 40.0}),
       square},
      {"convex on axis",
       std::make_shared<EvenAsphere>(
           EvenAsphereParameters{.vertex_radius_mm = 400.0, .conic = 0.0, .concave = false}),
       disc},
      {"convex off axis",
       std::make_shared<EvenAsphere>(EvenAsphereParameters{.vertex_radius_mm = 600.0,
                                                           .conic = -0.6,
                                                           .even_coefficients = {1e-11},
                                                           .off_axis_x_mm = 120.0,
                                                           .off_axis_y_mm = 60.0,
                                                           .concave = false}),
       square},
      {"freeform",
       std::make_shared<XyPolynomial>(
           std::vector<XyPolynomialTerm>{{2, 0, 4e-4}, {0, 2, -3e-4}, {1, 1, 1e-4}, {3, 0, 2e-7}}),
       disc},
  };
}

// Independent of the library: the ideal wheel (disc with a toroidal rim) at centre c contains
// point p when it is inside the torus tube, or inside the disc the tube surrounds. Returns the
// depth of p inside the wheel (mm, > 0 inside), measured as the torus distance.
double DepthInsideWheel(const Wheel& w, const Eigen::Vector3d& c, const Eigen::Vector3d& p) {
  const double rho = std::hypot(p.x() - c.x(), p.z() - c.z());
  const double dy = p.y() - c.y();
  if (std::abs(dy) > w.half_width_mm) return -1.0;  // beside the wheel
  const double tube = std::hypot(rho - w.base_radius_mm, dy) - w.arc_radius_mm;
  if (rho < w.base_radius_mm) return w.arc_radius_mm;  // in the hub: deep inside
  return -tube;
}

TEST(ControlPointForContact, TorusTouchesTheSurfaceWithTheSameNormal) {
  const Wheel wheel = TestWheel();
  std::mt19937 rng(4);
  for (const Case& c : Cases()) {
    std::uniform_real_distribution<double> ux(-c.aperture.HalfX(), c.aperture.HalfX());
    std::uniform_real_distribution<double> uy(-c.aperture.HalfY(), c.aperture.HalfY());
    for (int k = 0; k < 200; ++k) {
      const double x = ux(rng), y = uy(rng);
      const ControlPoint p = ControlPointForContact(*c.surface, wheel, x, y);
      const Eigen::Vector3d& w = p.wheel_centre_mm;
      // Distance from the contact to the torus: zero to 1 nm.
      const double rho = std::hypot(x - w.x(), p.contact_mm.z() - w.z());
      EXPECT_NEAR(std::hypot(rho - wheel.base_radius_mm, y - w.y()) - wheel.arc_radius_mm, 0.0, 1e-9)
          << c.name;
      // The torus normal there (from the nearest point of the arc-centre circle) is -n.
      Eigen::Vector3d radial(x - w.x(), 0.0, p.contact_mm.z() - w.z());
      radial.normalize();
      const Eigen::Vector3d arc_centre = w + wheel.base_radius_mm * radial;
      const Eigen::Vector3d torus_normal = (p.contact_mm - arc_centre).normalized();
      EXPECT_LT((torus_normal + p.normal).norm(), 1e-12) << c.name;
      const SurfacePoint s = c.surface->Evaluate(x, y);
      EXPECT_LT((p.normal - Eigen::Vector3d(-s.fx, -s.fy, 1.0).normalized()).norm(), 1e-15);
    }
  }
}

TEST(ControlPointForContact, WheelNowhereCutsBelowTheSurface) {
  const Wheel wheel = TestWheel();
  for (const Case& c : Cases()) {
    for (double x : {-c.aperture.HalfX() * 0.9, 0.0, c.aperture.HalfX() * 0.7}) {
      for (double y : {-c.aperture.HalfY() * 0.6, 0.0, c.aperture.HalfY() * 0.5}) {
        if (!c.aperture.Contains(x, y)) continue;
        const ControlPoint p = ControlPointForContact(*c.surface, wheel, x, y);
        // Dense around the contact (0.05 mm) and coarse over the aperture (2 mm).
        double deepest = -1.0;
        for (double step : {0.05, 2.0}) {
          const double span = step == 0.05 ? 2.0 : c.aperture.HalfX();
          for (double dx = -span; dx <= span; dx += step) {
            for (double dy = -span; dy <= span; dy += step) {
              const double sx = x + dx, sy = y + dy;
              const Eigen::Vector3d q(sx, sy, c.surface->Evaluate(sx, sy).z_mm);
              deepest = std::max(deepest, DepthInsideWheel(wheel, p.wheel_centre_mm, q));
            }
          }
        }
        EXPECT_LT(deepest, 1e-9) << c.name << " contact " << x << ", " << y;
        const GougeProbe probe = ProbeGouge(*c.surface, c.aperture, wheel, p, 41);
        EXPECT_GT(probe.min_gap_mm, -1e-9) << c.name;
      }
    }
  }
}

TEST(ProbeGouge, FindsAWheelLoweredByOneMicrometre) {
  const Wheel wheel = TestWheel();
  const Case c = Cases()[1];
  ControlPoint p = ControlPointForContact(*c.surface, wheel, 10.0, -5.0);
  p.wheel_centre_mm.z() -= 1e-3;
  const GougeProbe probe = ProbeGouge(*c.surface, c.aperture, wheel, p, 41);
  // The contact is one of the samples: there the lowered wheel sits 1 um into the surface, and
  // elsewhere the clearance only adds.
  EXPECT_NEAR(probe.min_gap_mm, -1e-3, 1e-9);
  EXPECT_NEAR(probe.x_mm, 10.0, 1e-12);
  EXPECT_NEAR(probe.y_mm, -5.0, 1e-12);
}

TEST(SolveContactForWheelCentre, InvertsEq5) {
  const Wheel wheel = TestWheel();
  for (const Case& c : Cases()) {
    const ControlPoint forward = ControlPointForContact(*c.surface, wheel, 17.0, -9.0);
    const ControlPoint back = SolveContactForWheelCentre(*c.surface, wheel, forward.wheel_centre_mm.x(),
                                                         forward.wheel_centre_mm.y(), {0.0, 0.0});
    EXPECT_NEAR(back.contact_mm.x(), 17.0, 1e-9) << c.name;
    EXPECT_NEAR(back.contact_mm.y(), -9.0, 1e-9) << c.name;
  }
}

TEST(Eq5Jacobian, MatchesFiniteDifferencesOfEq5) {
  const Wheel wheel = TestWheel();
  for (const Case& c : Cases()) {
    const double x = 12.0, y = 7.0, h = 1e-4;
    const Eigen::Matrix2d j = Eq5Jacobian(*c.surface, wheel, x, y);
    const auto centre = [&](double a, double b) {
      return ControlPointForContact(*c.surface, wheel, a, b).wheel_centre_mm.head<2>().eval();
    };
    const Eigen::Vector2d dx = (centre(x + h, y) - centre(x - h, y)) / (2 * h);
    const Eigen::Vector2d dy = (centre(x, y + h) - centre(x, y - h)) / (2 * h);
    EXPECT_LT((j.col(0) - dx).norm(), 1e-7) << c.name;
    EXPECT_LT((j.col(1) - dy).norm(), 1e-7) << c.name;
  }
}

struct Collected {
  std::vector<ToolpathRow> rows;
};

ToolpathSummary RunToolpath(const Case& c, const Wheel& wheel, const ToolpathOptions& options,
                            Collected& out) {
  return GenerateToolpath(*c.surface, c.aperture, wheel, options,
                          {.prepare = nullptr, .consume = [&out](ToolpathRow& r) { out.rows.push_back(r); }});
}

TEST(GenerateToolpath, RowsAreStraightAndEveryPointTouchesTheSurface) {
  const Wheel wheel = TestWheel();
  for (const Case& c : Cases()) {
    ToolpathOptions o{.step_over_mm = 2.5,
                      .point_spacing_mm = 1.5,
                      .feed_mm_per_min = 6000,
                      .lead_in_mm = 4.0,
                      .lead_out_mm = 6.0,
                      .gouge_check_spacing_mm = 3.0,
                      .threads = 2};
    Collected got;
    const ToolpathSummary summary = RunToolpath(c, wheel, o, got);
    ASSERT_FALSE(got.rows.empty()) << c.name;
    EXPECT_LT(summary.max_row_deviation_mm, 1e-9) << c.name;
    EXPECT_GT(summary.gouge_checks, 0);
    EXPECT_GT(summary.min_gouge_gap_mm, -1e-9) << c.name;
    EXPECT_LE(summary.row_pitch_mm, 2.5 + 1e-12);
    int previous_row = -1;
    for (const ToolpathRow& row : got.rows) {
      EXPECT_GT(row.row, previous_row);
      previous_row = row.row;
      const double row_yw = row.points.front().wheel_centre_mm.y();
      const double expected_yw = summary.first_row_yw_mm + row.row * summary.row_pitch_mm;
      EXPECT_NEAR(row_yw, expected_yw, 1e-9) << c.name;
      EXPECT_EQ(row.reversed, row.row % 2 == 1);
      for (size_t i = 0; i < row.points.size(); ++i) {
        const ControlPoint& p = row.points[i];
        EXPECT_NEAR(p.wheel_centre_mm.y(), expected_yw, 1e-9) << c.name;  // straight to 1 nm
        EXPECT_NEAR(p.contact_mm.z(), c.surface->Evaluate(p.contact_mm.x(), p.contact_mm.y()).z_mm, 1e-12);
        const double rho =
            std::hypot(p.contact_mm.x() - p.wheel_centre_mm.x(), p.contact_mm.z() - p.wheel_centre_mm.z());
        EXPECT_NEAR(std::hypot(rho - wheel.base_radius_mm, p.contact_mm.y() - p.wheel_centre_mm.y()),
                    wheel.arc_radius_mm, 1e-9)
            << c.name;
        if (i > 0) {
          const double step = p.wheel_centre_mm.x() - row.points[i - 1].wheel_centre_mm.x();
          EXPECT_LE(std::abs(step), 1.5 + 1e-9);
          EXPECT_GT(row.reversed ? -step : step, 0.0);
        }
      }
      // Lead-in / lead-out: contacts run past the aperture's chord at the row's middle contact.
      const auto& first = row.reversed ? row.points.back() : row.points.front();
      const auto& last = row.reversed ? row.points.front() : row.points.back();
      const double lead_low = row.reversed ? 6.0 : 4.0, lead_high = row.reversed ? 4.0 : 6.0;
      const double half_low = -first.contact_mm.x() - lead_low, half_high = last.contact_mm.x() - lead_high;
      EXPECT_NEAR(half_low, half_high, 1e-9) << c.name;
      EXPECT_LE(half_low, c.aperture.HalfX() + 1e-9);
    }
  }
}

TEST(GenerateToolpath, ChordalToleranceBoundsTheMidpointDeviation) {
  const Wheel wheel = TestWheel();
  const Case c{"sphere",
               std::make_shared<EvenAsphere>(EvenAsphereParameters{.vertex_radius_mm = 300.0, .conic = 0.0}),
               Aperture{.width_x_mm = 100.0, .width_y_mm = 10.0}};
  ToolpathOptions o{.step_over_mm = 5.0, .point_spacing_mm = 20.0, .chordal_tolerance_um = 0.5, .threads = 1};
  Collected got;
  RunToolpath(c, wheel, o, got);
  for (const ToolpathRow& row : got.rows) {
    for (size_t i = 1; i < row.points.size(); ++i) {
      const ControlPoint& a = row.points[i - 1];
      const ControlPoint& b = row.points[i];
      const ControlPoint mid =
          SolveContactForWheelCentre(*c.surface, wheel, 0.5 * (a.wheel_centre_mm.x() + b.wheel_centre_mm.x()),
                                     a.wheel_centre_mm.y(), a.contact_mm.head<2>());
      EXPECT_LE(std::abs(mid.wheel_centre_mm.z() - 0.5 * (a.wheel_centre_mm.z() + b.wheel_centre_mm.z())),
                0.5e-3 + 1e-12);
    }
    // Wheel-centre path on a sphere of radius 300 is a circle of radius 300 - 200 = 100 in the
    // middle row: chord s with sagitta s^2 / 800 <= 0.5 um needs s <= 0.63 mm over ~37 mm of Xw.
    EXPECT_GT(row.points.size(), 50u);
  }
}

TEST(GenerateToolpath, PassesStepDownToTheSurface) {
  const Wheel wheel = TestWheel();
  const Case c = Cases()[0];
  ToolpathOptions o{
      .step_over_mm = 20.0, .point_spacing_mm = 10.0, .depth_per_pass_um = 10.0, .passes = 3, .threads = 2};
  Collected got;
  const ToolpathSummary s = RunToolpath(c, wheel, o, got);
  ASSERT_EQ(got.rows.size(), static_cast<size_t>(3 * s.rows_per_pass));
  const ControlPoint& first_pass = got.rows.front().points.front();
  const ControlPoint& last_pass = got.rows[static_cast<size_t>(2 * s.rows_per_pass)].points.front();
  EXPECT_NEAR(first_pass.wheel_centre_mm.z() - last_pass.wheel_centre_mm.z(), 0.020, 1e-12);
  EXPECT_NEAR(first_pass.wheel_centre_mm.x(), last_pass.wheel_centre_mm.x(), 1e-12);
}

TEST(GenerateToolpath, RefusesAConcaveSurfaceMoreCurvedThanTheWheelNamingThePoint) {
  const Wheel wheel = TestWheel();  // total radius 200 mm
  const Case c{"tight sphere",
               std::make_shared<EvenAsphere>(EvenAsphereParameters{.vertex_radius_mm = 150.0, .conic = 0.0}),
               Aperture{.width_x_mm = 40.0, .width_y_mm = 20.0}};
  Collected got;
  const std::string message = ErrorMessageOf([&] { RunToolpath(c, wheel, {.threads = 2}, got); });
  EXPECT_THAT(message, HasSubstr("grinding.toolpath"));
  EXPECT_THAT(message, HasSubstr("cannot reach the curvature at contact ("));
  EXPECT_THAT(message, HasSubstr("row 0 point"));
}

TEST(GenerateToolpath, RefusesAContactOffTheWheelsUsableArc) {
  Wheel wheel = TestWheel();
  wheel.half_width_mm = 2.0;
  // 300 mm off axis in y on R0 = 800: fy ~ 0.4, so contacts sit ~18 mm from the arc centre.
  const Case c{"steep",
               std::make_shared<EvenAsphere>(
                   EvenAsphereParameters{.vertex_radius_mm = 800.0, .conic = 0.0, .off_axis_y_mm = 300.0}),
               Aperture{.width_x_mm = 20.0, .width_y_mm = 20.0}};
  Collected got;
  const std::string message = ErrorOf([&] { RunToolpath(c, wheel, {.threads = 1}, got); }).what();
  EXPECT_THAT(message, HasSubstr("beyond the wheel's usable arc"));
  EXPECT_THAT(message, HasSubstr("contact ("));
}

TEST(GenerateToolpath, RefusesInvalidOptionsByName) {
  const Case c = Cases()[0];
  Collected got;
  EXPECT_THAT(ErrorMessageOf([&] { RunToolpath(c, TestWheel(), {.step_over_mm = -1.0}, got); },
                             ErrorCode::kInvalidOption),
              HasSubstr("path.step_over_mm = -1 violates > 0"));
}

TEST(GenerateToolpath, MeasuredProfileMovesTheWheelAlongTheNormal) {
  Wheel wheel = TestWheel();
  wheel.profile_u_mm = {-10.0, 10.0};
  wheel.profile_error_um = {3.0, 3.0};  // a uniformly 3 um larger arc
  const Case c = Cases()[1];
  const ControlPoint ideal = ControlPointForContact(*c.surface, TestWheel(), 5.0, 5.0);
  const ControlPoint real = ControlPointForContact(*c.surface, wheel, 5.0, 5.0);
  EXPECT_LT((real.wheel_centre_mm - ideal.wheel_centre_mm - 3e-3 * ideal.normal).norm(), 1e-12);
}

}  // namespace
}  // namespace arcwheel::grinding
