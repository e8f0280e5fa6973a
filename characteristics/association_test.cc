// Reference circles against data sets whose answer is exact by construction, generated here: the
// support points on the circles, every other point strictly between (minimum zone) or strictly
// inside / outside (circumscribed / inscribed), so the optimality condition names the answer.

#include "characteristics/association.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <set>
#include <string>
#include <vector>

namespace arcwheel::characteristics {
namespace {

constexpr double kPi = std::numbers::pi;
// The requirement: centre and radii within 1e-7 mm.
constexpr double kToleranceMm = 1e-7;

struct Construction {
  double center_x_mm = 0.0, center_y_mm = 0.0;
  double radius_inner_mm = 0.0, radius_outer_mm = 0.0;
  std::set<int> support;
  std::vector<double> x_mm, y_mm;
  std::string description;
};

// Centre up to 1e4 mm from the origin, radius 1-500 mm (log-uniform), zone 0.1-50 um.
struct Draw {
  std::mt19937& rng;
  double Uniform(double low, double high) { return std::uniform_real_distribution<double>(low, high)(rng); }
  double LogUniform(double low, double high) { return std::exp(Uniform(std::log(low), std::log(high))); }
};

Construction Frame(Draw& draw, double span_deg) {
  Construction c;
  const double distance = draw.LogUniform(1.0, 1e4);
  const double direction = draw.Uniform(0, 2 * kPi);
  c.center_x_mm = distance * std::cos(direction);
  c.center_y_mm = distance * std::sin(direction);
  const double radius = draw.LogUniform(1.0, 500.0);
  const double zone_mm = draw.LogUniform(0.1e-3, 50e-3);
  c.radius_inner_mm = radius - 0.5 * zone_mm;
  c.radius_outer_mm = radius + 0.5 * zone_mm;
  c.description = "span " + std::to_string(span_deg) + " deg, radius " + std::to_string(radius) +
                  " mm, zone " + std::to_string(zone_mm * 1e3) + " um, centre " + std::to_string(distance) +
                  " mm out";
  return c;
}

void AddPoint(Construction& c, double angle_rad, double radius_mm) {
  c.x_mm.push_back(c.center_x_mm + radius_mm * std::cos(angle_rad));
  c.y_mm.push_back(c.center_y_mm + radius_mm * std::sin(angle_rad));
}

// n points equally spaced over the span from `start`; the support points replace the nearest
// samples. `radius_of(k)` gives the k-th support point's radius, `other()` the others'.
template <typename SupportRadius, typename OtherRadius>
void Sample(Construction& c, Draw& draw, double start, double span_rad, int n,
            const std::vector<double>& support_rad, SupportRadius radius_of, OtherRadius other) {
  const bool closed = span_rad >= 2 * kPi - 1e-12;
  const double step = span_rad / (closed ? n : n - 1);
  std::vector<int> support_index;
  for (const double angle : support_rad)
    support_index.push_back(static_cast<int>(std::lround((angle - start) / step)) % n);
  for (int i = 0; i < n; ++i) {
    const auto found = std::find(support_index.begin(), support_index.end(), i);
    if (found != support_index.end()) {
      const auto k = static_cast<std::size_t>(found - support_index.begin());
      AddPoint(c, support_rad[k], radius_of(k));
      c.support.insert(i);
    } else {
      AddPoint(c, start + step * i, other(draw));
    }
  }
}

// Four points alternately on the outer and inner circle, in angle order over the span.
Construction MinimumZoneCase(std::mt19937& rng, double span_deg) {
  Draw draw{rng};
  Construction c = Frame(draw, span_deg);
  const double span = span_deg * kPi / 180.0;
  const double start = draw.Uniform(-kPi, kPi);
  const int n = 240;
  std::vector<double> support;
  for (int k = 0; k < 4; ++k) support.push_back(start + span * (k + draw.Uniform(0.2, 0.8)) / 4.0);
  const double inner = c.radius_inner_mm, outer = c.radius_outer_mm;
  Sample(
      c, draw, start, span, n, support, [&](std::size_t k) { return k % 2 == 0 ? outer : inner; },
      [&](Draw& d) { return inner + (outer - inner) * d.Uniform(0.05, 0.95); });
  return c;
}

// Three points on the circle whose triangle holds the centre; the others strictly inside
// (circumscribed) or outside (inscribed) by 5-100 % of the zone.
Construction ThreePointCase(std::mt19937& rng, double span_deg, bool circumscribed) {
  Draw draw{rng};
  Construction c = Frame(draw, span_deg);
  const double span = span_deg * kPi / 180.0;
  const double start = draw.Uniform(-kPi, kPi);
  // Gaps between the support points of at most 0.55 span, and a closing gap of at most
  // 2 pi - 0.8 span: each below half a turn for spans of 240-300 deg. A full turn: three points
  // about a third of a turn apart.
  std::vector<double> support = {start + span * draw.Uniform(0.0, 0.1),
                                 start + span * draw.Uniform(0.45, 0.55),
                                 start + span * draw.Uniform(0.9, 1.0)};
  if (span_deg == 360.0) {
    support = {start + span * draw.Uniform(0.0, 0.05), start + span * draw.Uniform(0.3, 0.36),
               start + span * draw.Uniform(0.63, 0.7)};
  }
  const double zone = c.radius_outer_mm - c.radius_inner_mm;
  const double radius = circumscribed ? c.radius_outer_mm : c.radius_inner_mm;
  Sample(
      c, draw, start, span, 300, support, [&](std::size_t) { return radius; },
      [&](Draw& d) { return radius + (circumscribed ? -1.0 : 1.0) * zone * d.Uniform(0.05, 1.0); });
  if (circumscribed)
    c.radius_inner_mm = c.radius_outer_mm;
  else
    c.radius_outer_mm = c.radius_inner_mm;
  return c;
}

void ExpectCircle(const Construction& c, Association association) {
  const AssociatedCircle fit = AssociateCircle(c.x_mm, c.y_mm, {.association = association});
  ASSERT_TRUE(fit.IsCertified()) << c.description << ": " << fit.message;
  EXPECT_NEAR(fit.center_x_mm, c.center_x_mm, kToleranceMm) << c.description;
  EXPECT_NEAR(fit.center_y_mm, c.center_y_mm, kToleranceMm) << c.description;
  if (association == Association::kMinimumZone) {
    EXPECT_NEAR(fit.radius_inner_mm, c.radius_inner_mm, kToleranceMm) << c.description;
    EXPECT_NEAR(fit.radius_outer_mm, c.radius_outer_mm, kToleranceMm) << c.description;
    EXPECT_NEAR(fit.radius_mm, 0.5 * (c.radius_inner_mm + c.radius_outer_mm), kToleranceMm) << c.description;
    EXPECT_EQ(std::set<int>(fit.support_indices.begin(), fit.support_indices.end()), c.support)
        << c.description;
    ASSERT_EQ(fit.support_on_outer.size(), 4u);
    for (std::size_t k = 0; k < 4; ++k) EXPECT_NE(fit.support_on_outer[k], fit.support_on_outer[(k + 1) % 4]);
  } else {
    EXPECT_NEAR(fit.radius_mm, c.radius_outer_mm, kToleranceMm) << c.description;
    for (const int i : c.support) {
      EXPECT_NE(std::find(fit.support_indices.begin(), fit.support_indices.end(), i),
                fit.support_indices.end())
          << c.description << ": support point " << i;
    }
  }
}

TEST(MinimumZone, RecoversFourAlternatingContactsOnFullCirclesAndArcsDownTo40Deg) {
  std::mt19937 rng(20261205);  // fixed seed: a failure must reproduce
  for (const double span_deg : {360.0, 270.0, 180.0, 90.0, 60.0, 40.0}) {
    for (int trial = 0; trial < 60; ++trial)
      ExpectCircle(MinimumZoneCase(rng, span_deg), Association::kMinimumZone);
  }
}

TEST(MinimumCircumscribed, RecoversThreeContactsAroundTheCentre) {
  std::mt19937 rng(7);
  for (const double span_deg : {360.0, 300.0, 240.0}) {
    for (int trial = 0; trial < 60; ++trial) {
      ExpectCircle(ThreePointCase(rng, span_deg, true), Association::kMinimumCircumscribed);
    }
  }
}

TEST(MaximumInscribed, RecoversThreeContactsAroundTheCentre) {
  std::mt19937 rng(11);
  for (const double span_deg : {360.0, 300.0, 240.0}) {
    for (int trial = 0; trial < 60; ++trial) {
      ExpectCircle(ThreePointCase(rng, span_deg, false), Association::kMaximumInscribed);
    }
  }
}

// Harmonics k >= 2 about a circle have no first harmonic: the geometric least-squares circle is
// the circle itself (the gradient sum_i (d_i - R) u_i vanishes at the centre).
TEST(LeastSquares, RecoversTheCircleUnderHarmonicsOfTwoAndMoreUpr) {
  const double cx = -7300.0, cy = 4100.0, radius = 42.0;
  std::vector<double> x, y;
  const int n = 720;
  for (int i = 0; i < n; ++i) {
    const double t = 2 * kPi * i / n;
    const double r = radius + 3e-3 * std::cos(2 * t + 0.3) + 1e-3 * std::sin(15 * t);
    x.push_back(cx + r * std::cos(t));
    y.push_back(cy + r * std::sin(t));
  }
  const AssociatedCircle fit = AssociateCircle(x, y, {});
  ASSERT_TRUE(fit.IsCertified()) << fit.message;
  // Second order in the harmonics' amplitude over the radius: (3e-3)^2 / 42 = 2e-7 mm.
  EXPECT_NEAR(fit.center_x_mm, cx, 1e-6);
  EXPECT_NEAR(fit.center_y_mm, cy, 1e-6);
  EXPECT_NEAR(fit.radius_mm, radius, 1e-6);
  EXPECT_TRUE(fit.support_indices.empty());
}

TEST(Association, InscribedAndCircumscribedAreRefusedOnArcsWithinHalfATurn) {
  std::mt19937 rng(3);
  for (const Association association : {Association::kMaximumInscribed, Association::kMinimumCircumscribed}) {
    const Construction c = MinimumZoneCase(rng, 90.0);
    const AssociatedCircle fit = AssociateCircle(c.x_mm, c.y_mm, {.association = association});
    EXPECT_EQ(fit.status, AssociationStatus::kNotDefined) << fit.message;
    EXPECT_NE(fit.message.find("half a turn"), std::string::npos) << fit.message;
  }
}

TEST(Association, CollinearOrTooFewPointsAreDegenerate) {
  const std::vector<double> x = {0.0, 1.0, 2.0, 3.0}, y = {1.0, 3.0, 5.0, 7.0};
  for (const Association association : {Association::kLeastSquares, Association::kMinimumZone}) {
    const AssociatedCircle fit = AssociateCircle(x, y, {.association = association});
    EXPECT_EQ(fit.status, AssociationStatus::kDegenerate);
    EXPECT_EQ(fit.message, "all 4 points lie on one line: no circle passes through them");
  }
  EXPECT_EQ(CircleDataProblem(std::vector<double>{0.0, 1.0}, std::vector<double>{0.0, 1.0}),
            "a circle needs at least 3 points, got 2");
  EXPECT_EQ(CircleDataProblem(std::vector<double>{2.0, 2.0, 2.0}, std::vector<double>{1.0, 1.0, 1.0}),
            "all 3 points coincide");
  EXPECT_EQ(CircleDataProblem(std::vector<double>{0.0, 1.0, 0.0}, std::vector<double>{0.0, 0.0, 1.0}), "");
}

TEST(Association, NamesRoundTrip) {
  for (const Association association : {Association::kLeastSquares, Association::kMinimumZone,
                                        Association::kMaximumInscribed, Association::kMinimumCircumscribed}) {
    EXPECT_EQ(ParseAssociation(AssociationName(association)), association);
  }
  EXPECT_FALSE(ParseAssociation("chebyshev").has_value());
  EXPECT_EQ(AssociationOptions{.max_relinearisations = 0}.Problems(),
            std::vector<std::string>{"max_relinearisations = 0 violates >= 1"});
}

}  // namespace
}  // namespace arcwheel::characteristics
