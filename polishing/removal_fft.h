#pragma once
// The dwell solve's removal products as 2-D FFT convolutions (dwell.h, "FFT products").
//
// The removal at map node n is  sum_k R(X_n - P_k) t_k.  When every dwell point P_k lies on a node
// of the map's grid (extended beyond the map as far as the path goes), X_n - P_k is a whole number
// of grid steps, so the sum is the 2-D convolution of the removal function sampled at those steps
// with the dwell placed on the grid: the same products as the sparse removal matrix, computed with
// FFTW in O(N log N) instead of O(N x footprint). Transforms of 2^16 cells or more run on every
// core, their rows and column blocks shared out (removal_fft.cc, GridTransforms). The removal
// function is the same at every point (it is defined in the part's (x, y) projection), so the
// convolution holds over the whole part, curved or not. A point counts as on the grid when it
// lies within kGridTolerance of a grid step from a node; the kernel is sampled at the exact steps,
// so such a point's removal differs from the sparse matrix's by at most that shift times the
// rate's slope (1e-9 of the step: below 1e-9 of the peak rate over the footprint, for a footprint
// wider than one step).

#include <Eigen/Core>
#include <cstddef>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <vector>

#include "core/parallel.h"
#include "polishing/removal_function.h"
#include "polishing/removal_target.h"

namespace arcwheel::polishing::internal {

// Largest distance of a dwell point from a grid node, in grid steps, for the FFT products.
inline constexpr double kGridTolerance = 1e-9;

// The solve's element-wise passes over its vectors (a million points: memory-bound, and as many
// as the transforms' time when run on one core) split [0, n) into kPassBlocks blocks and run
// pass(begin, end, block) on each, on every core once n reaches kParallelElements. The blocks do
// not depend on the core count: sums formed per block and added in block order come out the same
// on every machine. With a pool, its workers run the blocks (FftRemoval::Pool).
inline constexpr int kPassBlocks = 16;
inline constexpr std::size_t kParallelElements = std::size_t{1} << 16;
void ForEachBlock(std::size_t n,
                  const std::function<void(std::size_t begin, std::size_t end, int block)>& pass,
                  WorkerPool* pool = nullptr);

class FftRemoval {
 public:
  // The products for the map nodes `row_nodes` (indices j * nx + i into `map`) and the dwell points
  // `path_xy_mm`; nothing when a point lies off the map's grid, or when the rate jumps within the
  // grid tolerance of a sampled offset (a table's edge or the Gaussian's truncation circle on the
  // grid: there the sparse matrix's entries depend on the rounding of each point's coordinates).
  [[nodiscard]] static std::optional<FftRemoval> Make(const ErrorMap& map, std::span<const int> row_nodes,
                                                      std::span<const Eigen::Vector2d> path_xy_mm,
                                                      const RemovalFunction& removal);
  // Removal (um) at the row nodes for a dwell (s) per point: A t.
  [[nodiscard]] Eigen::VectorXd Apply(const Eigen::VectorXd& dwell_s) const;
  // A^T r: for each point, the sum over the row nodes of the rate times r.
  [[nodiscard]] Eigen::VectorXd ApplyTranspose(const Eigen::VectorXd& rows) const;
  // The same into vectors the caller keeps (resized if need be): no allocation per product.
  void Apply(const Eigen::VectorXd& dwell_s, Eigen::VectorXd& rows) const;
  void ApplyTranspose(const Eigen::VectorXd& rows, Eigen::VectorXd& dwell_s) const;
  // residual = A t - target, in the same pass as its norm, which it returns; the same pass places
  // it on the row cells for GradientOfResidual.
  double Residual(const Eigen::VectorXd& dwell_s, const Eigen::VectorXd& target,
                  Eigen::VectorXd& residual) const;
  // A^T residual, for the residual the last Residual call wrote (and unchanged since): the
  // least-squares gradient, from the placed residual. Any other vector is placed afresh.
  void GradientOfResidual(const Eigen::VectorXd& residual, Eigen::VectorXd& dwell_s) const;
  // Entries of the sparse matrix that these products stand for: (row, point) pairs with a rate > 0.
  [[nodiscard]] long Nonzeros() const { return nonzeros_; }
  // The workers that run the products' transforms and passes, kept for the solve (one on a grid
  // below 2^16 cells), for the solve's own passes (ForEachBlock).
  [[nodiscard]] WorkerPool* Pool() const;
  // An upper bound of ||A||^2, the largest eigenvalue of A^T A: the largest |spectrum|^2 of the
  // kernel (A is the circular convolution between two restrictions, which cannot lengthen a
  // vector). The Lipschitz constant of the least-squares gradient, without power iterations.
  [[nodiscard]] double NormSquaredBound() const;
  // The row values placed on the FFT grid, filtered by the kernel's damped inverse,
  // conj(K) / (|K|^2 + mu) with mu = (relative_damping max |K|)^2, and read at the points
  // (RIFTA-style inverse filtering, Wang et al. 2020). With `extend`, every other cell first takes
  // the value of its nearest row cell (a flat extension beyond the aperture, which the dwell
  // points outside it need): a dwell that nearly solves A t = rows without bounds. Without, the
  // other cells stay 0: then it is M A^T rows, M the damped inverse of the kernel's power
  // spectrum, a preconditioned gradient of the least-squares problem.
  [[nodiscard]] Eigen::VectorXd InverseFilter(const Eigen::VectorXd& rows, double relative_damping,
                                              bool extend = true) const;
  // The same into a vector the caller keeps.
  void InverseFilter(const Eigen::VectorXd& rows, double relative_damping, bool extend,
                     Eigen::VectorXd& dwell_s) const;

 private:
  struct Workspace;  // FFTW plans and arrays
  FftRemoval() = default;
  // `input` (a grid of the workspace) convolved with the removal function, or correlated with it
  // (A^T), into the work grid.
  void Convolve(const double* input, bool correlate) const;
  [[nodiscard]] double* ClearedGrid() const;
  // The grid that holds the dwell at the point cells (0 elsewhere), or the row values at the row
  // cells, filled from `values`.
  [[nodiscard]] const double* PointGrid(const Eigen::VectorXd& values) const;
  [[nodiscard]] const double* RowGrid(const Eigen::VectorXd& values) const;

  int origin_i_ = 0, origin_j_ = 0;  // map index of FFT cell (0, 0)
  std::vector<int> row_cell_;        // FFT cell of each row node
  std::vector<int> point_cell_;      // FFT cell of each dwell point
  bool points_share_cells_ = false;  // two or more points in one cell: their dwells add up
  bool rows_share_cells_ = false;
  int rows_ = 0, columns_ = 0;  // FFT size
  long nonzeros_ = 0;
  std::shared_ptr<Workspace> work_;  // one FftRemoval serves one thread at a time
};

}  // namespace arcwheel::polishing::internal
