#pragma once
// The uniform cubic B-spline's four weights at fraction f in [0, 1] of a knot interval, for the
// coefficients first .. first + 3 (first = the interval's index - 1 in a periodic or padded
// numbering), and their derivatives per knot interval. Shared by the helix spline and the wheel model.

#include <array>

namespace arcwheel::processing {

struct UniformCubicWeights {
  std::array<double, 4> w;
  std::array<double, 4> dw;  // d(w)/df
};

[[nodiscard]] inline UniformCubicWeights UniformCubicBSplineWeights(double f) {
  const double g = 1.0 - f;
  return {{g * g * g / 6.0, (3.0 * f * f * f - 6.0 * f * f + 4.0) / 6.0,
           (-3.0 * f * f * f + 3.0 * f * f + 3.0 * f + 1.0) / 6.0, f * f * f / 6.0},
          {-0.5 * g * g, 1.5 * f * f - 2.0 * f, -1.5 * f * f + f + 0.5, 0.5 * f * f}};
}

}  // namespace arcwheel::processing
