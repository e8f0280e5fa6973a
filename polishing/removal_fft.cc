#include "polishing/removal_fft.h"

#include <fftw3.h>
#if defined(__linux__)
#include <sys/mman.h>
#endif

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <utility>

#include "core/check.h"
#include "core/fftw_planner.h"
#include "core/parallel.h"

namespace arcwheel::polishing::internal {
namespace {

// The workspace's workers: every core from kParallelElements cells (the threads are kept for the
// solve, so only their wake-up is paid per pass), else the calling thread alone.
int Workers(std::size_t cells) { return cells >= kParallelElements ? WorkerCount(0) : 1; }

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

void ForEachBlock(std::size_t n,
                  const std::function<void(std::size_t begin, std::size_t end, int block)>& pass,
                  WorkerPool* pool) {
  const auto run = [n, &pass](int block) {
    const std::size_t begin = n * static_cast<std::size_t>(block) / kPassBlocks;
    const std::size_t end = n * static_cast<std::size_t>(block + 1) / kPassBlocks;
    if (begin < end) pass(begin, end, block);
  };
  if (n < kParallelElements) {
    for (int block = 0; block < kPassBlocks; ++block) run(block);
    return;
  }
  const int workers = std::min(pool != nullptr ? pool->Workers() : WorkerCount(0), kPassBlocks);
  const auto share = [&run, workers](int worker) {
    for (int block = worker; block < kPassBlocks; block += workers) run(block);
  };
  if (pool != nullptr && workers == pool->Workers()) {
    pool->Run(share);
  } else {
    RunOnWorkers(workers, share);
  }
}

namespace {

// Zero-filled memory straight from the kernel, for the workspace's arrays. On a million-cell grid
// they come to some 40 MB, and first touching them a 4 kB page at a time costs ~10 us a page on a
// virtual machine, ~0.1 s a solve; asked for 2 MB pages (transparent huge pages, where the kernel
// has them), it takes a few ms.
class ZeroedPages {
 public:
  explicit ZeroedPages(std::size_t bytes) {
#if defined(__linux__)
    constexpr std::size_t kHugePage = std::size_t{2} << 20;
    length_ = bytes + kHugePage;
    void* base = mmap(nullptr, length_, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    ARCWHEEL_CHECK(base != MAP_FAILED) << bytes << " bytes";
    base_ = base;
    const auto start = (reinterpret_cast<std::uintptr_t>(base) + kHugePage - 1) & ~(kHugePage - 1);
    data_ = reinterpret_cast<void*>(start);
#if defined(MADV_HUGEPAGE)
    madvise(data_, bytes, MADV_HUGEPAGE);  // a hint: without it, 4 kB pages
#endif
#else
    base_ = data_ = std::calloc(bytes, 1);
    ARCWHEEL_CHECK(base_ != nullptr) << bytes << " bytes";
#endif
  }
  ~ZeroedPages() {
#if defined(__linux__)
    munmap(base_, length_);
#else
    std::free(base_);
#endif
  }
  ZeroedPages(const ZeroedPages&) = delete;
  ZeroedPages& operator=(const ZeroedPages&) = delete;
  [[nodiscard]] char* data() const { return static_cast<char*>(data_); }

 private:
  void* base_ = nullptr;
  void* data_ = nullptr;
  std::size_t length_ = 0;
};

// Bytes rounded up to whole cache lines (past SIMD alignment): each array starts on one.
constexpr std::size_t Lines(std::size_t bytes) { return (bytes + 63) / 64 * 64; }

// Grid rows per row plan; half-spectrum columns per column block. A column block of the spectrum
// (rows x 8 complex values, 128 kB for 1024 rows) stays in a core's L2 cache through its
// transforms and the product between them.
constexpr int kRowBlock = 8;
constexpr int kColumnBlock = 8;

// Complex values per row of a row block's buffer: the columns / 2 + 1 of a half spectrum's row,
// padded to whole 64-byte lines.
int BufferStride(int columns) { return (columns / 2 + 1 + 3) / 4 * 4; }

// work(index, worker) for index = 0 .. count - 1, each worker taking an equal run of indices.
template <class Work>
void ForEachIndex(int count, WorkerPool& pool, const Work& work) {
  const int workers = pool.Workers();
  if (workers <= 1) {
    for (int index = 0; index < count; ++index) work(index, 0);
    return;
  }
  pool.Run([&work, count, workers](int worker) {
    const int first = count * worker / workers, last = count * (worker + 1) / workers;
    for (int index = first; index < last; ++index) work(index, worker);
  });
}

// The 2-D transforms between a real rows x columns grid and its half spectrum (columns / 2 + 1
// complex columns), made of 1-D FFTW plans. The spectrum is stored by column blocks: block b
// (columns c0 = kColumnBlock b .. c0 + width - 1) holds row j's values at c0 rows + j width + (c -
// c0), the block's columns side by side. A row block's transform goes to a small buffer and from
// there into every column block, kRowBlock x width values in one run; a column block is then
// transformed where it lies, with the convolution's product between its forward and inverse
// transforms while it is in cache. FFTW_ESTIMATE's 2-D plan transforms the columns in place at the
// stride of a row (a forward and inverse pair of a 1024 x 1024 grid on two threads: 5.3 ms, where
// FFTW_MEASURE's plan, copying eight columns at a time into a buffer, takes 2.8 ms but 0.9 s to
// plan). The row and column blocks are shared out to the workers; a block's arithmetic does not
// depend on which worker runs it, so the result is the same for any number of cores. The plans
// are FFTW_ESTIMATE plans of fixed shapes: the same plans, hence the same rounding, on every run.
class GridTransforms {
 public:
  // For the workspace's 64-byte-aligned `grid` and `spectrum` (rows x (columns / 2 + 1) complex
  // values) and one row buffer of kRowBlock x BufferStride(columns) complex values per worker of
  // `pool` in `buffers`. Every grid transformed must be aligned as `grid` (FFTW's new-array
  // execution).
  GridTransforms(int rows, int columns, WorkerPool& pool, double* grid, fftw_complex* spectrum,
                 fftw_complex* buffers)
      : rows_(rows),
        columns_(columns),
        half_(columns / 2 + 1),
        stride_(BufferStride(columns)),
        pool_(pool),
        grid_(grid),
        spectrum_(spectrum),
        buffers_(buffers) {
    const FftwPlanner planner(1);
    const int n[] = {columns};
    const auto row_plans = [&](int block, fftw_plan& forward, fftw_plan& inverse) {
      if (block == 0) return;
      forward = fftw_plan_many_dft_r2c(1, n, block, grid, nullptr, 1, columns, buffers, nullptr, 1, stride_,
                                       FFTW_ESTIMATE | FFTW_PRESERVE_INPUT);
      inverse = fftw_plan_many_dft_c2r(1, n, block, buffers, nullptr, 1, stride_, grid, nullptr, 1, columns,
                                       FFTW_ESTIMATE);
      ARCWHEEL_CHECK(forward != nullptr && inverse != nullptr) << "row plans of " << columns;
    };
    row_plans(kRowBlock, row_forward_[0], row_inverse_[0]);
    row_plans(rows % kRowBlock, row_forward_[1], row_inverse_[1]);
    const int m[] = {rows};
    const auto column_plans = [&](int width, fftw_plan& forward, fftw_plan& inverse) {
      if (width == 0) return;
      forward = fftw_plan_many_dft(1, m, width, spectrum, nullptr, width, 1, spectrum, nullptr, width, 1,
                                   FFTW_FORWARD, FFTW_ESTIMATE);
      inverse = fftw_plan_many_dft(1, m, width, spectrum, nullptr, width, 1, spectrum, nullptr, width, 1,
                                   FFTW_BACKWARD, FFTW_ESTIMATE);
      ARCWHEEL_CHECK(forward != nullptr && inverse != nullptr) << "column plans of " << rows;
    };
    column_plans(kColumnBlock, column_forward_[0], column_inverse_[0]);
    column_plans(half_ % kColumnBlock, column_forward_[1], column_inverse_[1]);
  }
  ~GridTransforms() {
    const FftwPlanner planner;
    for (fftw_plan* plans : {row_forward_, row_inverse_, column_forward_, column_inverse_}) {
      for (int k = 0; k < 2; ++k) {
        if (plans[k] != nullptr) fftw_destroy_plan(plans[k]);
      }
    }
  }
  GridTransforms(const GridTransforms&) = delete;
  GridTransforms& operator=(const GridTransforms&) = delete;

