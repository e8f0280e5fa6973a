#include "processing/banded_spd.h"

#include <algorithm>

namespace arcwheel::processing {

bool BandedSpd::Factorize() {
  // Column-oriented LDL^T restricted to the band.
  for (std::size_t j = 0; j < n_; ++j) {
    double d = a_[j][0];
    const std::size_t k0 = j >= kBand ? j - kBand : 0;
    for (std::size_t k = k0; k < j; ++k) {
      const double l_jk = a_[k][j - k];
      d -= l_jk * l_jk * a_[k][0];
    }
    if (!(d > 0.0)) return false;
    a_[j][0] = d;
    for (std::size_t i = j + 1; i <= std::min(n_ - 1, j + kBand); ++i) {
      double s = a_[j][i - j];
      const std::size_t m0 = i >= kBand ? i - kBand : 0;
      for (std::size_t k = std::max(k0, m0); k < j; ++k) s -= a_[k][i - k] * a_[k][j - k] * a_[k][0];
      a_[j][i - j] = s / d;
    }
  }
  return true;
}

void BandedSpd::Solve(std::vector<double>& b) const {
  for (std::size_t i = 0; i < n_; ++i) {
    const std::size_t k0 = i >= kBand ? i - kBand : 0;
    for (std::size_t k = k0; k < i; ++k) b[i] -= a_[k][i - k] * b[k];
  }
  for (std::size_t i = 0; i < n_; ++i) b[i] /= a_[i][0];
  for (std::size_t i = n_; i-- > 0;) {
    for (std::size_t k = i + 1; k <= std::min(n_ - 1, i + kBand); ++k) b[i] -= a_[i][k - i] * b[k];
  }
}

double BandedSpd::InverseQuadraticForm(std::vector<double>& b) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < n_; ++i) {
    const std::size_t k0 = i >= kBand ? i - kBand : 0;
    for (std::size_t k = k0; k < i; ++k) b[i] -= a_[k][i - k] * b[k];
    sum += b[i] * b[i] / a_[i][0];
  }
  return sum;
}

void BandedSpd::ComputeSelectedInverse() {
  // Z = A^{-1} satisfies Z = D^{-1} L^{-1} + (I - L^T) Z; within the band this needs only
  // band entries of Z below row j (Takahashi et al.).
  z_.assign(n_, {0.0, 0.0, 0.0, 0.0});
  const auto z = [&](std::size_t i, std::size_t j) { return i <= j ? z_[i][j - i] : z_[j][i - j]; };
  for (std::size_t j = n_; j-- > 0;) {
    const std::size_t last = std::min(n_ - 1, j + kBand);
    for (std::size_t i = last; i > j; --i) {
      double s = 0.0;
      for (std::size_t k = j + 1; k <= last; ++k) s -= a_[j][k - j] * z(k, i);
      z_[j][i - j] = s;
    }
    double s = 1.0 / a_[j][0];
    for (std::size_t k = j + 1; k <= last; ++k) s -= a_[j][k - j] * z_[j][k - j];
    z_[j][0] = s;
  }
}

}  // namespace arcwheel::processing
