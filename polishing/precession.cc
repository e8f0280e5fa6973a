#include "polishing/precession.h"

#include <fmt/core.h>

#include <cmath>
#include <numbers>

#include "core/error.h"

namespace arcwheel::polishing {
namespace {

constexpr const char* kPrecessionStage = "polishing.precession";

Eigen::Vector3d UpwardNormal(const surfaces::SurfacePoint& p) {
  return Eigen::Vector3d(-p.fx, -p.fy, 1.0).normalized();
}

}  // namespace

std::vector<std::string> PrecessionOptions::Problems() const {
  std::vector<std::string> problems;
  const auto check = [&](const char* name, double value, bool ok, const char* rule) {
    if (!ok) problems.push_back(fmt::format("PrecessionOptions::{} = {} violates {}", name, value, rule));
  };
  check("tilt_deg", tilt_deg, tilt_deg >= 0.0 && tilt_deg < 90.0, "[0, 90)");
  check("precession_rate_rpm", precession_rate_rpm, std::isfinite(precession_rate_rpm), "finite");
  check("feed_mm_per_s", feed_mm_per_s, feed_mm_per_s > 0.0 && std::isfinite(feed_mm_per_s), "> 0");
  check("bonnet_radius_mm", bonnet_radius_mm, bonnet_radius_mm >= 0.0 && std::isfinite(bonnet_radius_mm),
        ">= 0");
  check("arm_length_mm", arm_length_mm, arm_length_mm >= 0.0 && std::isfinite(arm_length_mm), ">= 0");
  check("time_step_s", time_step_s, time_step_s > 0.0 && std::isfinite(time_step_s), "> 0");
  return problems;
}

std::vector<PrecessionSample> PrecessionTrajectory(const surfaces::Surface& surface,
                                                   std::span<const Eigen::Vector2d> path_xy_mm,
                                                   const PrecessionOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kPrecessionStage, options.Problems());
  // Cumulative length of the polyline in the part's (x, y) plane lifted onto the surface.
  std::vector<double> length_mm{0.0};
  for (std::size_t i = 0; i < path_xy_mm.size(); ++i) {
    const Eigen::Vector2d& p = path_xy_mm[i];
    if (!surface.InDomain(p.x(), p.y())) {
      throw Error(ErrorCode::kBadInput, kPrecessionStage,
                  fmt::format("path point {} ({}, {}) mm is off the surface", i, p.x(), p.y()));
    }
    if (i == 0) continue;
    const Eigen::Vector3d a(path_xy_mm[i - 1].x(), path_xy_mm[i - 1].y(),
                            surface.Evaluate(path_xy_mm[i - 1].x(), path_xy_mm[i - 1].y()).z_mm);
    const Eigen::Vector3d b(p.x(), p.y(), surface.Evaluate(p.x(), p.y()).z_mm);
    length_mm.push_back(length_mm.back() + (b - a).norm());
  }
  if (path_xy_mm.size() < 2 || !(length_mm.back() > 0.0)) {
    throw Error(ErrorCode::kInvalidOption, kPrecessionStage, "the path needs two or more distinct points");
  }
  const double theta_rad = options.tilt_deg * std::numbers::pi / 180.0;
  const double w2_rad_per_s = options.precession_rate_rpm * 2.0 * std::numbers::pi / 60.0;

  std::vector<PrecessionSample> samples;
  std::size_t segment = 1;
  const double total_s = length_mm.back() / options.feed_mm_per_s;
  for (long k = 0;; ++k) {
    const double t = std::min(static_cast<double>(k) * options.time_step_s, total_s);
    const double s = t * options.feed_mm_per_s;
    while (segment + 1 < length_mm.size() && length_mm[segment] < s) ++segment;
    const double span_mm = length_mm[segment] - length_mm[segment - 1];
    const double u = span_mm > 0.0 ? (s - length_mm[segment - 1]) / span_mm : 0.0;
    const Eigen::Vector2d xy = (1.0 - u) * path_xy_mm[segment - 1] + u * path_xy_mm[segment];
    const surfaces::SurfacePoint sp = surface.Evaluate(xy.x(), xy.y());
    const Eigen::Vector3d c = UpwardNormal(sp);
    const Eigen::Vector2d d = path_xy_mm[segment] - path_xy_mm[segment - 1];
    // Feed direction on the surface (the chord's tangent), then projected on the tangent plane.
    const Eigen::Vector3d feed(d.x(), d.y(), sp.fx * d.x() + sp.fy * d.y());
    const Eigen::Vector3d a = (feed - feed.dot(c) * c).normalized();
    PrecessionSample sample;
    sample.time_s = t;
    sample.contact_mm = Eigen::Vector3d(xy.x(), xy.y(), sp.z_mm);
    sample.centre_mm = sample.contact_mm + options.bonnet_radius_mm * c;
    sample.local_frame.col(0) = a;
    sample.local_frame.col(1) = c.cross(a);
    sample.local_frame.col(2) = c;
    const double alpha = w2_rad_per_s * t;
    const Eigen::Vector3d p_a(std::sin(theta_rad) * std::cos(alpha), std::sin(theta_rad) * std::sin(alpha),
                              std::cos(theta_rad));
    sample.axis = sample.local_frame * p_a;
    sample.traced_mm = sample.centre_mm + options.arm_length_mm * sample.axis;
    samples.push_back(sample);
    if (t >= total_s) break;
  }
  return samples;
}

}  // namespace arcwheel::polishing
