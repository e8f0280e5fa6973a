#include "polishing/removal_fft.h"

#include <fftw3.h>

#include <algorithm>
#include <cmath>
#include <complex>
#include <cstdlib>
#include <utility>

#include "core/check.h"
#include "core/fftw_planner.h"
#include "core/parallel.h"

namespace arcwheel::polishing::internal {
namespace {

// Transforms of at least this many cells run on every core (FFTW's threads): below it, waking the
// threads costs more than they save.
constexpr std::size_t kThreadedCells = std::size_t{1} << 18;

int PlanThreads(std::size_t cells) { return cells >= kThreadedCells ? WorkerCount(0) : 1; }

// The whole number of steps from `origin` to `value`, if it lies within kGridTolerance of one.
std::optional<int> GridIndex(double value, double origin, double step) {
  const double u = (value - origin) / step;
  const double nearest = std::round(u);
  if (!(std::abs(u - nearest) <= kGridTolerance) || std::abs(nearest) > 1e8) return std::nullopt;
  return static_cast<int>(nearest);
}

struct Span {
  int first = 0, last = 0;  // whole grid steps
};

// The smallest length >= n with no prime factor above 7, where FFTW is fastest.
int FastLength(int n) {
  for (int m = std::max(n, 1);; ++m) {
    int rest = m;
    for (const int p : {2, 3, 5, 7}) {
      while (rest % p == 0) rest /= p;
    }
    if (rest == 1) return m;
  }
}

// FFT length along one axis: the cells from the first to the last index, plus room for the
// kernel's largest reach so that the circular convolution wraps nothing onto a cell in use.
int FftLength(int cells, const Span& kernel) {
  const int reach = std::max(std::abs(kernel.first), std::abs(kernel.last));
  return FastLength(std::max(cells + reach, kernel.last - kernel.first + 1));
}

// True when the rate at a sampled offset stays put within the grid tolerance around it. Where it
// jumps (on a table's edge, or on the Gaussian's truncation circle) the sparse matrix's entry
// depends on the rounding of each point's coordinates, so the products are left to it.
bool SteadyAround(const RemovalFunction& removal, double x_mm, double y_mm, double rate, double dx_mm,
                  double dy_mm) {
  const double ex = 2.0 * kGridTolerance * dx_mm, ey = 2.0 * kGridTolerance * dy_mm;
  const double jump = 1e-6 * removal.PeakRateUmPerS();
  for (const auto& [sx, sy] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
    if (std::abs(removal.RateUmPerS(x_mm + sx * ex, y_mm + sy * ey) - rate) > jump) return false;
  }
  return true;
}

}  // namespace

// A real grid, its half spectrum and the two plans between them. FFTW_ESTIMATE plans: the same
// plan, hence the same rounding, on every run (FFTW_MEASURE picks by timing).
struct FftRemoval::Workspace {
  int rows = 0, columns = 0;
  double* grid = nullptr;
  fftw_complex* spectrum = nullptr;
  std::vector<std::complex<double>> kernel;  // the removal function's spectrum, scaled by 1 / size
  fftw_plan forward = nullptr, inverse = nullptr;

  Workspace(int r, int c) : rows(r), columns(c) {
    const std::size_t cells = static_cast<std::size_t>(r) * c;
    const std::size_t half = static_cast<std::size_t>(r) * (c / 2 + 1);
    grid = fftw_alloc_real(cells);
    spectrum = fftw_alloc_complex(half);
    ARCWHEEL_CHECK(grid != nullptr && spectrum != nullptr) << "FFT arrays of " << r << " x " << c;
    const FftwPlanner planner(PlanThreads(cells));
    forward = fftw_plan_dft_r2c_2d(r, c, grid, spectrum, FFTW_ESTIMATE);
    inverse = fftw_plan_dft_c2r_2d(r, c, spectrum, grid, FFTW_ESTIMATE);
    ARCWHEEL_CHECK(forward != nullptr && inverse != nullptr) << "FFT plans of " << r << " x " << c;
  }
  ~Workspace() {
    {
      const FftwPlanner planner;
      fftw_destroy_plan(forward);
      fftw_destroy_plan(inverse);
    }
    fftw_free(grid);
    fftw_free(spectrum);
  }
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;