  // spectrum = the half spectrum of `input`.
  void Forward(const double* input) const {
    RowsForward(input);
    Columns([this](fftw_complex* block, std::size_t, int width) { Execute(column_forward_, width, block); });
  }
  // grid = the unnormalised inverse of the spectrum, which it overwrites.
  void Inverse() const {
    Columns([this](fftw_complex* block, std::size_t, int width) { Execute(column_inverse_, width, block); });
    RowsInverse();
  }
  // grid = the unnormalised inverse of the half spectrum of `input` with each value z at index k
  // of the stored spectrum replaced by multiply(z, k); overwrites the spectrum.
  template <class Multiply>
  void Filter(const double* input, const Multiply& multiply) const {
    RowsForward(input);
    Columns([this, &multiply](fftw_complex* block, std::size_t first, int width) {
      Execute(column_forward_, width, block);
      const std::size_t values = static_cast<std::size_t>(rows_) * width;
      double* z = &block[0][0];
      for (std::size_t k = 0; k < values; ++k) multiply(z + 2 * k, first + k);
      Execute(column_inverse_, width, block);
    });
    RowsInverse();
  }

 private:
  void Execute(const fftw_plan (&plans)[2], int width, fftw_complex* block) const {
    fftw_execute_dft(plans[width == kColumnBlock ? 0 : 1], block, block);
  }
  [[nodiscard]] int RowBlocks() const { return (rows_ + kRowBlock - 1) / kRowBlock; }
  [[nodiscard]] int ColumnBlocks() const { return (half_ + kColumnBlock - 1) / kColumnBlock; }
  // Rows j0 .. j0 + count - 1 between the worker's row buffer and the column blocks.
  template <bool kToBlocks>
  void Shuffle(fftw_complex* buffer, int j0, int count) const {
    for (int b = 0; b < ColumnBlocks(); ++b) {
      const int c0 = b * kColumnBlock, width = std::min(kColumnBlock, half_ - c0);
      double* block =
          &spectrum_[static_cast<std::size_t>(c0) * rows_ + static_cast<std::size_t>(j0) * width][0];
      for (int r = 0; r < count; ++r) {
        double* row = &buffer[static_cast<std::size_t>(r) * stride_ + c0][0];
        double* run = block + 2 * static_cast<std::size_t>(r) * width;
        if (width == kColumnBlock) {
          for (int k = 0; k < 2 * kColumnBlock; ++k)
            (kToBlocks ? run[k] : row[k]) = (kToBlocks ? row[k] : run[k]);
        } else {
          for (int k = 0; k < 2 * width; ++k) (kToBlocks ? run[k] : row[k]) = (kToBlocks ? row[k] : run[k]);
        }
      }
    }
  }
  void RowsForward(const double* input) const {
    ForEachIndex(RowBlocks(), pool_, [this, input](int block, int worker) {
      const int j0 = block * kRowBlock, count = std::min(kRowBlock, rows_ - j0);
      fftw_complex* buffer = buffers_ + static_cast<std::size_t>(worker) * kRowBlock * stride_;
      // FFTW takes the input through the plan's pointer type; it keeps it (FFTW_PRESERVE_INPUT).
      fftw_execute_dft_r2c(row_forward_[count == kRowBlock ? 0 : 1],
                           const_cast<double*>(input) + static_cast<std::size_t>(j0) * columns_, buffer);
      Shuffle<true>(buffer, j0, count);
    });
  }
  void RowsInverse() const {
    ForEachIndex(RowBlocks(), pool_, [this](int block, int worker) {
      const int j0 = block * kRowBlock, count = std::min(kRowBlock, rows_ - j0);
      fftw_complex* buffer = buffers_ + static_cast<std::size_t>(worker) * kRowBlock * stride_;
      Shuffle<false>(buffer, j0, count);
      fftw_execute_dft_c2r(row_inverse_[count == kRowBlock ? 0 : 1], buffer,
                           grid_ + static_cast<std::size_t>(j0) * columns_);
    });
  }
  // work(block, index of its first value, width) on each column block.
  template <class Work>
  void Columns(const Work& work) const {
    ForEachIndex(ColumnBlocks(), pool_, [this, &work](int block, int) {
      const int c0 = block * kColumnBlock, width = std::min(kColumnBlock, half_ - c0);
      const std::size_t first = static_cast<std::size_t>(c0) * rows_;
      work(spectrum_ + first, first, width);
    });
  }

