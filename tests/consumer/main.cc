// Fits a circle to exact points on a known arc through the installed arcwheel::fitting and checks
// the answer against the circle the points were made from. Exit status 0 when the radius and
// centre are within 1e-9 mm and the installed version header reports the expected version.
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string_view>
#include <vector>

#include "core/version.h"
#include "fitting/circle_fit.h"

int main() {
  constexpr double kCenterXMm = 12.5, kCenterYMm = -40.0, kRadiusMm = 137.25;
  constexpr double kToleranceMm = 1e-9;
  // A 50 deg arc, as a wheel section gives, sampled at 61 points.
  std::vector<double> x_mm, y_mm;
  for (int i = 0; i <= 60; ++i) {
    const double angle_rad = (20.0 + 50.0 * i / 60.0) * std::numbers::pi / 180.0;
    x_mm.push_back(kCenterXMm + kRadiusMm * std::cos(angle_rad));
    y_mm.push_back(kCenterYMm + kRadiusMm * std::sin(angle_rad));
  }
  const arcwheel::fitting::CircleFit fit = arcwheel::fitting::FitCircle(x_mm, y_mm, {}, {});
  std::printf("arcwheel %s: radius %.12f mm, centre (%.12f, %.12f) mm, %s\n", arcwheel::kVersion,
              fit.radius_mm, fit.center_mm.x(), fit.center_mm.y(), fit.message.c_str());
  bool ok = fit.IsUsable() && std::abs(fit.radius_mm - kRadiusMm) <= kToleranceMm &&
            std::abs(fit.center_mm.x() - kCenterXMm) <= kToleranceMm &&
            std::abs(fit.center_mm.y() - kCenterYMm) <= kToleranceMm;
  if (!ok) {
    std::printf("expected radius %.12f mm, centre (%.12f, %.12f) mm\n", kRadiusMm, kCenterXMm, kCenterYMm);
  }
  if (std::string_view(arcwheel::kVersion) != ARCWHEEL_EXPECTED_VERSION) {
    std::printf("expected version %s\n", ARCWHEEL_EXPECTED_VERSION);
    ok = false;
  }
  return ok ? 0 : 1;
}
