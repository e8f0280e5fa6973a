#include "processing/cubic_interpolation.h"

#include <algorithm>

#include "core/check.h"

namespace arcwheel::processing {

NaturalCubicSpline::NaturalCubicSpline(std::span<const double> x, std::span<const double> y)
    : x_(x.begin(), x.end()), y_(y.begin(), y.end()), second_(x.size(), 0.0) {
  ARCWHEEL_CHECK(x.size() == y.size() && x.size() >= 2) << "spline needs two or more points";
  const std::size_t n = x_.size();
  if (n < 3) return;
  // Tridiagonal system for the interior second derivatives (Thomas algorithm).
  std::vector<double> diagonal(n, 0.0);
  std::vector<double> rhs(n, 0.0);
  for (std::size_t i = 1; i + 1 < n; ++i) {
    const double h0 = x_[i] - x_[i - 1];
    const double h1 = x_[i + 1] - x_[i];
    diagonal[i] = 2.0 * (h0 + h1);
    rhs[i] = 6.0 * ((y_[i + 1] - y_[i]) / h1 - (y_[i] - y_[i - 1]) / h0);
    if (i > 1) {
      const double factor = h0 / diagonal[i - 1];
      diagonal[i] -= factor * h0;
      rhs[i] -= factor * rhs[i - 1];
    }
  }
  for (std::size_t i = n - 2; i >= 1; --i) {
    const double h1 = x_[i + 1] - x_[i];
    second_[i] = (rhs[i] - h1 * second_[i + 1]) / diagonal[i];
  }
}

std::size_t NaturalCubicSpline::Interval(double x) const {
  const auto it = std::upper_bound(x_.begin(), x_.end(), x);
  const auto index = static_cast<std::size_t>(std::max<long>(1, it - x_.begin()));
  return std::min(index, x_.size() - 1) - 1;
}

double NaturalCubicSpline::operator()(double x) const {
  const std::size_t i = Interval(x);
  const double h = x_[i + 1] - x_[i];
  const double a = (x_[i + 1] - x) / h;
  const double b = (x - x_[i]) / h;
  return a * y_[i] + b * y_[i + 1] +
         ((a * a * a - a) * second_[i] + (b * b * b - b) * second_[i + 1]) * h * h / 6.0;
}

}  // namespace arcwheel::processing