  [[nodiscard]] std::size_t Cells() const { return static_cast<std::size_t>(rows) * columns; }
  [[nodiscard]] std::size_t HalfCells() const { return static_cast<std::size_t>(rows) * (columns / 2 + 1); }
  [[nodiscard]] std::complex<double>* Spectrum() const {
    return reinterpret_cast<std::complex<double>*>(spectrum);
  }
  // The half spectrum of the grid as it is now.
  [[nodiscard]] std::vector<std::complex<double>> SpectrumOfGrid() const {
    fftw_execute(forward);
    return {Spectrum(), Spectrum() + HalfCells()};
  }
};

std::optional<FftRemoval> FftRemoval::Make(const ErrorMap& map, std::span<const int> row_nodes,
                                           std::span<const Eigen::Vector2d> path_xy_mm,
                                           const RemovalFunction& removal) {
  std::vector<int> point_i, point_j;
  point_i.reserve(path_xy_mm.size());
  point_j.reserve(path_xy_mm.size());
  for (const Eigen::Vector2d& p : path_xy_mm) {
    const std::optional<int> i = GridIndex(p.x(), map.grid.x0_mm, map.grid.dx_mm);
    const std::optional<int> j = GridIndex(p.y(), map.grid.y0_mm, map.grid.dy_mm);
    if (!i || !j) return std::nullopt;
    point_i.push_back(*i);
    point_j.push_back(*j);
  }
  if (point_i.empty()) return std::nullopt;
  FftRemoval f;
  f.origin_i_ = std::min(0, *std::min_element(point_i.begin(), point_i.end()));
  f.origin_j_ = std::min(0, *std::min_element(point_j.begin(), point_j.end()));
  const int cells_x =
      std::max(map.grid.nx - 1, *std::max_element(point_i.begin(), point_i.end())) - f.origin_i_ + 1;
  const int cells_y =
      std::max(map.grid.ny - 1, *std::max_element(point_j.begin(), point_j.end())) - f.origin_j_ + 1;
  // One step more each side than the footprint's box: the rate itself is zero outside it.
  const FootprintBox box = removal.Footprint();
  const Span kx{static_cast<int>(std::floor(box.min_x_mm / map.grid.dx_mm)) - 1,
                static_cast<int>(std::ceil(box.max_x_mm / map.grid.dx_mm)) + 1};
  const Span ky{static_cast<int>(std::floor(box.min_y_mm / map.grid.dy_mm)) - 1,
                static_cast<int>(std::ceil(box.max_y_mm / map.grid.dy_mm)) + 1};
  f.columns_ = FftLength(cells_x, kx);
  f.rows_ = FftLength(cells_y, ky);
  f.work_ = std::make_shared<Workspace>(f.rows_, f.columns_);
  Workspace& w = *f.work_;

  auto cell = [&f](int i, int j) { return (j - f.origin_j_) * f.columns_ + (i - f.origin_i_); };
  for (std::size_t k = 0; k < point_i.size(); ++k) f.point_cell_.push_back(cell(point_i[k], point_j[k]));
  for (const int node : row_nodes) f.row_cell_.push_back(cell(node % map.grid.nx, node / map.grid.nx));

  // The kernel with offset (0, 0) at cell (0, 0), negative offsets wrapped to the far end; and its
  // support, for the entry count.
  auto wrap = [](int v, int n) { return (v % n + n) % n; };
  std::vector<double> support(w.Cells(), 0.0);
  double* kernel = f.ClearedGrid();
  for (int b = ky.first; b <= ky.last; ++b) {
    for (int a = kx.first; a <= kx.last; ++a) {
      const double rate = removal.RateUmPerS(a * map.grid.dx_mm, b * map.grid.dy_mm);
      if (!SteadyAround(removal, a * map.grid.dx_mm, b * map.grid.dy_mm, rate, map.grid.dx_mm,
                        map.grid.dy_mm))
        return std::nullopt;
      if (!(rate > 0.0)) continue;
      const std::size_t c = static_cast<std::size_t>(wrap(b, f.rows_)) * f.columns_ + wrap(a, f.columns_);
      kernel[c] = rate;
      support[c] = 1.0;
    }
  }
  w.kernel = w.SpectrumOfGrid();
  const double scale = 1.0 / static_cast<double>(w.Cells());  // FFTW's inverse is unnormalised
  for (std::complex<double>& k : w.kernel) k *= scale;

  // The sparse matrix's entry count: for each row node, the points whose footprint covers it.
  std::copy(support.begin(), support.end(), f.ClearedGrid());
  const std::vector<std::complex<double>> support_spectrum = w.SpectrumOfGrid();
  double* points = f.ClearedGrid();
  for (const int c : f.point_cell_) points[c] += 1.0;
  fftw_execute(w.forward);
  std::complex<double>* spectrum = w.Spectrum();
  for (std::size_t k = 0; k < w.HalfCells(); ++k) spectrum[k] *= support_spectrum[k] * scale;
  fftw_execute(w.inverse);
  for (const int c : f.row_cell_) f.nonzeros_ += std::lround(w.grid[c]);
  return f;
}

void FftRemoval::Convolve(bool correlate) const {
  Workspace& w = *work_;
  fftw_execute(w.forward);
  // Written out: std::complex's operator* checks every product for NaN (C99 Annex G) and keeps
  // the loop from vectorising; the spectra are finite, and the arithmetic is the same.
  double* spectrum = &w.spectrum[0][0];
  const double* kernel = reinterpret_cast<const double*>(w.kernel.data());
  const double sign = correlate ? -1.0 : 1.0;  // A^T: the kernel's complex conjugate
  const std::size_t n = w.HalfCells();
  for (std::size_t k = 0; k < 2 * n; k += 2) {
    const double a = spectrum[k], b = spectrum[k + 1], c = kernel[k], d = sign * kernel[k + 1];
    spectrum[k] = a * c - b * d;
    spectrum[k + 1] = a * d + b * c;
  }
  fftw_execute(w.inverse);
}

double FftRemoval::NormSquaredBound() const {
  const Workspace& w = *work_;
  const double n = static_cast<double>(w.Cells());  // the stored spectrum is scaled by 1 / n
  double most = 0.0;
  for (const std::complex<double>& k : w.kernel) most = std::max(most, std::norm(k));
  return most * n * n;
}

Eigen::VectorXd FftRemoval::InverseFilter(const Eigen::VectorXd& rows, double relative_damping,
                                          bool extend) const {
  ARCWHEEL_CHECK(rows.size() == static_cast<Eigen::Index>(row_cell_.size())) << rows.size();
  Workspace& w = *work_;
  // Breadth-first from the row cells over the (non-periodic) grid: each cell takes the value of
  // the row cell it is reached from, its nearest in steps.
  std::vector<char> filled(w.Cells(), 0);
  std::vector<int> queue;
  queue.reserve(w.Cells());
  double* cells = ClearedGrid();
  for (std::size_t r = 0; r < row_cell_.size(); ++r) {
    cells[row_cell_[r]] = rows[static_cast<Eigen::Index>(r)];
    filled[static_cast<std::size_t>(row_cell_[r])] = 1;
    queue.push_back(row_cell_[r]);
  }
  if (!extend) queue.clear();
  for (std::size_t head = 0; head < queue.size(); ++head) {
    const int c = queue[head], i = c % columns_, j = c / columns_;
    for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
      const int ni = i + di, nj = j + dj;
      if (ni < 0 || nj < 0 || ni >= columns_ || nj >= rows_) continue;
      const int n = nj * columns_ + ni;
      if (filled[static_cast<std::size_t>(n)]) continue;
      filled[static_cast<std::size_t>(n)] = 1;
      cells[n] = cells[c];
      queue.push_back(n);
    }
  }
  fftw_execute(w.forward);
  const double n = static_cast<double>(w.Cells());
  const double damping = relative_damping * relative_damping * NormSquaredBound();
  std::complex<double>* spectrum = w.Spectrum();
  for (std::size_t k = 0; k < w.HalfCells(); ++k) {
    const std::complex<double> kernel = w.kernel[k] * n;  // the kernel's own spectrum
    spectrum[k] *= std::conj(kernel) / ((std::norm(kernel) + damping) * n);
  }
  fftw_execute(w.inverse);
  Eigen::VectorXd dwell(static_cast<Eigen::Index>(point_cell_.size()));
  for (std::size_t k = 0; k < point_cell_.size(); ++k)
    dwell[static_cast<Eigen::Index>(k)] = cells[point_cell_[k]];
  return dwell;
}

