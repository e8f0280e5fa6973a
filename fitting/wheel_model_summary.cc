// The fitted wheel model as WheelModel reports it: Ra, a and b at the map's phases, Ra's mean, range
// and harmonics, and the profile error, each with its 1-sigma from the covariance.
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <utility>
#include <vector>

#include "fitting/wheel_model_impl.h"

namespace arcwheel::fitting::internal {
namespace {

// Value and 1-sigma of w^T theta.
std::pair<double, double> Linear(const VectorXd& w, const VectorXd& theta, const MatrixXd& covariance) {
  return {w.dot(theta), std::sqrt(std::max(w.dot(covariance * w), 0.0))};
}

}  // namespace

void SampleFunctions(const Fitted& f, std::span<const double> phases_deg, WheelModel& model) {
  const Layout& l = f.layout;
  const MatrixXd radius = l.radius.Matrix(phases_deg);
  const MatrixXd axial = l.axial.Matrix(phases_deg);
  const MatrixXd runout = l.runout.Matrix(phases_deg);
  for (Eigen::Index r = 0; r < radius.rows(); ++r) {
    VectorXd w = VectorXd::Zero(l.size());
    w.head(l.radius.knots) = radius.row(r).transpose();
    auto [ra, ra_sigma] = Linear(w, f.solution.theta, f.covariance);
    w.setZero();
    w.segment(l.a0(), l.axial.knots) = axial.row(r).transpose();
    auto [a, a_sigma] = Linear(w, f.solution.theta, f.covariance);
    w.setZero();
    w.segment(l.b0(), l.runout.knots) = runout.row(r).transpose();
    auto [b, b_sigma] = Linear(w, f.solution.theta, f.covariance);
    model.arc_radius_mm.push_back(ra);
    model.arc_radius_sigma_mm.push_back(ra_sigma);
    model.center_axial_mm.push_back(a);
    model.center_axial_sigma_mm.push_back(a_sigma);
    model.center_radial_mm.push_back(b);
    model.center_radial_sigma_mm.push_back(b_sigma);
  }
}

void SummariseRadius(const Fitted& f, std::span<const double> phases_deg, WheelModel& model) {
  const Layout& l = f.layout;
  const Eigen::Index k = l.radius.knots;
  const VectorXd r = f.solution.theta.head(k);
  const MatrixXd c = f.covariance.topLeftCorner(k, k);
  // Every periodic basis function has the same integral, so the mean over a turn is the mean
  // coefficient.
  const VectorXd mean = VectorXd::Constant(k, 1.0 / static_cast<double>(k));
  model.mean_arc_radius_mm = mean.dot(r);
  model.mean_arc_radius_sigma_mm = std::sqrt(mean.dot(c * mean));
  const MatrixXd at = l.radius.Matrix(phases_deg);
  const VectorXd values = at * r;
  Eigen::Index high = 0, low = 0;
  values.maxCoeff(&high);
  values.minCoeff(&low);
  if (k == 1) return;  // a constant radius: no range
  const VectorXd range = (at.row(high) - at.row(low)).transpose();
  model.arc_radius_range_mm = range.dot(r);
  model.arc_radius_range_sigma_mm = std::sqrt(std::max(range.dot(c * range), 0.0));
}

void RadiusHarmonics(const Fitted& f, int harmonics, WheelModel& model) {
  const Layout& l = f.layout;
  const Eigen::Index k = l.radius.knots;
  const int points = 64 * l.radius.knots;
  std::vector<double> phases(static_cast<std::size_t>(points));
  for (int i = 0; i < points; ++i) phases[static_cast<std::size_t>(i)] = i * 360.0 / points;
  const MatrixXd at = l.radius.Matrix(phases);
  const VectorXd r = f.solution.theta.head(k);
  const MatrixXd c = f.covariance.topLeftCorner(k, k);
  const int orders = l.radius.knots < 4 ? 0 : std::min(harmonics, std::max(1, l.radius.knots / 2 - 1));
  for (int order = 1; order <= orders; ++order) {
    // Ra's Fourier coefficients: A cos(order c) + B sin(order c), linear in the coefficients.
    VectorXd cos_w = VectorXd::Zero(k), sin_w = VectorXd::Zero(k);
    for (int i = 0; i < points; ++i) {
      const double angle = order * phases[static_cast<std::size_t>(i)] * std::numbers::pi / 180.0;
      cos_w += 2.0 / points * std::cos(angle) * at.row(i).transpose();
      sin_w += 2.0 / points * std::sin(angle) * at.row(i).transpose();
    }
    const double a = cos_w.dot(r), b = sin_w.dot(r);
    const double va = cos_w.dot(c * cos_w), vb = sin_w.dot(c * sin_w), cab = cos_w.dot(c * sin_w);
    const double amplitude = std::hypot(a, b);
    RadiusHarmonic h;
    h.order = order;
    h.amplitude_um = amplitude * 1e3;
    // amplitude cos(order c + phase) = A cos + B sin with A = amp cos(phase), B = -amp sin(phase).
    h.phase_deg = std::atan2(-b, a) * 180.0 / std::numbers::pi;
    if (amplitude > 0) {
      h.amplitude_sigma_um =
          std::sqrt(std::max(a * a * va + b * b * vb + 2 * a * b * cab, 0.0)) / amplitude * 1e3;
      h.phase_sigma_deg = std::sqrt(std::max(b * b * va + a * a * vb - 2 * a * b * cab, 0.0)) /
                          (amplitude * amplitude) * 180.0 / std::numbers::pi;
    }
    model.radius_harmonics.push_back(h);
  }
}

void SampleProfile(const Fitted& f, double half_width_mm, WheelModel& model) {
  const Layout& l = f.layout;
  const int steps = static_cast<int>(std::ceil(2.0 * half_width_mm / 0.1));
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (int i = 0; i <= steps; ++i) {
    const double u = -half_width_mm + 2.0 * half_width_mm * i / steps;
    double w[4], slope[4];
    const int first = l.profile.At(u, w, slope);
    VectorXd row = VectorXd::Zero(l.size());
    for (int k = 0; k < 4; ++k) row[l.p0() + first + k] = w[k];
    const auto [p, sigma] = Linear(row, f.solution.theta, f.covariance);
    model.profile_u_mm.push_back(u);
    model.profile_error_um.push_back(p * 1e3);
    model.profile_error_sigma_um.push_back(sigma * 1e3);
    low = std::min(low, p);
    high = std::max(high, p);
  }
  model.profile_pv_um = (high - low) * 1e3;
}

}  // namespace arcwheel::fitting::internal