  int rows_, columns_, half_, stride_;
  WorkerPool& pool_;
  double* grid_;
  fftw_complex* spectrum_;
  fftw_complex* buffers_;
  fftw_plan row_forward_[2] = {}, row_inverse_[2] = {};        // kRowBlock rows, the rows left over
  fftw_plan column_forward_[2] = {}, column_inverse_[2] = {};  // kColumnBlock columns, the rest
};

}  // namespace

// Real grids, a half spectrum and the transforms between them. The point and row grids keep zeros
// outside their cells, so a product writes its values there and transforms from there (the
// forward transforms keep their input) with no clearing pass.
struct FftRemoval::Workspace {
  int rows = 0, columns = 0, workers = 1;
  WorkerPool pool;
  ZeroedPages pages;
  double* grid = nullptr;        // the transforms' output, and the input of the filters
  double* point_grid = nullptr;  // the dwell at the point cells
  double* row_grid = nullptr;    // the row values at the row cells
  fftw_complex* spectrum = nullptr;
  std::complex<double>* kernel = nullptr;   // the removal function's spectrum, scaled by 1 / size
  std::complex<double>* support = nullptr;  // its support's, for the entry count (Make)
  // For the extended inverse filter, the row each cell takes its value from (-1: none), found on
  // its first call.
  int* nearest_row = nullptr;
  bool nearest_found = false;
  // The row grid holds the residual that Residual wrote to this vector's data (nullptr: none).
  const double* placed_residual = nullptr;
  std::optional<GridTransforms> transforms;

