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
#include <functional>
#include <span>
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
  // The same forward pass over b in blocks of consecutive rows, first row 0, so that b need not
  // be held whole: each call takes rows [first, first + block.size()) and carries the sum and the
  // last rows of L^{-1} b to the next. `sum` after the last block is that of InverseQuadraticForm.
  struct ForwardPass {
    std::size_t next_row = 0;                 // the first row of the next block
    double sum = 0.0;                         // sum_i (L^{-1} b)_i^2 / D_i over the rows so far
    std::array<double, kBand> previous = {};  // (L^{-1} b) at rows next_row - 3 .. next_row - 1
  };
  void InverseQuadraticFormRows(std::span<double> block, ForwardPass& pass) const;
  using BandRows = std::vector<std::array<double, kBand + 1>>;
  // Entries of A^{-1} within the band, after Factorize: Inverse(i, j) for |i - j| <= 3.
  void ComputeSelectedInverse();
  [[nodiscard]] double Inverse(std::size_t i, std::size_t j) const {
    return i <= j ? z_[i][j - i] : z_[j][i - j];
  }
  [[nodiscard]] bool HasSelectedInverse() const { return z_.size() == n_; }
  // Inverse(i, i + d) for d = 0..3.
  [[nodiscard]] double InverseInBand(std::size_t i, int d) const {
    return z_[i][static_cast<std::size_t>(d)];
  }

  // Rows of the selected inverse that SweepSelectedInverse has computed: InverseInBand(i, d) for
  // first <= i < min(size(), end + 3).
  struct InverseBlock {
    std::size_t first = 0, end = 0;
    const BandRows* rows = nullptr;  // rows[i - first] = row i
    [[nodiscard]] double InverseInBand(std::size_t i, int d) const {
      return (*rows)[i - first][static_cast<std::size_t>(d)];
    }
  };
  // The selected inverse in blocks of at most `block_rows` rows, from the last row down, calling
  // visit(block) after each, without holding it whole (23 MB for a 1e8-sample spline). The numbers
  // are those of ComputeSelectedInverse.
  void SweepSelectedInverse(std::size_t block_rows,
                            const std::function<void(const InverseBlock&)>& visit) const;

 private:
  std::size_t n_;
  // a_[i][d] = A(i, i + d) before Factorize; after it, a_[i][0] = D(i) and
  // a_[i][d] = L(i + d, i) for d = 1..3.
  std::vector<std::array<double, kBand + 1>> a_;
  BandRows z_;  // z_[i][d] = Inverse(i, i + d)
  // Rows [first, end) of the selected inverse into z[row - z_first], given rows [end, end + 3)
  // there (Takahashi et al.).
  void SelectedInverseRows(std::size_t first, std::size_t end, BandRows& z, std::size_t z_first) const;
};

}  // namespace arcwheel::processing
