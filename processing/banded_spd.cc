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
  ForwardPass pass;
  InverseQuadraticFormRows(b, pass);
  return pass.sum;
}

void BandedSpd::InverseQuadraticFormRows(std::span<double> block, ForwardPass& pass) const {
  const std::size_t first = pass.next_row;
  // Row k of L^{-1} b: in this block, or among the three carried from the one before.
  const auto solved = [&](std::size_t k) {
    return k >= first ? block[k - first] : pass.previous[k + kBand - first];
  };
  for (std::size_t r = 0; r < block.size(); ++r) {
    const std::size_t i = first + r;
    const std::size_t k0 = i >= kBand ? i - kBand : 0;
    for (std::size_t k = k0; k < i; ++k) block[r] -= a_[k][i - k] * solved(k);
    pass.sum += block[r] * block[r] / a_[i][0];
  }
  const std::size_t end = first + block.size();
  std::array<double, kBand> carried{};
  for (std::size_t j = 0; j < kBand; ++j) {
    if (end + j >= kBand) carried[j] = solved(end + j - kBand);
  }
  pass.previous = carried;
  pass.next_row = end;
}

void BandedSpd::ComputeSelectedInverse() {
  z_.assign(n_, {0.0, 0.0, 0.0, 0.0});
  SelectedInverseRows(0, n_, z_, 0);
}

void BandedSpd::SweepSelectedInverse(std::size_t block_rows,
                                     const std::function<void(const InverseBlock&)>& visit) const {
  block_rows = std::max<std::size_t>(1, std::min(block_rows, n_));
  BandRows rows(std::min(n_, block_rows + kBand), {0.0, 0.0, 0.0, 0.0});
  for (std::size_t end = n_; end > 0;) {
    const std::size_t first = end > block_rows ? end - block_rows : 0;
    // The rows [end, end + 3) that the recurrence reads sat at the start of the previous block;
    // they move up to follow this one (backwards: the two ranges may overlap).
    const std::size_t carried = std::min<std::size_t>(kBand, n_ - end);
    for (std::size_t r = carried; r-- > 0;) rows[end - first + r] = rows[r];
    SelectedInverseRows(first, end, rows, first);
    visit(InverseBlock{first, end, &rows});
    end = first;
  }
}

void BandedSpd::SelectedInverseRows(std::size_t first, std::size_t end, BandRows& z_rows,
                                    std::size_t z_first) const {
  // Z = A^{-1} satisfies Z = D^{-1} L^{-1} + (I - L^T) Z; within the band this needs only
  // band entries of Z below row j (Takahashi et al.).
  const auto z = [&](std::size_t i, std::size_t j) {
    return i <= j ? z_rows[i - z_first][j - i] : z_rows[j - z_first][i - j];
  };
  for (std::size_t j = end; j-- > first;) {
    const std::size_t last = std::min(n_ - 1, j + kBand);
    auto& row = z_rows[j - z_first];
    for (std::size_t i = last; i > j; --i) {
      double s = 0.0;
      for (std::size_t k = j + 1; k <= last; ++k) s -= a_[j][k - j] * z(k, i);
      row[i - j] = s;
    }
    double s = 1.0 / a_[j][0];
    for (std::size_t k = j + 1; k <= last; ++k) s -= a_[j][k - j] * row[k - j];
    row[0] = s;
  }
}

}  // namespace arcwheel::processing