  Workspace(int r, int c)
      : rows(r),
        columns(c),
        workers(Workers(Cells())),
        pool(workers),
        pages(3 * Lines(Cells() * sizeof(double)) + 3 * Lines(SpectrumSize() * sizeof(fftw_complex)) +
              Lines(Cells() * sizeof(int)) +
              Lines(static_cast<std::size_t>(workers) * kRowBlock * BufferStride(c) * sizeof(fftw_complex))) {
    char* next = pages.data();
    const auto take = [&next](std::size_t bytes) {
      char* at = next;
      next += Lines(bytes);
      return at;
    };
    grid = reinterpret_cast<double*>(take(Cells() * sizeof(double)));
    point_grid = reinterpret_cast<double*>(take(Cells() * sizeof(double)));
    row_grid = reinterpret_cast<double*>(take(Cells() * sizeof(double)));
    spectrum = reinterpret_cast<fftw_complex*>(take(SpectrumSize() * sizeof(fftw_complex)));
    kernel = reinterpret_cast<std::complex<double>*>(take(SpectrumSize() * sizeof(fftw_complex)));
    support = reinterpret_cast<std::complex<double>*>(take(SpectrumSize() * sizeof(fftw_complex)));
    nearest_row = reinterpret_cast<int*>(take(Cells() * sizeof(int)));
    auto* buffers = reinterpret_cast<fftw_complex*>(
        take(static_cast<std::size_t>(workers) * kRowBlock * BufferStride(c) * sizeof(fftw_complex)));
    transforms.emplace(r, c, pool, grid, spectrum, buffers);
  }
  Workspace(const Workspace&) = delete;
  Workspace& operator=(const Workspace&) = delete;

