#pragma once
// A symmetric positive definite matrix with half-bandwidth 3 (the normal matrix of a
// least-squares cubic B-spline), its LDL^T factor, solves, and the selected inverse: the
// entries of the inverse inside the band (Takahashi, Fagan & Chen 1973), which give the
// variance of any spline value in O(n).
//
// Eigen has no banded solver, and LAPACK's dpbtrf has no selected inverse; the recurrences are
// a few lines each for a fixed bandwidth.

#include <array>
#include <cstddef>
#include <vector>

namespace arcwheel::processing {

class BandedSpd {
 public:
  static constexpr int kBand = 3;

  explicit BandedSpd(std::size_t n) : n_(n), a_(n) {}

  // Adds `value` to A(i, j) for |i - j| <= 3 (only i <= j is stored; pass i <= j).
  void Add(std::size_t i, std::size_t j, double value) { a_[i][j - i] += value; }
  [[nodiscard]] double Get(std::size_t i, std::size_t j) const {
    return i <= j ? a_[i][j - i] : a_[j][i - j];
  }
  [[nodiscard]] std::size_t size() const { return n_; }

  // Factorises A = L D L^T in place. Returns false if a pivot is not positive.
  [[nodiscard]] bool Factorize();
  // Solves A x = b (after Factorize) in place.
  void Solve(std::vector<double>& b) const;
  // b^T A^{-1} b (after Factorize) as sum_i (L^{-1} b)_i^2 / D_i: one forward pass in place,
  // which leaves b overwritten.
  [[nodiscard]] double InverseQuadraticForm(std::vector<double>& b) const;
  // Entries of A^{-1} within the band, after Factorize: Inverse(i, j) for |i - j| <= 3.
  void ComputeSelectedInverse();
  [[nodiscard]] double Inverse(std::size_t i, std::size_t j) const {
    return i <= j ? z_[i][j - i] : z_[j][i - j];
  }
  // Frees the selected inverse (Inverse and InverseInBand may not be called after).
  void ReleaseSelectedInverse() { z_ = {}; }
  [[nodiscard]] bool HasSelectedInverse() const { return z_.size() == n_; }
  // Inverse(i, i + d) for d = 0..3.
  [[nodiscard]] double InverseInBand(std::size_t i, int d) const {
    return z_[i][static_cast<std::size_t>(d)];
  }

 private:
  std::size_t n_;
  // a_[i][d] = A(i, i + d) before Factorize; after it, a_[i][0] = D(i) and
  // a_[i][d] = L(i + d, i) for d = 1..3.
  std::vector<std::array<double, kBand + 1>> a_;
  std::vector<std::array<double, kBand + 1>> z_;  // z_[i][d] = Inverse(i, i + d)
};

}  // namespace arcwheel::processing