double* FftRemoval::ClearedGrid() const {
  std::fill(work_->grid, work_->grid + work_->Cells(), 0.0);
  return work_->grid;
}

Eigen::VectorXd FftRemoval::Apply(const Eigen::VectorXd& dwell_s) const {
  Eigen::VectorXd rows(static_cast<Eigen::Index>(row_cell_.size()));
  Apply(dwell_s, rows);
  return rows;
}

Eigen::VectorXd FftRemoval::ApplyTranspose(const Eigen::VectorXd& rows) const {
  Eigen::VectorXd dwell(static_cast<Eigen::Index>(point_cell_.size()));
  ApplyTranspose(rows, dwell);
  return dwell;
}

void FftRemoval::Apply(const Eigen::VectorXd& dwell_s, Eigen::VectorXd& rows) const {
  ARCWHEEL_CHECK(dwell_s.size() == static_cast<Eigen::Index>(point_cell_.size())) << dwell_s.size();
  rows.resize(static_cast<Eigen::Index>(row_cell_.size()));
  double* cells = ClearedGrid();
  for (std::size_t k = 0; k < point_cell_.size(); ++k)
    cells[point_cell_[k]] += dwell_s[static_cast<Eigen::Index>(k)];
  Convolve(false);
  for (std::size_t r = 0; r < row_cell_.size(); ++r) rows[static_cast<Eigen::Index>(r)] = cells[row_cell_[r]];
}

void FftRemoval::ApplyTranspose(const Eigen::VectorXd& rows, Eigen::VectorXd& dwell_s) const {
  ARCWHEEL_CHECK(rows.size() == static_cast<Eigen::Index>(row_cell_.size())) << rows.size();
  dwell_s.resize(static_cast<Eigen::Index>(point_cell_.size()));
  double* cells = ClearedGrid();
  for (std::size_t r = 0; r < row_cell_.size(); ++r)
    cells[row_cell_[r]] += rows[static_cast<Eigen::Index>(r)];
  Convolve(true);
  for (std::size_t k = 0; k < point_cell_.size(); ++k)
    dwell_s[static_cast<Eigen::Index>(k)] = cells[point_cell_[k]];
}

}  // namespace arcwheel::polishing::internal
