#pragma once
// The wheel model's bases (fitting/wheel_model.h): the periodic cubic B-splines of Ra(c), a(c) and
// b(c), the profile's cubic B-spline p(u), and where their coefficients sit in the parameter
// vector. Internal to the model's sources.

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>

#include "processing/uniform_cubic_bspline.h"

namespace arcwheel::fitting::internal {

using Eigen::MatrixXd;
using Eigen::VectorXd;

// processing::UniformCubicBSplineWeights with 1/6 as a product: a division by 6 costs as much as
// the rest of a sample's row, and the weights differ in the last bit at most.
inline void CubicWeights(double f, double w[4]) {
  constexpr double kSixth = 1.0 / 6.0;
  const double g = 1.0 - f, f2 = f * f, f3 = f2 * f;
  w[0] = g * g * g * kSixth;
  w[1] = (3.0 * f3 - 6.0 * f2 + 4.0) * kSixth;
  w[2] = (-3.0 * f3 + 3.0 * f2 + 3.0 * f + 1.0) * kSixth;
  w[3] = f3 * kSixth;
}

// A periodic basis at one phase: the knot interval, the four coefficients it touches and their
// weights.
struct PeriodicAt {
  int interval = 0;
  int column[4];
  double w[4];
};

// Ra(c), a(c), b(c): `knots` coefficients spread evenly over a turn, wrapping around.
struct PeriodicBasis {
  int knots = 0;
  // The coefficients of interval j (0 <= j <= knots; j = knots at c just below 360 degrees,
  // where the division rounds up).
  void Columns(int j, int column[4]) const {
    for (int k = 0; k < 4; ++k) {
      const int i = j - 1 + k;
      column[k] = knots == 1 ? 0 : (i < 0 ? i + knots : (i >= knots ? i - knots : i));
    }
  }
  // As At, without the library's floor and the integer divisions (0 <= phase_deg < 360;
  // knots_per_deg = knots / 360).
  void Weights(double phase_deg, double knots_per_deg, PeriodicAt& at) const {
    if (knots == 1) {
      // A constant: its four weights, on the one coefficient, sum to 1.
      at = {0, {0, 0, 0, 0}, {1.0, 0.0, 0.0, 0.0}};
      return;
    }
    const double t = phase_deg * knots_per_deg;
    at.interval = static_cast<int>(t);
    CubicWeights(t - at.interval, at.w);
    Columns(at.interval, at.column);
  }
  void At(double phase_deg, int index[4], double weight[4]) const {
    const double t = phase_deg / 360.0 * knots;
    const double interval = std::floor(t);
    const processing::UniformCubicWeights cw = processing::UniformCubicBSplineWeights(t - interval);
    const int j = static_cast<int>(interval);
    for (int k = 0; k < 4; ++k) {
      index[k] = ((j - 1 + k) % knots + knots) % knots;
      weight[k] = cw.w[static_cast<std::size_t>(k)];
    }
  }
  // Row r of the returned matrix holds every coefficient's weight at phases_deg[r].
  [[nodiscard]] MatrixXd Matrix(std::span<const double> phases_deg) const {
    MatrixXd m = MatrixXd::Zero(static_cast<Eigen::Index>(phases_deg.size()), knots);
    for (std::size_t r = 0; r < phases_deg.size(); ++r) {
      int index[4];
      double weight[4];
      At(phases_deg[r], index, weight);
      for (int k = 0; k < 4; ++k) m(static_cast<Eigen::Index>(r), index[k]) += weight[k];
    }
    return m;
  }
};

// p(u): a cubic B-spline with uniform knots over [low_mm, low_mm + intervals * step_mm].
struct ProfileBasis {
  double low_mm = 0, step_mm = 1;
  int intervals = 1;
  [[nodiscard]] int size() const { return intervals + 3; }
  // First coefficient, weights and d(weight)/du at u (clamped to the span).
  int At(double u_mm, double weight[4], double slope[4]) const {
    const double t = std::clamp((u_mm - low_mm) / step_mm, 0.0, static_cast<double>(intervals));
    const int j = std::min(static_cast<int>(t), intervals - 1);
    const processing::UniformCubicWeights cw = processing::UniformCubicBSplineWeights(t - j);
    for (int k = 0; k < 4; ++k) {
      weight[k] = cw.w[static_cast<std::size_t>(k)];
      slope[k] = cw.dw[static_cast<std::size_t>(k)] / step_mm;
    }
    return j;
  }
  // As At, with 1 / step_mm given (a division per sample costs as much as the rest of the weights).
  int At(double u_mm, double per_step, double weight[4], double slope[4]) const {
    const double t = std::clamp((u_mm - low_mm) * per_step, 0.0, static_cast<double>(intervals));
    const int j = std::min(static_cast<int>(t), intervals - 1);
    const double f = t - j, g = 1.0 - f;
    CubicWeights(f, weight);
    slope[0] = -0.5 * g * g * per_step;
    slope[1] = (1.5 * f * f - 2.0 * f) * per_step;
    slope[2] = (-1.5 * f * f + f + 0.5) * per_step;
    slope[3] = 0.5 * f * f * per_step;
    return j;
  }
};

// Knots per turn of Ra(c), a(c) and b(c).
struct Knots {
  int radius = 0, axial = 0, runout = 0;
  bool operator==(const Knots&) const = default;
};

// Where each function's coefficients sit in the parameter vector [Ra, a, b, p].
struct Layout {
  PeriodicBasis radius, axial, runout;
  ProfileBasis profile;
  [[nodiscard]] Knots knots() const { return {radius.knots, axial.knots, runout.knots}; }
  [[nodiscard]] int a0() const { return radius.knots; }
  [[nodiscard]] int b0() const { return radius.knots + axial.knots; }
  [[nodiscard]] int p0() const { return b0() + runout.knots; }
  [[nodiscard]] int size() const { return p0() + profile.size(); }
};

// The layout of `knots` over a band of half_width_mm, the profile's knots knot_step_mm apart
// (wheel_model_basis.cc, as the rest of this section).
Layout MakeLayout(const Knots& knots, double half_width_mm, double knot_step_mm);

// The constraints on p: its integrals against 1, u and u^2 over the band vanish. Returns an
// orthonormal basis of the coefficient vectors that meet them (size x (size - 3)).
MatrixXd ProfileNullSpace(const ProfileBasis& basis, double half_width_mm);

// Maps reduced parameters [Ra, a, b (coarse knots), p in the constraints' null space] to the full
// parameters of `fine`.
MatrixXd Reduction(const Layout& fine, const Knots& coarse, const MatrixXd& null_space);

}  // namespace arcwheel::fitting::internal