  [[nodiscard]] std::size_t Cells() const { return static_cast<std::size_t>(rows) * columns; }
  // Complex values of the stored half spectrum.
  [[nodiscard]] std::size_t SpectrumSize() const {
    return static_cast<std::size_t>(rows) * (columns / 2 + 1);
  }
  [[nodiscard]] std::complex<double>* Spectrum() const {
    return reinterpret_cast<std::complex<double>*>(spectrum);
  }
};

namespace {

// True when some cell appears more than once; `marks` is a cleared grid, left marked.
bool SharesCells(const std::vector<int>& cells, double* marks) {
  for (const int c : cells) {
    if (marks[c] != 0.0) return true;
    marks[c] = 1.0;
  }
  return false;
}

}  // namespace

std::optional<FftRemoval> FftRemoval::Make(const ErrorMap& map, std::span<const int> row_nodes,
                                           std::span<const Eigen::Vector2d> path_xy_mm,
                                           const RemovalFunction& removal) {
  if (path_xy_mm.empty()) return std::nullopt;
  FftRemoval f;
  // The points' grid indices: i in the cell list (turned into cells below), j aside.
  std::vector<int> point_j;
  f.point_cell_.reserve(path_xy_mm.size());
  point_j.reserve(path_xy_mm.size());
  for (const Eigen::Vector2d& p : path_xy_mm) {
    const std::optional<int> i = GridIndex(p.x(), map.grid.x0_mm, map.grid.dx_mm);
    const std::optional<int> j = GridIndex(p.y(), map.grid.y0_mm, map.grid.dy_mm);
    if (!i || !j) return std::nullopt;
    f.point_cell_.push_back(*i);
    point_j.push_back(*j);
  }
  std::vector<int>& point_i = f.point_cell_;
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
  for (std::size_t k = 0; k < point_j.size(); ++k) f.point_cell_[k] = cell(point_i[k], point_j[k]);
  for (const int node : row_nodes) f.row_cell_.push_back(cell(node % map.grid.nx, node / map.grid.nx));
  f.points_share_cells_ = SharesCells(f.point_cell_, f.ClearedGrid());
  f.rows_share_cells_ = SharesCells(f.row_cell_, f.ClearedGrid());

  // The kernel with offset (0, 0) at cell (0, 0), negative offsets wrapped to the far end; and its
  // support in the (still clear) row grid, for the entry count.
  auto wrap = [](int v, int n) { return (v % n + n) % n; };
  double* support = w.row_grid;
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
  const double scale = 1.0 / static_cast<double>(w.Cells());  // the inverse is unnormalised
  w.transforms->Forward(w.grid);
  for (std::size_t k = 0; k < w.SpectrumSize(); ++k) w.kernel[k] = w.Spectrum()[k] * scale;

  // The sparse matrix's entry count: for each row node, the points whose footprint covers it.
  w.transforms->Forward(support);
  std::fill(support, support + w.Cells(), 0.0);
  std::complex<double>* support_spectrum = w.support;
  std::copy(w.Spectrum(), w.Spectrum() + w.SpectrumSize(), support_spectrum);
  double* points = f.ClearedGrid();
  for (const int c : f.point_cell_) points[c] += 1.0;
  w.transforms->Filter(points, [support_spectrum, scale](double* z, std::size_t k) {
    const std::complex<double> product = std::complex<double>(z[0], z[1]) * (support_spectrum[k] * scale);
    z[0] = product.real();
    z[1] = product.imag();
  });
  for (const int c : f.row_cell_) f.nonzeros_ += std::lround(w.grid[c]);
  return f;
}

void FftRemoval::Convolve(const double* input, bool correlate) const {
  Workspace& w = *work_;
  // Written out: std::complex's operator* checks every product for NaN (C99 Annex G) and keeps
  // the loop from vectorising; the spectra are finite, and the arithmetic is the same.
  const double* kernel = reinterpret_cast<const double*>(w.kernel);
  const double sign = correlate ? -1.0 : 1.0;  // A^T: the kernel's complex conjugate
  w.transforms->Filter(input, [kernel, sign](double* z, std::size_t k) {
    const double a = z[0], b = z[1], c = kernel[2 * k], d = sign * kernel[2 * k + 1];
    z[0] = a * c - b * d;
    z[1] = a * d + b * c;
  });
}

namespace {

// `values` into their cells of `grid`, whose other cells hold 0. Where cells repeat, the grid is
// cleared and the values added in order.
const double* Place(double* grid, std::size_t grid_cells, const std::vector<int>& cell, bool shared,
                    const Eigen::VectorXd& values, WorkerPool& pool) {
  if (shared) {
    std::fill(grid, grid + grid_cells, 0.0);
    for (std::size_t k = 0; k < cell.size(); ++k) grid[cell[k]] += values[static_cast<Eigen::Index>(k)];
    return grid;
  }
  const int* c = cell.data();
  ForEachBlock(
      cell.size(),
      [grid, c, &values](std::size_t begin, std::size_t end, int) {
        for (std::size_t k = begin; k < end; ++k) grid[c[k]] = values[static_cast<Eigen::Index>(k)];
      },
      &pool);
  return grid;
}

// out[k] = grid[cell[k]].
void Gather(const double* grid, const std::vector<int>& cell, Eigen::VectorXd& out, WorkerPool& pool) {
  out.resize(static_cast<Eigen::Index>(cell.size()));
  const int* c = cell.data();
  ForEachBlock(
      cell.size(),
      [grid, c, &out](std::size_t begin, std::size_t end, int) {
        for (std::size_t k = begin; k < end; ++k) out[static_cast<Eigen::Index>(k)] = grid[c[k]];
      },
      &pool);
}

}  // namespace

WorkerPool* FftRemoval::Pool() const { return &work_->pool; }

double FftRemoval::NormSquaredBound() const {
  const Workspace& w = *work_;
  const double n = static_cast<double>(w.Cells());  // the stored spectrum is scaled by 1 / n
  double most = 0.0;
  for (std::size_t k = 0; k < w.SpectrumSize(); ++k) most = std::max(most, std::norm(w.kernel[k]));
  return most * n * n;
}

Eigen::VectorXd FftRemoval::InverseFilter(const Eigen::VectorXd& rows, double relative_damping,
                                          bool extend) const {
  Eigen::VectorXd dwell;
  InverseFilter(rows, relative_damping, extend, dwell);
  return dwell;
}

void FftRemoval::InverseFilter(const Eigen::VectorXd& rows, double relative_damping, bool extend,
                               Eigen::VectorXd& dwell_s) const {
  ARCWHEEL_CHECK(rows.size() == static_cast<Eigen::Index>(row_cell_.size())) << rows.size();
  Workspace& w = *work_;
  double* cells = w.grid;
  if (extend) {
    // Breadth-first from the row cells over the (non-periodic) grid: each cell takes the value of
    // the row cell it is reached from, its nearest in steps. The same cells every time: found on
    // the first call.
    if (!w.nearest_found) {
      int* nearest = w.nearest_row;
      std::fill(nearest, nearest + w.Cells(), -1);
      std::vector<int> queue;
      queue.reserve(w.Cells());
      for (std::size_t r = 0; r < row_cell_.size(); ++r) {
        if (nearest[row_cell_[r]] < 0) queue.push_back(row_cell_[r]);
        nearest[row_cell_[r]] = static_cast<int>(r);  // rows in one cell: the last one's value
      }
      for (std::size_t head = 0; head < queue.size(); ++head) {
        const int c = queue[head], i = c % columns_, j = c / columns_;
        for (const auto& [di, dj] : {std::pair{1, 0}, std::pair{-1, 0}, std::pair{0, 1}, std::pair{0, -1}}) {
          const int ni = i + di, nj = j + dj;
          if (ni < 0 || nj < 0 || ni >= columns_ || nj >= rows_) continue;
          const int n = nj * columns_ + ni;
          if (nearest[n] >= 0) continue;
          nearest[n] = nearest[c];
          queue.push_back(n);
        }
      }
      w.nearest_found = true;
    }
    const int* nearest = w.nearest_row;
    ForEachBlock(
        w.Cells(),
        [cells, nearest, &rows](std::size_t begin, std::size_t end, int) {
          for (std::size_t c = begin; c < end; ++c) cells[c] = nearest[c] >= 0 ? rows[nearest[c]] : 0.0;
        },
        &w.pool);
  } else {
    std::fill(cells, cells + w.Cells(), 0.0);
    for (std::size_t r = 0; r < row_cell_.size(); ++r)
      cells[row_cell_[r]] = rows[static_cast<Eigen::Index>(r)];
  }
  const double n = static_cast<double>(w.Cells());
  const double damping = relative_damping * relative_damping * NormSquaredBound();
  const double* kernel = reinterpret_cast<const double*>(w.kernel);
  // z *= conj(K) / ((|K|^2 + damping) n), K the kernel's own spectrum, written out (see Convolve).
  w.transforms->Filter(cells, [kernel, n, damping](double* z, std::size_t k) {
    const double kr = kernel[2 * k] * n, ki = kernel[2 * k + 1] * n;
    const double q = (kr * kr + ki * ki + damping) * n;
    const double c = kr / q, d = -ki / q;
    const double a = z[0], b = z[1];
    z[0] = a * c - b * d;
    z[1] = a * d + b * c;
  });
  Gather(cells, point_cell_, dwell_s, w.pool);
}

double* FftRemoval::ClearedGrid() const {
  std::fill(work_->grid, work_->grid + work_->Cells(), 0.0);
  return work_->grid;
}

const double* FftRemoval::PointGrid(const Eigen::VectorXd& values) const {
  return Place(work_->point_grid, work_->Cells(), point_cell_, points_share_cells_, values, work_->pool);
}

const double* FftRemoval::RowGrid(const Eigen::VectorXd& values) const {
  work_->placed_residual = nullptr;
  return Place(work_->row_grid, work_->Cells(), row_cell_, rows_share_cells_, values, work_->pool);
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
  Convolve(PointGrid(dwell_s), false);
  Gather(work_->grid, row_cell_, rows, work_->pool);
}

void FftRemoval::ApplyTranspose(const Eigen::VectorXd& rows, Eigen::VectorXd& dwell_s) const {
  ARCWHEEL_CHECK(rows.size() == static_cast<Eigen::Index>(row_cell_.size())) << rows.size();
  Convolve(RowGrid(rows), true);
  Gather(work_->grid, point_cell_, dwell_s, work_->pool);
}

double FftRemoval::Residual(const Eigen::VectorXd& dwell_s, const Eigen::VectorXd& target,
                            Eigen::VectorXd& residual) const {
  ARCWHEEL_CHECK(dwell_s.size() == static_cast<Eigen::Index>(point_cell_.size())) << dwell_s.size();
  ARCWHEEL_CHECK(target.size() == static_cast<Eigen::Index>(row_cell_.size())) << target.size();
  Workspace& w = *work_;
  Convolve(PointGrid(dwell_s), false);
  residual.resize(target.size());
  const double* grid = w.grid;
  double* row_grid = w.row_grid;
  const int* cell = row_cell_.data();
  const bool place = !rows_share_cells_;  // else the cells' values add up: RowGrid places them
  std::array<double, kPassBlocks> squares{};
  ForEachBlock(
      row_cell_.size(),
      [&](std::size_t begin, std::size_t end, int block) {
        for (std::size_t r = begin; r < end; ++r) {
          const auto i = static_cast<Eigen::Index>(r);
          const double value = grid[cell[r]] - target[i];
          residual[i] = value;
          if (place) row_grid[cell[r]] = value;
        }
        // Its block still in cache; Eigen's sum vectorises.
        squares[static_cast<std::size_t>(block)] =
            residual.segment(static_cast<Eigen::Index>(begin), static_cast<Eigen::Index>(end - begin))
                .squaredNorm();
      },
      &w.pool);
  w.placed_residual = place ? residual.data() : nullptr;
  double sum = 0.0;
  for (const double s : squares) sum += s;
  return std::sqrt(sum);
}

void FftRemoval::GradientOfResidual(const Eigen::VectorXd& residual, Eigen::VectorXd& dwell_s) const {
  Workspace& w = *work_;
  if (w.placed_residual == nullptr || w.placed_residual != residual.data()) {
    ApplyTranspose(residual, dwell_s);
    return;
  }
  Convolve(w.row_grid, true);
  Gather(w.grid, point_cell_, dwell_s, w.pool);
}

}  // namespace arcwheel::polishing::internal
