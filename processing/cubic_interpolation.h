#pragma once
// Natural cubic spline interpolation through (x_i, y_i), x strictly increasing.

#include <span>
#include <vector>

namespace arcwheel::processing {

class NaturalCubicSpline {
 public:
  NaturalCubicSpline(std::span<const double> x, std::span<const double> y);
  // Interpolated value; x outside [x_0, x_n-1] is extrapolated from the end cubic.
  [[nodiscard]] double operator()(double x) const;
  // Index i of the interval [x_i, x_i+1] that holds x (clamped to the ends).
  [[nodiscard]] std::size_t Interval(double x) const;

 private:
  std::vector<double> x_;
  std::vector<double> y_;
  std::vector<double> second_;  // second derivatives at the knots
};

}  // namespace arcwheel::processing
