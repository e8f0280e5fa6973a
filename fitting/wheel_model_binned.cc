// The wheel model's binned fit (docs/wheel_model.md, "Binned fit"): the samples into cells of
// three weighted points each, the passes over the cells, and the residual map against the model
// along each cell.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <numeric>
#include <utility>
#include <vector>

#include "core/check.h"
#include "core/parallel.h"
#include "fitting/wheel_model_impl.h"
#include "processing/helix_geometry.h"

namespace arcwheel::fitting::internal {
namespace {

// A cell ends at the turn's end, at every knot of the fine fit's functions and of a 64-knot grid
// (so that it spans at most 1/64 turn whatever the knots), and after this many samples.
constexpr std::uint64_t kMaxCellSpan = 4096;
constexpr int kCellsPerTurn = 64;

// The knot counts at whose knots cells end: kCellsPerTurn and those of the fine fit's functions
// that do not divide it.
std::vector<double> CellCutsPerDeg(const Layout& fine) {
  std::vector<double> per_deg = {kCellsPerTurn / 360.0};
  for (const int knots : {fine.radius.knots, fine.axial.knots, fine.runout.knots}) {
    if (knots > 1 && kCellsPerTurn % knots != 0) per_deg.push_back(knots / 360.0);
  }
  return per_deg;
}

// The sums of powers of a closed cell's sample positions about their mean, d.
struct CentralMoments {
  double n = 0, d2 = 0, d3 = 0, d4 = 0, d5 = 0;
};

// The three-point Gauss rule of positions with these central moments: nodes x (sorted) and
// weights w with sum w x^j = the samples' sum d^j for j = 0..5.
void GaussRule(const CentralMoments& m, std::array<double, 3>& x, std::array<double, 3>& w) {
  // In units of the positions' standard deviation: moments 1, 0, 1, m3, m4, m5 per sample.
  const double sigma = std::sqrt(m.d2 / m.n);
  const double m3 = m.d3 / (m.n * sigma * sigma * sigma), m4 = m.d4 / (m.n * std::pow(sigma, 4)),
               m5 = m.d5 / (m.n * std::pow(sigma, 5));
  // The monic cubic orthogonal to 1, x and x^2 under the samples' positions: x^3 + a x^2 + b x + c.
  Eigen::Matrix3d hankel;
  hankel << 1.0, 0.0, 1.0, 0.0, 1.0, m3, 1.0, m3, m4;
  const Eigen::Vector3d cba = hankel.partialPivLu().solve(Eigen::Vector3d(-m3, -m4, -m5));
  const double c = cba[0], b = cba[1], a = cba[2];
  // Its three real roots (trigonometric form of the depressed cubic t^3 + p t + q).
  const double p = b - a * a / 3.0, q = 2.0 * a * a * a / 27.0 - a * b / 3.0 + c;
  const double r = 2.0 * std::sqrt(std::max(-p / 3.0, 0.0));
  const double cos3 = r > 0.0 ? std::clamp(3.0 * q / (p * r), -1.0, 1.0) : 0.0;
  const double theta = std::acos(cos3) / 3.0;
  for (std::size_t k = 0; k < 3; ++k) {
    x[k] = r * std::cos(theta - 2.0 * std::numbers::pi * static_cast<double>(k) / 3.0) - a / 3.0;
  }
  std::sort(x.begin(), x.end());
  // Powers as products: pow() per entry cost a fifth of a cell's closing.
  Eigen::Matrix3d vandermonde;
  for (int k = 0; k < 3; ++k) {
    const double xk = x[static_cast<std::size_t>(k)];
    vandermonde.col(k) << 1.0, xk, xk * xk;
  }
  const Eigen::Vector3d weights = vandermonde.partialPivLu().solve(Eigen::Vector3d(m.n, 0.0, m.n));
  for (std::size_t k = 0; k < 3; ++k) {
    w[k] = weights[static_cast<Eigen::Index>(k)];
    x[k] *= sigma;
  }
}

// The part of a cell's closing that depends on its samples' positions alone: their central moments,
// the Gauss rule and its Vandermonde matrix. A cell without gaps (every sample of first..last
// valid) has positions 0..n-1 about the same centre, so this is a function of its count, and the
// cells of a turn mostly share their count: a part keeps the last one (the same operations on the
// same positions, so the same bits).
struct PositionRule {
  double n = 0, center = 0;  // the cell it was made for; n = 0: none yet
  CentralMoments moments;
  std::array<double, 3> x{}, w{};
  Eigen::PartialPivLU<Eigen::Matrix3d> vandermonde;
};

// The positions' moments, rule and matrix of a cell of n samples about `center`, for
// `position_of(k)` the k-th valid sample's index - first.
template <typename PositionOf>
void MakePositionRule(double n, double center, const PositionOf& position_of, PositionRule& rule) {
  rule.n = n;
  rule.center = center;
  rule.moments = CentralMoments{};
  rule.moments.n = n;
  const auto count = static_cast<std::size_t>(n);
  for (std::size_t k = 0; k < count; ++k) {
    const double d = position_of(k) - center;
    const double d2 = d * d;
    rule.moments.d2 += d2;
    rule.moments.d3 += d2 * d;
    rule.moments.d4 += d2 * d2;
    rule.moments.d5 += d2 * d2 * d;
  }
  GaussRule(rule.moments, rule.x, rule.w);
  Eigen::Matrix3d vandermonde;
  for (int k = 0; k < 3; ++k) {
    const double xk = rule.x[static_cast<std::size_t>(k)];
    vandermonde.col(k) << 1.0, xk, xk * xk;
  }
  rule.vandermonde.compute(vandermonde);
}

// A cell of the valid samples first..last (all in the band; n of them, their positions summing
// to sum_s and their z to sum_z_mm), from a second look at its samples (still in cache). `rule`:
// the part's last position rule, reused when the cell has no gaps and the same count.
template <typename Sample>
HelixCell CloseCell(const Samples<Sample>& samples, std::uint64_t first, std::uint64_t last, double n,
                    double sum_s, double sum_z_mm, PositionRule& rule) {
  HelixCell cell;
  cell.first = first;
  cell.count = static_cast<std::uint32_t>(n);
  const double center = sum_s / n;
  cell.z_mean_mm = sum_z_mm / n;
  const auto rho_at = [&](std::uint64_t i) { return static_cast<double>(samples.rho_mm[i]); };
  if (n <= 3.0) {  // a cell of up to three samples keeps them as its points
    std::size_t seen = 0;
    for (std::uint64_t i = first; i <= last; ++i) {
      if (!std::isfinite(rho_at(i))) continue;
      cell.node[seen] = static_cast<float>(i - first);
      cell.weight[seen] = 1.0f;
      cell.value_mm[seen] = static_cast<float>(rho_at(i) - cell.z_mean_mm);
      ++seen;
    }
    return cell;
  }
  const bool gapless = static_cast<double>(last - first + 1) == n;
  if (!gapless) {
    std::vector<double> positions;
    positions.reserve(static_cast<std::size_t>(n));
    for (std::uint64_t i = first; i <= last; ++i) {
      if (std::isfinite(rho_at(i))) positions.push_back(static_cast<double>(i - first));
    }
    MakePositionRule(
        n, center, [&](std::size_t k) { return positions[k]; }, rule);
    rule.n = 0;  // made for this cell's gaps: not one to reuse
  } else if (rule.n != n || rule.center != center) {
    MakePositionRule(
        n, center, [](std::size_t k) { return static_cast<double>(k); }, rule);
  }
  double zd = 0.0, zd2 = 0.0, z2 = 0.0;
  for (std::uint64_t i = first; i <= last; ++i) {
    const double rho = rho_at(i);
    if (!gapless && !std::isfinite(rho)) continue;
    const double d = static_cast<double>(i - first) - center, e = rho - cell.z_mean_mm;
    const double d2 = d * d;
    zd += e * d;
    zd2 += e * d2;
    z2 += e * e;
  }
  // Pseudo-values v / w: sum v = 0 (about the mean), sum v x = sum (z - mean) d, sum v x^2 =
  // sum (z - mean) d^2.
  const Eigen::Vector3d v = rule.vandermonde.solve(Eigen::Vector3d(0.0, zd, zd2));
  double carried = 0.0;
  for (std::size_t k = 0; k < 3; ++k) {
    const double vk = v[static_cast<Eigen::Index>(k)];
    cell.node[k] = static_cast<float>(center + rule.x[k]);
    cell.weight[k] = static_cast<float>(rule.w[k]);
    cell.value_mm[k] = static_cast<float>(vk / rule.w[k]);
    carried += vk * vk / rule.w[k];
  }
  cell.rss_offset_mm2 = static_cast<float>(z2 - carried);
  return cell;
}

// The samples of begin..end in the band, as an index range: on a helix from the settings the
// axial position is monotonic in the index (each operation of AxialAt rounds monotonically), so
// the band holds a run of them, found by bisection with the same test as a pass over each sample.
template <typename Sample>
std::pair<std::size_t, std::size_t> BandRun(const Samples<Sample>& samples, std::size_t begin,
                                            std::size_t end) {
  if (begin >= end) return {begin, begin};
  const processing::HelixGeometry& geometry = samples.geometry;
  const auto below = [&](std::size_t i) { return geometry.AxialAt(i) < samples.band_low_mm; };
  const auto above = [&](std::size_t i) { return geometry.AxialAt(i) > samples.band_high_mm; };
  // The first index in begin..end where `test` holds, for a test that holds from some index on.
  const auto first_where = [&](const auto& test) {
    std::size_t low = begin, high = end;
    while (low < high) {
      const std::size_t mid = low + (high - low) / 2;
      if (test(mid)) {
        high = mid;
      } else {
        low = mid + 1;
      }
    }
    return low;
  };
  const bool rising = geometry.AxialAt(end - 1) >= geometry.AxialAt(begin);
  const std::size_t first = rising ? first_where([&](std::size_t i) { return !below(i); })
                                   : first_where([&](std::size_t i) { return !above(i); });
  const std::size_t last = rising ? first_where(above) : first_where(below);
  return {first, std::max(first, last)};
}

// The index after `i` at which the next cell begins: the first sample past the next knot of any
// cut (the phase is linear in the index), at most kMaxCellSpan on.
std::size_t CellEnd(const processing::HelixGeometry& geometry, const std::vector<double>& cuts_per_deg,
                    std::size_t i) {
  const double deg_per_sample = geometry.PhaseAtIndex(1.0) - geometry.PhaseAtIndex(0.0);
  std::size_t end = i + kMaxCellSpan;
  if (deg_per_sample == 0.0) return end;
  const double phase = geometry.PhaseAtIndex(static_cast<double>(i));
  for (const double per_deg : cuts_per_deg) {
    const double knot = std::floor(phase * per_deg) + (deg_per_sample > 0.0 ? 1.0 : 0.0);
    const double at = std::ceil((knot / per_deg - phase) / deg_per_sample);
    if (at >= 1.0 && at < static_cast<double>(kMaxCellSpan))
      end = std::min(end, i + static_cast<std::size_t>(at));
  }
  return std::max(end, i + 1);
}

// One part's samples into cells: the binned fit's one pass before the residual map's.
template <typename Sample>
void BinPart(const Samples<Sample>& samples, const std::vector<double>& cuts_per_deg, int part,
             std::vector<HelixCell>& cells, double& low_y_mm, double& high_y_mm) {
  const std::size_t total = samples.rho_mm.size();
  const auto [begin, end] = BandRun(samples, total * static_cast<std::size_t>(part) / kParts,
                                    total * static_cast<std::size_t>(part + 1) / kParts);
  const processing::HelixGeometry& geometry = samples.geometry;
  if (begin < end) {  // a cell per cut per turn, and per kMaxCellSpan samples
    const double turns = std::abs(geometry.PhaseAt(end - 1) - geometry.PhaseAt(begin)) / 360.0 + 1.0;
    const double cuts = 360.0 * std::accumulate(cuts_per_deg.begin(), cuts_per_deg.end(), 0.0);
    cells.reserve(static_cast<std::size_t>(
        std::min(turns * cuts + static_cast<double>((end - begin) / kMaxCellSpan) + 1.0,
                 static_cast<double>(end - begin))));
  }
  double low = std::numeric_limits<double>::infinity(), high = -low;
  PositionRule rule;
  for (std::size_t from = begin; from < end;) {
    const std::size_t to = std::min(CellEnd(geometry, cuts_per_deg, from), end);
    double n = 0.0, sum_s = 0.0, sum_z = 0.0;
    std::size_t first = to, last = to;
    for (std::size_t i = from; i < to; ++i) {
      const auto rho = static_cast<double>(samples.rho_mm[i]);
      if (!std::isfinite(rho)) continue;
      if (n == 0.0) first = i;
      last = i;
      n += 1.0;
      sum_s += static_cast<double>(i - first);
      sum_z += rho;
    }
    if (n > 0.0) {
      cells.push_back(CloseCell(samples, first, last, n, sum_s, sum_z, rule));
      for (const std::size_t i : {first, last}) {
        low = std::min(low, geometry.AxialAt(i));
        high = std::max(high, geometry.AxialAt(i));
      }
    }
    from = to;
  }
  low_y_mm = low;
  high_y_mm = high;
}

}  // namespace

template <typename Sample>
HelixCells BinSamples(const Samples<Sample>& samples, const Layout& fine) {
  HelixCells cells;
  const std::vector<double> cuts_per_deg = CellCutsPerDeg(fine);
  ARCWHEEL_CHECK(cuts_per_deg.size() <= 4) << cuts_per_deg.size();
  const int workers = std::min(WorkerCount(0), kParts);
  RunOnWorkers(workers, [&](int worker) {
    for (int part = worker; part < kParts; part += workers) {
      const auto p = static_cast<std::size_t>(part);
      BinPart(samples, cuts_per_deg, part, cells.parts[p], cells.ranges.low_y_mm[p],
              cells.ranges.high_y_mm[p]);
    }
  });
  return cells;
}

// One part's cells as weighted points: J^T J, J^T r and r^T r of its samples, exact where the
// model is quadratic along each cell. The points' rows are scaled by the root of their weights.
void AccumulateCellsPart(const std::vector<HelixCell>& cells, const processing::HelixGeometry& geometry,
                         const RowModel& model, NormalEquations& normal, bool normal_matrix) {
  BlockAccumulator block(model, normal, normal_matrix);
  double rss = 0.0;
  std::size_t used = 0;
  std::array<Row, 3> rows;
  for (const HelixCell& cell : cells) {
    const std::size_t points = cell.points();
    const auto base = static_cast<double>(cell.first);
    bool inside = true;
    for (std::size_t k = 0; k < points && inside; ++k) {
      const double at = base + cell.node[k];
      const double c = processing::PhaseInTurn(geometry.PhaseAtIndex(at));
      inside = model.Evaluate(c, geometry.AxialAtIndex(at), cell.z_mean_mm + cell.value_mm[k], rows[k]);
    }
    if (!inside) continue;
    for (std::size_t k = 0; k < points; ++k) {
      Row& row = rows[k];
      const double root = std::sqrt(static_cast<double>(cell.weight[k]));
      for (double& value : row.value) value *= root;
      row.residual *= root;
      block.Add(row);
      rss += row.residual * row.residual;
    }
    rss += cell.rss_offset_mm2;
    used += cell.count;
  }
  normal.rss += rss;
  normal.samples += used;
}

namespace {

// The model along the samples first..last of a helix cell (at most 1/64 turn): the cubic through
// its values at four Chebyshev points of the span (at the samples themselves when there are no
// more than four), whose error, of the model's fourth derivative along the cell, is some 1e-5 um
// on a lobed wheel. Valid is false where a point lies beyond the arc.
struct SpanModel {
  std::array<double, 4> x{}, c{};  // the points (sample indices) and Newton's coefficients
  std::size_t points = 0;
  bool valid = true;
  SpanModel(const RowModel& model, const processing::HelixGeometry& geometry, std::size_t first,
            std::size_t last) {
    points = std::min<std::size_t>(last - first + 1, 4);
    const double mid = 0.5 * static_cast<double>(first + last),
                 half = 0.5 * static_cast<double>(last - first);
    Row row;
    for (std::size_t k = 0; k < points; ++k) {
      x[k] = points < 4 || last - first < 4
                 ? static_cast<double>(first + k)
                 : mid + half * std::cos((2.0 * static_cast<double>(k) + 1.0) * std::numbers::pi / 8.0);
      const double phase = processing::PhaseInTurn(geometry.PhaseAtIndex(x[k]));
      valid = valid && model.Evaluate(phase, geometry.AxialAtIndex(x[k]), 0.0, row);
      c[k] = -row.residual;
    }
    for (std::size_t j = 1; j < points; ++j) {  // divided differences
      for (std::size_t k = points - 1; k >= j; --k) c[k] = (c[k] - c[k - 1]) / (x[k] - x[k - j]);
    }
  }
  [[nodiscard]] double At(double index) const {
    double value = c[points - 1];
    for (std::size_t k = points - 1; k-- > 0;) value = c[k] + (index - x[k]) * value;
    return value;
  }
};

// One part's residuals per cell of the map's grid. Within a helix cell (its samples run to the
// next cell's first) the phase and the axial position are monotonic in the index, so its samples
// fall into the map's cells in runs: each run's end is predicted from the rates and checked with
// the per-sample rule (found by bisection where the guess was off), and its residuals are summed
// against the model along the cell (SpanModel).
template <typename Sample>
void CellResidualsPart(const Samples<Sample>& samples, const std::vector<HelixCell>& cells,
                       const RowModel& model, const Grid& grid, int part, CellSums& sums) {
  if (sums.axial_cells == 0 || cells.empty()) return;
  const std::size_t total = samples.rho_mm.size();
  const std::size_t end = BandRun(samples, total * static_cast<std::size_t>(part) / kParts,
                                  total * static_cast<std::size_t>(part + 1) / kParts)
                              .second;
  const processing::HelixGeometry& geometry = samples.geometry;
  const double per_phase_cell = 1.0 / grid.phase_step_deg, per_axial_cell = 1.0 / grid.y_step_mm;
  // Map cells per sample along the phase and the axis.
  const double phase_rate = (geometry.PhaseAtIndex(1.0) - geometry.PhaseAtIndex(0.0)) * per_phase_cell;
  const double axial_rate = (geometry.AxialAtIndex(1.0) - geometry.AxialAtIndex(0.0)) * per_axial_cell;
  // Where the rates put the next map cell's first sample after `from`: a guess, checked below.
  const auto predicted_end = [&](std::size_t from) {
    const double at[2] = {processing::PhaseInTurn(geometry.PhaseAt(from)) * per_phase_cell,
                          (geometry.AxialAt(from) - grid.y0_mm) * per_axial_cell};
    const double rate[2] = {phase_rate, axial_rate};
    double steps = static_cast<double>(kMaxCellSpan);
    for (int k = 0; k < 2; ++k) {
      if (rate[k] > 0.0) steps = std::min(steps, (std::floor(at[k] + 0.5) + 0.5 - at[k]) / rate[k]);
      if (rate[k] < 0.0) steps = std::min(steps, (at[k] - std::ceil(at[k] - 0.5) + 0.5) / -rate[k]);
    }
    return from + std::max<std::size_t>(1, static_cast<std::size_t>(std::ceil(steps)));
  };
  // The map's cell of sample i as the pass over every sample finds it: (phase, axial - first_axial).
  const auto map_cell = [&](std::size_t i) {
    const double c = processing::PhaseInTurn(geometry.PhaseAt(i));
    auto p = static_cast<std::size_t>(processing::RoundHalfAway(c * per_phase_cell));
    if (p >= grid.n_phase) p -= grid.n_phase;  // c rounds up to the turn's end
    const long a =
        processing::RoundHalfAway((geometry.AxialAt(i) - grid.y0_mm) * per_axial_cell) - sums.first_axial;
    return std::pair<std::size_t, long>{p, a};
  };
  for (std::size_t k = 0; k < cells.size(); ++k) {
    const HelixCell& cell = cells[k];
    const std::size_t to = k + 1 < cells.size() ? cells[k + 1].first : end;
    const SpanModel span(model, geometry, cell.first, to - 1);
    for (std::size_t from = cell.first; from < to;) {
      const std::pair<std::size_t, long> key = map_cell(from);
      // The run ends at the first index of another map cell: where predicted, if the rule agrees
      // there and one sample before; else found by bisection.
      const std::size_t guess = std::min(predicted_end(from), to);
      const bool guessed =
          (guess == to || map_cell(guess) != key) && (guess - 1 == from || map_cell(guess - 1) == key);
      std::size_t low = guessed ? guess : from + 1, high = to;
      while (!guessed && low < high) {
        const std::size_t mid = low + (high - low) / 2;
        if (map_cell(mid) != key) {
          high = mid;
        } else {
          low = mid + 1;
        }
      }
      if (span.valid && key.second >= 0 && key.second < sums.axial_cells) {
        double sum = 0.0;
        std::uint32_t count = 0;
        for (std::size_t i = from; i < low; ++i) {
          const auto rho = static_cast<double>(samples.rho_mm[i]);
          if (!std::isfinite(rho)) continue;
          sum += rho - span.At(static_cast<double>(i));
          ++count;
        }
        const std::size_t index =
            key.first * static_cast<std::size_t>(sums.axial_cells) + static_cast<std::size_t>(key.second);
        sums.sum[index] += sum;
        sums.count[index] += count;
      }
      from = low;
    }
  }
}

}  // namespace

// The residual map of the binned fit at theta: one more pass over the samples, each residual
// against the model along its cell. Releases the cells before the map is summed.
template <typename Sample>
std::vector<double> CellResidualMap(const Samples<Sample>& samples, HelixCells& cells, const Grid& grid,
                                    const Layout& layout, const VectorXd& theta) {
  if (grid.empty()) return {};
  const RowModel model(layout, theta);
  std::vector<CellSums> sums;
  for (std::size_t part = 0; part < kParts; ++part) {
    sums.push_back(CellSumsFor(grid, cells.ranges.low_y_mm[part], cells.ranges.high_y_mm[part]));
  }
  const int workers = std::min(WorkerCount(0), kParts);
  RunOnWorkers(workers, [&](int worker) {
    for (int part = worker; part < kParts; part += workers) {
      const auto p = static_cast<std::size_t>(part);
      CellResidualsPart(samples, cells.parts[p], model, grid, part, sums[p]);
    }
  });
  for (std::vector<HelixCell>& part : cells.parts) std::vector<HelixCell>().swap(part);
  return ResidualMap(grid, sums);
}

template HelixCells BinSamples(const Samples<double>& samples, const Layout& fine);
template HelixCells BinSamples(const Samples<float>& samples, const Layout& fine);
template std::vector<double> CellResidualMap(const Samples<double>& samples, HelixCells& cells,
                                             const Grid& grid, const Layout& layout, const VectorXd& theta);
template std::vector<double> CellResidualMap(const Samples<float>& samples, HelixCells& cells,
                                             const Grid& grid, const Layout& layout, const VectorXd& theta);

}  // namespace arcwheel::fitting::internal
