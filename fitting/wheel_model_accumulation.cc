// The wheel model's passes over the samples: J^T J, J^T r and r^T r at a set of coefficients,
// over every sample or a subsample, and the residuals' sums per cell of the map's grid.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/nan.h"
#include "core/parallel.h"
#include "fitting/wheel_model_impl.h"
#include "processing/helix_geometry.h"

namespace arcwheel::fitting::internal {
namespace {

std::size_t RunStart(std::size_t run, std::size_t stride) {
  // splitmix64's finaliser: a fixed, well-spread place in each run.
  std::uint64_t z = run + 0x9e3779b97f4a7c15ULL;
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  z ^= z >> 31;
  return run * stride + static_cast<std::size_t>(z % stride);
}

}  // namespace

// The axial cells that a part's samples between low_y_mm and high_y_mm can fall into.
CellSums CellSumsFor(const Grid& grid, double low_y_mm, double high_y_mm) {
  CellSums cells;
  if (!(low_y_mm <= high_y_mm)) return cells;
  const long last = static_cast<long>(grid.n_y) - 1;
  cells.first_axial =
      std::clamp(processing::RoundHalfAway((low_y_mm - grid.y0_mm) / grid.y_step_mm), 0L, last);
  const long high =
      std::clamp(processing::RoundHalfAway((high_y_mm - grid.y0_mm) / grid.y_step_mm), 0L, last);
  cells.axial_cells = high - cells.first_axial + 1;
  cells.sum.assign(grid.n_phase * static_cast<std::size_t>(cells.axial_cells), 0.0);
  cells.count.assign(cells.sum.size(), 0);
  return cells;
}

namespace {

// One part's share of a pass.
template <typename Sample>
void AccumulatePart(const Samples<Sample>& samples, const RowModel& model, const PassRequest& request,
                    int part, NormalEquations& normal, CellSums* cells, double& low_y_mm, double& high_y_mm) {
  const std::size_t total = samples.rho_mm.size();
  const std::size_t runs = (total + request.stride - 1) / request.stride;
  const std::size_t begin = runs * static_cast<std::size_t>(part) / kParts;
  const std::size_t end = runs * static_cast<std::size_t>(part + 1) / kParts;
  const processing::HelixGeometry& geometry = samples.geometry;
  BlockAccumulator block(model, normal, request.normal_matrix);
  Row row;
  // Locals, not the references, so that the loop keeps them in registers.
  double rss = 0.0, low = std::numeric_limits<double>::infinity(), high = -low;
  std::size_t used = 0;
  const double per_phase_cell = request.grid != nullptr ? 1.0 / request.grid->phase_step_deg : 0.0;
  const double per_axial_cell = request.grid != nullptr ? 1.0 / request.grid->y_step_mm : 0.0;
  for (std::size_t run = begin; run < end; ++run) {
    const std::size_t i = request.stride == 1 ? run : RunStart(run, request.stride);
    if (i >= total) continue;
    const auto rho = static_cast<double>(samples.rho_mm[i]);
    if (!std::isfinite(rho)) continue;
    const double y = geometry.AxialAt(i);
    if (y < samples.band_low_mm || y > samples.band_high_mm) continue;
    low = std::min(low, y);
    high = std::max(high, y);
    const double c = processing::PhaseInTurn(geometry.PhaseAt(i));
    if (!model.Evaluate(c, y, rho, row)) continue;
    block.Add(row);
    rss += row.residual * row.residual;
    ++used;
    if (cells == nullptr || cells->axial_cells == 0) continue;
    const Grid& grid = *request.grid;
    auto p = static_cast<std::size_t>(processing::RoundHalfAway(c * per_phase_cell));
    if (p >= grid.n_phase) p -= grid.n_phase;  // c rounds up to the turn's end
    const long a = processing::RoundHalfAway((y - grid.y0_mm) * per_axial_cell) - cells->first_axial;
    if (a < 0 || a >= cells->axial_cells) continue;
    const std::size_t cell = p * static_cast<std::size_t>(cells->axial_cells) + static_cast<std::size_t>(a);
    cells->sum[cell] += row.residual;
    ++cells->count[cell];
  }
  normal.rss += rss;
  normal.samples += used;
  low_y_mm = low;
  high_y_mm = high;
}

}  // namespace

// One pass over the samples on every core. With a grid, each part sums the residuals over the
// axial range that `previous` (a pass over the same samples) found its samples in.
template <typename Sample>
PassResult Accumulate(const Samples<Sample>& samples, const Layout& layout, const VectorXd& theta,
                      const PassRequest& request, const PartRanges* previous) {
  ARCWHEEL_CHECK(request.grid == nullptr || previous != nullptr) << "a residual map needs the parts' ranges";
  ARCWHEEL_CHECK(samples.cells == nullptr || (request.grid == nullptr && request.stride == 1))
      << "the cells make neither a residual map nor a subsample";
  const int n = layout.size();
  const RowModel model(layout, theta);
  std::vector<NormalEquations> parts(kParts);
  PassResult result;
  if (request.grid != nullptr && !request.grid->empty()) {
    for (int part = 0; part < kParts; ++part) {
      const auto p = static_cast<std::size_t>(part);
      result.cells.push_back(CellSumsFor(*request.grid, previous->low_y_mm[p], previous->high_y_mm[p]));
    }
  }
  const int workers = std::min(WorkerCount(0), kParts);
  RunOnWorkers(workers, [&](int worker) {
    for (int part = worker; part < kParts; part += workers) {
      const auto p = static_cast<std::size_t>(part);
      NormalEquations& normal = parts[p];
      if (request.normal_matrix) normal.jtj = MatrixXd::Zero(n, n);
      normal.jtr = VectorXd::Zero(n);
      if (samples.cells != nullptr) {
        AccumulateCellsPart(samples.cells->parts[p], samples.geometry, model, normal, request.normal_matrix);
        continue;
      }
      AccumulatePart(samples, model, request, part, normal, result.cells.empty() ? nullptr : &result.cells[p],
                     result.ranges.low_y_mm[p], result.ranges.high_y_mm[p]);
    }
  });
  if (samples.cells != nullptr) result.ranges = samples.cells->ranges;
  result.normal = std::move(parts[0]);
  for (std::size_t part = 1; part < parts.size(); ++part) result.normal.Add(parts[part]);
  result.normal.Symmetrise();
  return result;
}

// Mean residual per cell of the map's grid (um), NaN where no sample fell.
std::vector<double> ResidualMap(const Grid& grid, const std::vector<CellSums>& parts) {
  if (grid.empty()) return {};
  std::vector<double> sum(grid.size(), 0.0);
  std::vector<std::uint32_t> count(grid.size(),
                                   0);  // as CellSums::count: a cell holds fewer than 2^32 samples
  for (const CellSums& part : parts) {
    for (std::size_t p = 0; p < grid.n_phase; ++p) {
      for (long a = 0; a < part.axial_cells; ++a) {
        const std::size_t from = p * static_cast<std::size_t>(part.axial_cells) + static_cast<std::size_t>(a);
        const std::size_t to = p * grid.n_y + static_cast<std::size_t>(part.first_axial + a);
        sum[to] += part.sum[from];
        count[to] += part.count[from];
      }
    }
  }
  for (std::size_t cell = 0; cell < sum.size(); ++cell) {
    sum[cell] = count[cell] > 0 ? sum[cell] / static_cast<double>(count[cell]) * 1e3 : kNaN;
  }
  return sum;
}

template PassResult Accumulate(const Samples<double>& samples, const Layout& layout, const VectorXd& theta,
                               const PassRequest& request, const PartRanges* previous);
template PassResult Accumulate(const Samples<float>& samples, const Layout& layout, const VectorXd& theta,
                               const PassRequest& request, const PartRanges* previous);

}  // namespace arcwheel::fitting::internal
