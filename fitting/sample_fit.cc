#include "fitting/sample_fit.h"

#include <fmt/core.h>

#include <Eigen/Dense>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

#include "core/check.h"
#include "core/dense.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/nan.h"
#include "core/parallel.h"

namespace arcwheel::fitting {
namespace {

constexpr const char* kSampleFitStage = "fitting";
constexpr int kWorkers = 2;
// Gauss-Newton passes over the runs after the Kasa start; the last one also gathers the
// residuals and the map. The first is without the slope correction; each later one takes its
// slopes and its band centre from the pass before. The passes are over the runs (a few per
// degree and turn), not the samples, so they are cheap; six leave steps far below the sigmas.
constexpr int kGaussNewtonPasses = 6;
// Axial spacing of each node's slope table (mm); the slope is linear between its entries.
constexpr double kSlopeStepMm = 0.25;
// The longest gap in a node's turns that is bridged (in helix pitches, 1 = no turn lost).
constexpr int kMaxGapPitches = 8;

struct Circle {
  double a = 0.0, b = 0.0, r = 0.0;
  bool valid = false;
  [[nodiscard]] double At(double y) const {
    const double u = y - a;
    return b + std::sqrt(std::max(0.0, r * r - u * u));
  }
};

// Sums of one node's pass over the runs, W the runs' weights. Kasa (pass 0): the weighted sums of
// [x, rho, 1] x [x, rho, 1, q], q = x^2 + rho^2, x = y - band centre. Gauss-Newton: J^T W J
// (upper triangle), J^T W e, the residuals' extremes and sum of squares (by samples).
struct NodeSums {
  std::array<double, 6> jtj{};
  std::array<double, 6> jtwwj{};  // J^T W (1 / samples) W J: the covariance's middle factor / sigma^2
  std::array<double, 3> jte{};
  std::array<double, 3> kasa_w{};  // weighted sums of x q, rho q, q
  double ee = 0.0;
  double count = 0.0;  // samples in the band
  double runs = 0.0;   // runs in the band (the section's points, one a turn)
  double y_min = std::numeric_limits<double>::infinity();
  double y_max = -std::numeric_limits<double>::infinity();
  double e_min = std::numeric_limits<double>::infinity();
  double e_max = -std::numeric_limits<double>::infinity();
};

// Residual sums of the map's cells: [node * n_y + axial node]; and of the sections' points: each
// node's runs in the band, by axial bin [node * bins + bin].
struct CellSums {
  std::vector<double> residual;
  std::vector<double> count;
  std::vector<double> offset, offset2;  // sums of samples x (y - y_m) and x (y - y_m)^2
  std::size_t bins = 0;
  double bin_low_mm = 0.0, bin_width_mm = 1.0;
  std::vector<double> section_e, section_y, section_count;
};

// The most axial bins a section's points are gathered in (WheelFit::section_bins): one a pitch,
// so that each holds one run a turn, unless the pitch is so fine that the arc error's bootstrap
// would fit thousands of points a phase.
constexpr std::size_t kMaxSectionBins = 100;

// One node's slope along the phase (mm per degree) tabulated over the axial span.
struct SlopeTable {
  double y0 = 0.0, step = kSlopeStepMm;
  std::size_t nodes = 0;
  std::vector<double> values;  // [node * nodes + k]
  [[nodiscard]] double At(std::size_t node, double y) const {
    if (values.empty()) return 0.0;
    const double x = std::clamp((y - y0) / step, 0.0, static_cast<double>(nodes - 1));
    const auto k = std::min(static_cast<std::size_t>(x), nodes - 2);
    const double f = x - static_cast<double>(k);
    const double* v = &values[node * nodes + k];
    return v[0] + f * (v[1] - v[0]);
  }
};

struct PassSetup {
  enum class Kind { kKasa, kGaussNewton } kind = Kind::kKasa;
  double band_center_mm = 0.0;
  double band_half_mm = 0.0;
  double taper_mm = 0.0;  // the helix pitch, the axial spacing of a phase's samples (BandWeight)
  double step_mm = 0.0;   // the same, signed: from one turn to the next along the scan (RunWeight)
  bool full = false;
  const std::vector<Circle>* circles = nullptr;
  const SlopeTable* slope = nullptr;
};

// A sample's weight in its phase's fit: how much of the band it stands for, in helix pitches
// (the samples of a phase lie one pitch apart along the axis, with the offset of where the
// helix happens to cross the band's edges). Inside, 1; over the four pitches at each edge the
// weights of a quadrature of the interval from the edge: the extended Simpson rule's end weights
// (17/48, 59/48, 43/48, 49/48; exact for cubics) from the first sample on, and the stretch from
// the edge to the first sample, t pitches long (t in [0, 1)), by the quadratic through the first
// three samples (weights t + 3t^2/4 + t^3/6, -(t^2 + t^3/3), t^2/4 + t^3/6). The weighted sums of
// a phase's fit are then its integrals over the band, wherever the samples fall: the band is read
// as the interval. Counting the samples that happen to lie in it instead moved a circle over
// 16 mm of a rim that falls steeply at its edges by some 150 um per mm of extra weight at an
// edge, and their mean (over the offsets) by +0.2 um; a linear ramp at the edges, by -0.5 um.
[[nodiscard]] inline double BandWeight(double y, const PassSetup& pass) {
  const double t = (pass.band_half_mm - std::abs(y - pass.band_center_mm)) / pass.taper_mm;
  if (t < 0.0) return 0.0;
  if (t < 1.0) return 17.0 / 48.0 + t + 0.75 * t * t + t * t * t / 6.0;
  if (t < 2.0) {
    const double s = t - 1.0;
    return 59.0 / 48.0 - s * s - s * s * s / 3.0;
  }
  if (t < 3.0) {
    const double s = t - 2.0;
    return 43.0 / 48.0 + 0.25 * s * s + s * s * s / 6.0;
  }
  if (t < 4.0) return 49.0 / 48.0;
  return 1.0;
}

// The node a phase within the turn belongs to, and the offset from it (deg).
struct NodeOf {
  std::size_t node;
  double offset_deg;
};

class NodeLocator {
 public:
  explicit NodeLocator(std::size_t n_phase)
      : n_(n_phase), step_deg_(360.0 / static_cast<double>(n_phase)), inv_step_(1.0 / step_deg_) {}
  [[nodiscard]] NodeOf Locate(double unwrapped_deg) const {
    const double c = processing::PhaseInTurn(unwrapped_deg);
    auto k = static_cast<std::size_t>(c * inv_step_ + 0.5);
    const double offset = c - static_cast<double>(k) * step_deg_;
    if (k >= n_) k -= n_;
    return {k, offset};
  }
  [[nodiscard]] double step_deg() const { return step_deg_; }

 private:
  std::size_t n_;
  double step_deg_, inv_step_;
};

// One node's samples on one turn: a run of consecutive samples in the scan. Its samples lie
// within 1/360 of a pitch of each other along the axis (half a micrometre at the paper's
// settings), where the residual of a circle is linear to 1e-12 of itself: the run's centroid,
// weighted by its count, stands for its samples in every sum of the fit.
struct Run {
  double rho_mm = 0.0;      // mean reading
  double y_mm = 0.0;        // mean axial position
  double offset_deg = 0.0;  // mean phase offset from the node
  std::uint32_t node = 0;
  std::uint32_t samples = 0;
  // Pitches to the node's run before and after it (1 = none lost between; a gap of more than
  // kMaxGapPitches counts as 1: too long to bridge).
  std::uint8_t gap_before = 1, gap_after = 1;
};

// The runs of a scan in scan order, as the two workers collected them (not joined: at 1e8
// samples a copy would add some 36 MB to the peak).
using RunParts = std::array<std::vector<Run>, kWorkers>;

// The runs of samples [begin, end), in scan order.
template <typename T>
void CollectRuns(std::span<const T> rho, const processing::HelixGeometry& geometry, std::size_t begin,
                 std::size_t end, const NodeLocator& locate, std::vector<Run>& runs) {
  double sum_rho = 0.0, sum_y = 0.0, sum_offset = 0.0, run_phase = 0.0;
  std::uint32_t count = 0;
  std::size_t node = 0;
  const auto flush = [&] {
    if (count == 0) return;
    const double n = count;
    runs.push_back({sum_rho / n, sum_y / n, sum_offset / n, static_cast<std::uint32_t>(node), count, 1, 1});
    sum_rho = sum_y = sum_offset = 0.0;
    count = 0;
  };
  for (std::size_t i = begin; i < end; ++i) {
    const auto value = static_cast<double>(rho[i]);
    if (!std::isfinite(value)) continue;
    const double phase = geometry.PhaseAt(i);
    const NodeOf at = locate.Locate(phase);
    if (count > 0 && (at.node != node || std::abs(phase - run_phase) > locate.step_deg())) flush();
    if (count == 0) {
      node = at.node;
      run_phase = phase;
    }
    sum_rho += value;
    sum_y += geometry.AxialAt(i);
    sum_offset += at.offset_deg;
    ++count;
  }
  flush();
}

// The same for a scan whose phase and axial position follow from its settings alone (linear in
// the sample index), where a node's stretch of samples on a turn is found from the phase instead
// of sample by sample: its end by the phase of the node's upper edge, checked against Locate on
// either side, so that every sample falls in the run CollectRuns gives it. Each run's centroid is
// then its samples' mean index; the readings are summed in the same order. A few times faster at
// many samples per node and turn (133 at the 400 kHz of the 1e8 benchmark).
template <typename T>
void CollectRunsOfLinearScan(std::span<const T> rho, const processing::HelixGeometry& geometry,
                             std::size_t begin, std::size_t end, const NodeLocator& locate,
                             std::vector<Run>& runs) {
  const double start_phase = geometry.PhaseAtIndex(0.0);
  const double phase_step = geometry.PhaseAtIndex(1.0) - start_phase;
  const auto node_at = [&](std::size_t i) {
    return locate.Locate(geometry.PhaseAtIndex(static_cast<double>(i)));
  };
  std::size_t i = begin;
  while (i < end) {
    const double phase = geometry.PhaseAtIndex(static_cast<double>(i));
    const NodeOf at = locate.Locate(phase);
    const double centre = phase - at.offset_deg;  // the node's centre on this turn, unwrapped
    // First sample past the node's upper edge, then moved to where Locate says the node ends.
    const double past = std::ceil((centre + 0.5 * locate.step_deg() - start_phase) / phase_step);
    std::size_t stop = i + 1;
    if (past > static_cast<double>(stop))
      stop = past >= static_cast<double>(end) ? end : static_cast<std::size_t>(past);
    while (stop > i + 1 && node_at(stop - 1).node != at.node) --stop;
    while (stop < end && node_at(stop).node == at.node) ++stop;
    double sum_rho = 0.0, sum_index = 0.0;
    std::uint32_t count = 0;
    for (std::size_t k = i; k < stop; ++k) {
      const auto value = static_cast<double>(rho[k]);
      if (!std::isfinite(value)) continue;
      sum_rho += value;
      sum_index += static_cast<double>(k);
      ++count;
    }
    if (count > 0) {
      const double n = count;
      const double mean_index = sum_index / n;
      runs.push_back({sum_rho / n, geometry.AxialAtIndex(mean_index),
                      geometry.PhaseAtIndex(mean_index) - centre, static_cast<std::uint32_t>(at.node), count,
                      1, 1});
    }
    i = stop;
  }
}

// Every run of the scan on two workers, halves meeting where the node changes; then the gaps in
// each node's turns on either side of each run (in pitches).
template <typename T>
RunParts Runs(std::span<const T> rho, const processing::HelixGeometry& geometry, const NodeLocator& locate,
              std::size_t n_phase, double pitch_mm) {
  ThrowIfInterrupted();
  const std::size_t n = rho.size();
  const auto boundary = [&](std::size_t b) {
    while (b > 0 && b < n &&
           locate.Locate(geometry.PhaseAt(b)).node == locate.Locate(geometry.PhaseAt(b - 1)).node) {
      ++b;
    }
    return b;
  };
  const double turns = n > 1 ? std::abs(geometry.PhaseAt(n - 1) - geometry.PhaseAt(0)) / 360.0 : 1.0;
  const auto expected =
      static_cast<std::size_t>((turns + 2.0) * static_cast<double>(n_phase) * 1.02 / kWorkers);
  // Fewer samples than nodes a turn: CollectRuns, whose runs then split by the phase's jumps.
  const bool linear = geometry.from_settings() && n > 1 &&
                      std::abs(geometry.PhaseAtIndex(1.0) - geometry.PhaseAtIndex(0.0)) < locate.step_deg() &&
                      geometry.PhaseAtIndex(1.0) > geometry.PhaseAtIndex(0.0);
  RunParts parts;
  RunOnWorkers(kWorkers, [&](int worker) {
    const auto w = static_cast<std::size_t>(worker);
    parts[w].reserve(std::min(expected, n));
    const std::size_t from = boundary(n * w / kWorkers), to = boundary(n * (w + 1) / kWorkers);
    if (linear) {
      CollectRunsOfLinearScan(rho, geometry, from, to, locate, parts[w]);
    } else {
      CollectRuns(rho, geometry, from, to, locate, parts[w]);
    }
  });
  // The turns each node lost between its runs (a dropout, a burst of spikes), for RunWeight.
  const auto gap = [pitch_mm](double from, double to) -> std::uint8_t {
    if (!std::isfinite(from)) return 1;
    const double pitches = std::round(std::abs(to - from) / pitch_mm);
    return pitches >= 1.0 && pitches <= kMaxGapPitches ? static_cast<std::uint8_t>(pitches) : 1;
  };
  std::vector<double> neighbour_y(n_phase, kNaN);
  for (std::vector<Run>& part : parts) {
    for (Run& r : part) {
      r.gap_before = gap(neighbour_y[r.node], r.y_mm);
      neighbour_y[r.node] = r.y_mm;
    }
  }
  neighbour_y.assign(n_phase, kNaN);
  for (auto part = parts.rbegin(); part != parts.rend(); ++part) {
    for (auto r = part->rbegin(); r != part->rend(); ++r) {
      r->gap_after = gap(neighbour_y[r->node], r->y_mm);
      neighbour_y[r->node] = r->y_mm;
    }
  }
  return parts;
}

// A run's weight: its band weight, plus the share of each turn its node lost next to it that
// linear interpolation between the run and its neighbour gives it (1 - k/g for the k-th of the
// g - 1 turns lost, counted from the run), each lost turn at its own place in the band. The
// weighted sums are then those of the node's values interpolated into the turns it lost, and
// the band is still read as the interval. Giving a lost turn's weight to one neighbour instead
// erred by a pitch times the profile's slope there, in every phase the dropout spans: at the
// band's edge, where the profile falls and the edge weights are steep, by up to 30 um in one
// phase, and the mean's scatter over seeds of the paper wheel grew 1.17x past its sigma.
double RunWeight(const Run& run, const PassSetup& pass) {
  if (pass.full) return 1.0 + 0.5 * (run.gap_before - 1) + 0.5 * (run.gap_after - 1);
  double w = BandWeight(run.y_mm, pass);
  for (int k = 1; k < run.gap_before; ++k)
    w += (1.0 - static_cast<double>(k) / run.gap_before) * BandWeight(run.y_mm - k * pass.step_mm, pass);
  for (int k = 1; k < run.gap_after; ++k)
    w += (1.0 - static_cast<double>(k) / run.gap_after) * BandWeight(run.y_mm + k * pass.step_mm, pass);
  return w;
}

// One pass of the fit over the runs of the nodes first..end - 1 (Kasa or Gauss-Newton, as `pass`
// says). A run weighs RunWeight; its centroid's variance is sigma^2 / samples.
void AccumulateRunsOfNodes(const RunParts& parts, const PassSetup& pass, const processing::WheelMap& map,
                           std::size_t first, std::size_t end, std::vector<NodeSums>& sums, CellSums* cells) {
  const std::size_t n_y = map.n_y();
  const double map_y0 = map.y_mm.front();
  const double map_inv_step = n_y > 1 ? 1.0 / (map.y_mm[1] - map.y_mm[0]) : 0.0;
  // The parts one after the other (not std::views::join: clang 14 with libstdc++ 12 refuses it).
  for (const std::vector<Run>& part : parts) {
    for (const Run& run : part) {
      if (run.node < first || run.node >= end) continue;
      const double y = run.y_mm;
      const double v =
          pass.slope != nullptr ? run.rho_mm - run.offset_deg * pass.slope->At(run.node, y) : run.rho_mm;
      const bool in_band = pass.full || std::abs(y - pass.band_center_mm) <= pass.band_half_mm;
      const double w = RunWeight(run, pass);
      const double samples = run.samples;
      NodeSums& s = sums[run.node];
      // A run just outside the band weighs in when it bridges a turn lost inside it (RunWeight);
      // the band's statistics (counts, extent, residual extremes) are of the runs inside it.
      const bool weighted = w > 0.0;
      if (pass.kind == PassSetup::Kind::kKasa) {
        if (!weighted) continue;
        const double x = y - pass.band_center_mm;
        const double q = x * x + v * v;
        // w [x, v, 1] outer [x, v, 1]: 0 xx, 1 xv, 2 x1, 3 vv, 4 v1, 5 11.
        s.jtj[0] += w * x * x;
        s.jtj[1] += w * x * v;
        s.jtj[2] += w * x;
        s.jtj[3] += w * v * v;
        s.jtj[4] += w * v;
        s.jtj[5] += w;
        s.kasa_w[0] += w * x * q;
        s.kasa_w[1] += w * v * q;
        s.kasa_w[2] += w * q;
        if (in_band) {
          s.count += samples;
          s.runs += 1.0;
          s.y_min = std::min(s.y_min, y);
          s.y_max = std::max(s.y_max, y);
        }
        continue;
      }
      const Circle& c = (*pass.circles)[run.node];
      if (!c.valid) continue;
      const double dy = y - c.a;
      const double dv = v - c.b;
      const double d = std::sqrt(dy * dy + dv * dv);
      const double e = d - c.r;
      if (weighted) {
        const double inv = 1.0 / d;
        const double j0 = -dy * inv, j1 = -dv * inv;  // d e / d(a, b); d e / d r = -1
        const double w0 = w * j0, w1 = w * j1;
        s.jtj[0] += w0 * j0;
        s.jtj[1] += w0 * j1;
        s.jtj[2] -= w0;
        s.jtj[3] += w1 * j1;
        s.jtj[4] -= w1;
        s.jtj[5] += w;
        s.jte[0] += w0 * e;
        s.jte[1] += w1 * e;
        s.jte[2] -= w * e;
        // The centroid's variance is sigma^2 / samples: J^T W (sigma^2 / n) W J.
        const double ww = w * w / samples;
        s.jtwwj[0] += ww * j0 * j0;
        s.jtwwj[1] += ww * j0 * j1;
        s.jtwwj[2] -= ww * j0;
        s.jtwwj[3] += ww * j1 * j1;
        s.jtwwj[4] -= ww * j1;
        s.jtwwj[5] += ww;
      }
      if (in_band) {
        s.ee += samples * e * e;
        s.count += samples;
        s.runs += 1.0;
        s.y_min = std::min(s.y_min, y);
        s.y_max = std::max(s.y_max, y);
        s.e_min = std::min(s.e_min, e);
        s.e_max = std::max(s.e_max, e);
      }
      if (cells != nullptr) {
        const double m = std::round((y - map_y0) * map_inv_step);
        if (m >= 0.0 && m < static_cast<double>(n_y)) {
          const std::size_t cell = run.node * n_y + static_cast<std::size_t>(m);
          // The run's radial offset from the node's circle, measured along rho, and where it lies
          // from the axial node.
          const double dy_node = y - map.y_mm[static_cast<std::size_t>(m)];
          cells->residual[cell] += samples * (v - c.At(y));
          cells->count[cell] += samples;
          cells->offset[cell] += samples * dy_node;
          cells->offset2[cell] += samples * dy_node * dy_node;
        }
        if (in_band && cells->bins > 0) {
          const double x = std::max(0.0, (y - cells->bin_low_mm) / cells->bin_width_mm);
          const std::size_t k =
              run.node * cells->bins + std::min(cells->bins - 1, static_cast<std::size_t>(x));
          cells->section_e[k] += samples * e;
          cells->section_y[k] += samples * y;
          cells->section_count[k] += samples;
        }
      }
    }
  }
}

// One pass over all runs, each worker taking half of the nodes: everything a run adds to is its
// node's, so each sum takes the same runs in the same order as in one pass.
void AccumulateRuns(const RunParts& parts, const PassSetup& pass, const processing::WheelMap& map,
                    std::vector<NodeSums>& sums, CellSums* cells) {
  const std::size_t n_phase = sums.size();
  RunOnWorkers(kWorkers, [&](int worker) {
    const auto w = static_cast<std::size_t>(worker);
    AccumulateRunsOfNodes(parts, pass, map, n_phase * w / kWorkers, n_phase * (w + 1) / kWorkers, sums,
                          cells);
  });
}

Eigen::Matrix3d Symmetric(const std::array<double, 6>& u) {
  Eigen::Matrix3d m;
  m << u[0], u[1], u[2], u[1], u[3], u[4], u[2], u[4], u[5];
  return m;
}

Eigen::Matrix3d Normal(const NodeSums& s) { return Symmetric(s.jtj); }

// Kasa 1976 algebraic circle: only the start of the Gauss-Newton passes.
Circle KasaCircle(const NodeSums& s, double band_center_mm, int min_points) {
  Circle c;
  if (s.count < std::max(4, min_points)) return c;
  const Eigen::Vector3d rhs(-s.kasa_w[0], -s.kasa_w[1], -s.kasa_w[2]);
  const Eigen::Vector3d p = dense::LdltSolve(Normal(s), rhs);
  const double a = -p(0) / 2.0, b = -p(1) / 2.0;
  const double r2 = a * a + b * b - p(2);
  if (!p.allFinite() || !(r2 > 0.0)) return c;
  c = {a + band_center_mm, b, std::sqrt(r2), true};
  return c;
}

bool Usable(const NodeSums& s, const Circle& c, double band_width_mm, bool full,
            const WheelFitOptions& options, std::string* flag) {
  if (!c.valid) {
    if (flag != nullptr) *flag = "no circle: too few samples or a degenerate section";
    return false;
  }
  if (s.count < options.min_points) {
    if (flag != nullptr) *flag = fmt::format("too few points in the band ({})", static_cast<long>(s.count));
    return false;
  }
  const double extent = s.y_max - s.y_min;
  if (!full && extent < options.min_band_coverage * band_width_mm) {
    if (flag != nullptr) {
      *flag = fmt::format("the section covers {:.3g} mm of the {:.3g} mm band", extent, band_width_mm);
    }
    return false;
  }
  return true;
}

// Mean arc-centre axial position of the usable circles; throws Error{kFitFailed} when there is none.
double MeanCenterAxial(const std::vector<Circle>& circles, const std::vector<NodeSums>& sums,
                       double band_width_mm, bool full, const WheelFitOptions& options) {
  double sum = 0.0;
  int usable = 0;
  std::string why;
  for (std::size_t j = 0; j < circles.size(); ++j) {
    std::string* flag = why.empty() ? &why : nullptr;
    if (!Usable(sums[j], circles[j], band_width_mm, full, options, flag)) continue;
    sum += circles[j].a;
    ++usable;
  }
  if (usable == 0) {
    throw Error(ErrorCode::kFitFailed, kSampleFitStage, "no phase gave a usable arc fit (" + why + ")");
  }
  return sum / usable;
}

// Each node's slope from its neighbours' circles (one-sided where a neighbour has none).
SlopeTable Slopes(const std::vector<Circle>& circles, double y_low, double y_high, double node_step_deg) {
  SlopeTable table;
  table.y0 = y_low;
  table.nodes =
      std::max<std::size_t>(2, static_cast<std::size_t>(std::ceil((y_high - y_low) / kSlopeStepMm)) + 1);
  const std::size_t n = circles.size();
  table.values.assign(n * table.nodes, 0.0);
  for (std::size_t j = 0; j < n; ++j) {
    const Circle& prev = circles[(j + n - 1) % n];
    const Circle& next = circles[(j + 1) % n];
    const Circle& self = circles[j];
    const Circle* lo = prev.valid ? &prev : (self.valid ? &self : nullptr);
    const Circle* hi = next.valid ? &next : (self.valid ? &self : nullptr);
    if (lo == nullptr || hi == nullptr || lo == hi) continue;
    const double span_deg = node_step_deg * ((lo == &prev ? 1.0 : 0.0) + (hi == &next ? 1.0 : 0.0));
    for (std::size_t k = 0; k < table.nodes; ++k) {
      const double y = y_low + static_cast<double>(k) * table.step;
      table.values[j * table.nodes + k] = (hi->At(y) - lo->At(y)) / span_deg;
    }
  }
  return table;
}

// The phase fits, their means, spreads and sigmas (nodes share no samples: the mean's variance is
// the sum of the nodes' over n^2).
void Summarise(const std::vector<Circle>& circles, const std::vector<NodeSums>& sums, double band_width_mm,
               bool full, double sigma_mm, const WheelFitOptions& options, WheelFit& out) {
  int usable = 0;
  double var_radius = 0.0, var_axial = 0.0;
  for (std::size_t j = 0; j < circles.size(); ++j) {
    const NodeSums& s = sums[j];
    const Circle& c = circles[j];
    PhaseFit fit;
    fit.points = static_cast<int>(s.count);
    std::string flag;
    if (Usable(s, c, band_width_mm, full, options, &flag)) {
      // The weighted fit's covariance: sigma^2 (J^T W J)^-1 J^T W^2 J (J^T W J)^-1.
      const Eigen::Matrix3d inverse = Normal(s).inverse();
      const Eigen::Matrix3d covariance = sigma_mm * sigma_mm * inverse * Symmetric(s.jtwwj) * inverse;
      fit.center_axial_mm = c.a;
      fit.center_radial_mm = c.b;
      fit.arc_radius_mm = c.r;
      fit.center_axial_sigma_mm = std::sqrt(covariance(0, 0));
      fit.center_radial_sigma_mm = std::sqrt(covariance(1, 1));
      fit.arc_radius_sigma_mm = std::sqrt(covariance(2, 2));
      fit.arc_error_um = (s.e_max - s.e_min) * 1000.0;
      // Each run's centroid residual times the root of its samples is one noise sigma.
      fit.chi2_per_dof = s.runs > 3.0 && sigma_mm > 0 ? s.ee / (sigma_mm * sigma_mm) / (s.runs - 3.0) : 0.0;
      if (!std::isfinite(fit.arc_radius_sigma_mm) || fit.arc_radius_sigma_mm > 0.1 * fit.arc_radius_mm) {
        fit.flag = "ill-conditioned: the radius is not determined";
      } else {
        fit.usable = true;
        ++usable;
        var_radius += covariance(2, 2);
        var_axial += covariance(0, 0);
      }
    } else {
      fit.flag = flag;
    }
    out.phases.push_back(fit);
  }
  if (usable == 0) {
    throw Error(ErrorCode::kFitFailed, kSampleFitStage,
                "no phase gave a usable arc fit (phase 0: " + out.phases.front().flag + ")");
  }
  SummariseUsablePhases(out);
  const auto n = static_cast<double>(usable);
  out.mean_arc_radius_sigma_mm = std::sqrt(var_radius) / n;
  out.mean_center_axial_sigma_mm = std::sqrt(var_axial) / n;
}

// The mean over the phases of the cells' residuals at each axial node (NaN where no phase has one).
std::vector<double> MeanResidualProfile(const std::vector<Circle>& circles, const CellSums& cells,
                                        std::size_t n_phase, std::size_t n_y) {
  std::vector<double> sum(n_y, 0.0), phases(n_y, 0.0);
  for (std::size_t j = 0; j < n_phase; ++j) {
    if (!circles[j].valid) continue;
    for (std::size_t m = 0; m < n_y; ++m) {
      const std::size_t cell = j * n_y + m;
      if (cells.count[cell] <= 0.0) continue;
      sum[m] += cells.residual[cell] / cells.count[cell];
      phases[m] += 1.0;
    }
  }
  for (std::size_t m = 0; m < n_y; ++m) sum[m] = phases[m] > 0.0 ? sum[m] / phases[m] : kNaN;
  return sum;
}

// First and second derivative (per mm, per mm^2) of `profile` at node m: from the five nodes
// centred on it (errors of order h^4), else the three centred on it, else the three at the end
// of the finite stretch; 0 where there are fewer than three. With three points only, a 1 um
// profile wave of 3 mm period at 0.2 mm spacing left 17 nm in a node's map over the phases, with
// five 9 nm.
std::array<double, 2> ProfileDerivatives(const std::vector<double>& f, std::size_t m, double h) {
  const auto finite = [&](long k) {
    return k >= 0 && static_cast<std::size_t>(k) < f.size() && std::isfinite(f[static_cast<std::size_t>(k)]);
  };
  const auto at = [&](long k) { return f[static_cast<std::size_t>(k)]; };
  const auto i = static_cast<long>(m);
  if (!finite(i)) return {0.0, 0.0};
  if (finite(i - 2) && finite(i - 1) && finite(i + 1) && finite(i + 2)) {
    return {(at(i - 2) - 8.0 * at(i - 1) + 8.0 * at(i + 1) - at(i + 2)) / (12.0 * h),
            (-at(i - 2) + 16.0 * at(i - 1) - 30.0 * at(i) + 16.0 * at(i + 1) - at(i + 2)) / (12.0 * h * h)};
  }
  if (finite(i - 1) && finite(i + 1)) {
    return {(at(i + 1) - at(i - 1)) / (2.0 * h), (at(i + 1) - 2.0 * at(i) + at(i - 1)) / (h * h)};
  }
  if (finite(i + 1) && finite(i + 2)) {
    return {(-3.0 * at(i) + 4.0 * at(i + 1) - at(i + 2)) / (2.0 * h),
            (at(i) - 2.0 * at(i + 1) + at(i + 2)) / (h * h)};
  }
  if (finite(i - 1) && finite(i - 2)) {
    return {(3.0 * at(i) - 4.0 * at(i - 1) + at(i - 2)) / (2.0 * h),
            (at(i) - 2.0 * at(i - 1) + at(i - 2)) / (h * h)};
  }
  return {0.0, 0.0};
}

// The typical 1-sigma of a map value from the noise: the median over the cells with a value of
// sigma / sqrt(samples in the cell), each value resting on the mean residual of its cell's samples
// (summary.json's map_sigma_um); 0 when no cell has one.
double MedianValueSigma(const CellSums& cells, const processing::WheelMap& map) {
  std::vector<double> sigmas;
  for (std::size_t cell = 0; cell < map.rho_mm.size(); ++cell) {
    if (std::isfinite(map.rho_mm[cell])) sigmas.push_back(map.noise_sigma_mm / std::sqrt(cells.count[cell]));
  }
  if (sigmas.empty()) return 0.0;
  const auto middle = sigmas.begin() + static_cast<long>(sigmas.size() / 2);
  std::nth_element(sigmas.begin(), middle, sigmas.end());
  return *middle;
}

// The map from the last pass's cells: the node's circle plus the cell's mean residual, moved to
// the axial node along the wheel's mean residual profile. A node's run on one turn lies up to
// half a pitch from the node, and where along that half pitch depends on the phase (the helix
// reaches phase c_j at j / n_phase of a pitch); left where it lies, a profile error of slope s
// enters the runout as s x pitch across the phases (0.5 um of P3 gave 25 nm, a 1 um profile wave
// of 3 mm period 0.5 um). The mean profile's first and second derivatives come from the
// phases' mean at the neighbouring nodes, which 360 phases make 19x less noisy than a cell.
void SetMap(const std::vector<Circle>& circles, const CellSums& cells, processing::WheelMap& map) {
  const std::size_t n_y = map.n_y();
  const double step_mm = n_y > 1 ? map.y_mm[1] - map.y_mm[0] : 1.0;
  const std::vector<double> profile = MeanResidualProfile(circles, cells, map.n_phase(), n_y);
  std::vector<std::array<double, 2>> derivatives(n_y);
  for (std::size_t m = 0; m < n_y; ++m) derivatives[m] = ProfileDerivatives(profile, m, step_mm);
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    for (std::size_t m = 0; m < n_y; ++m) {
      const std::size_t cell = j * n_y + m;
      const double count = cells.count[cell];
      const double u = map.y_mm[m] - circles[j].a;
      if (!(count > 0 && circles[j].valid && std::abs(u) < circles[j].r)) {
        map.rho_mm[cell] = kNaN;
        continue;
      }
      const auto [slope, curvature] = derivatives[m];
      const double moved = slope * cells.offset[cell] / count + 0.5 * curvature * cells.offset2[cell] / count;
      map.rho_mm[cell] = circles[j].At(map.y_mm[m]) + cells.residual[cell] / count - moved;
    }
  }
  map.map_sigma_mm = MedianValueSigma(cells, map);
}

// The sections' points from the last pass's bins: mean residual, position and its noise sigma.
void SetSections(const CellSums& cells, double sigma_mm, WheelFit& out) {
  out.section_bins = static_cast<int>(cells.bins);
  const std::size_t n = cells.section_count.size();
  out.section_residual_um.assign(n, kNaN);
  out.section_y_mm.assign(n, kNaN);
  out.section_sigma_um.assign(n, kNaN);
  for (std::size_t k = 0; k < n; ++k) {
    const double count = cells.section_count[k];
    if (count <= 0.0) continue;
    out.section_residual_um[k] = cells.section_e[k] / count * 1000.0;
    out.section_y_mm[k] = cells.section_y[k] / count;
    out.section_sigma_um[k] = sigma_mm * 1000.0 / std::sqrt(count);
  }
}

template <typename T>
WheelFit FitToSamples(std::span<const T> rho, const processing::HelixGeometry& geometry,
                      processing::WheelMap& map, const WheelFitOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kSampleFitStage, options.Problems());
  ARCWHEEL_CHECK(geometry.size() == rho.size())
      << geometry.size() << " positions for " << rho.size() << " samples";
  ARCWHEEL_CHECK(map.n_phase() >= 4 && map.n_y() >= 2) << map.n_phase() << " x " << map.n_y() << " map";
  const NodeLocator locate(map.n_phase());
  const bool full = options.fit_span == FitSpan::kFull;
  const double half = options.band_half_width_mm;
  const double y_low = map.y_mm.front();
  const double y_high = map.y_mm.back();
  PassSetup pass;
  pass.band_half_mm = half;
  pass.full = full;
  pass.taper_mm = std::max(std::abs(geometry.PitchMm()), 1e-9);
  pass.step_mm = rho.size() > 1 && geometry.AxialAt(rho.size() - 1) < geometry.AxialAt(0) ? -pass.taper_mm
                                                                                          : pass.taper_mm;
  pass.band_center_mm = 0.5 * (y_low + y_high);
  const std::size_t n_phase = map.n_phase();
  const RunParts runs = Runs(rho, geometry, locate, n_phase, pass.taper_mm);
  ThrowIfInterrupted();

  std::vector<NodeSums> sums(n_phase);
  AccumulateRuns(runs, pass, map, sums, nullptr);
  std::vector<Circle> circles(n_phase);
  for (std::size_t j = 0; j < n_phase; ++j)
    circles[j] = KasaCircle(sums[j], pass.band_center_mm, options.min_points);
  const double band_width = 2.0 * half;
  SlopeTable slope;
  CellSums cells;
  double used_center = pass.band_center_mm;
  for (int k = 1; k <= kGaussNewtonPasses; ++k) {
    const bool last = k == kGaussNewtonPasses;
    pass.kind = PassSetup::Kind::kGaussNewton;
    pass.circles = &circles;
    pass.slope = k >= 2 ? &slope : nullptr;
    used_center = pass.band_center_mm;
    sums.assign(n_phase, NodeSums{});
    if (last) {
      cells.residual.assign(n_phase * map.n_y(), 0.0);
      cells.count.assign(n_phase * map.n_y(), 0.0);
      cells.offset.assign(n_phase * map.n_y(), 0.0);
      cells.offset2.assign(n_phase * map.n_y(), 0.0);
      const double low = full ? y_low : pass.band_center_mm - half;
      const double width = full ? y_high - y_low : band_width;
      cells.bins = std::clamp<std::size_t>(static_cast<std::size_t>(std::lround(width / pass.taper_mm)), 1,
                                           kMaxSectionBins);
      cells.bin_low_mm = low;
      cells.bin_width_mm = width / static_cast<double>(cells.bins);
      cells.section_e.assign(n_phase * cells.bins, 0.0);
      cells.section_y.assign(n_phase * cells.bins, 0.0);
      cells.section_count.assign(n_phase * cells.bins, 0.0);
    }
    AccumulateRuns(runs, pass, map, sums, last ? &cells : nullptr);
    // The map's cells and the residual extremes are those of the circles the last pass started
    // from, which its step moves by far less than their sigma.
    for (std::size_t j = 0; j < n_phase; ++j) {
      if (!circles[j].valid || sums[j].count < std::max(4, options.min_points)) {
        circles[j].valid = false;
        continue;
      }
      const Eigen::Vector3d jte(sums[j].jte[0], sums[j].jte[1], sums[j].jte[2]);
      const Eigen::Vector3d step = -dense::LdltSolve(Normal(sums[j]), jte);
      if (!step.allFinite()) {
        circles[j].valid = false;
        continue;
      }
      circles[j].a += step(0);
      circles[j].b += step(1);
      circles[j].r += step(2);
    }
    if (!last) {
      slope = Slopes(circles, y_low, y_high, locate.step_deg());
      if (!full) pass.band_center_mm = MeanCenterAxial(circles, sums, band_width, full, options);
    }
  }

  WheelFit out;
  out.band_low_mm = full ? y_low : std::max(used_center - half, y_low);
  out.band_high_mm = full ? y_high : std::min(used_center + half, y_high);
  if (!(out.band_high_mm > out.band_low_mm)) {
    throw Error(ErrorCode::kBadInput, kSampleFitStage,
                fmt::format("the band {:.4g} +- {:.4g} mm lies outside the scanned span [{:.4g}, {:.4g}] mm",
                            used_center, half, y_low, y_high));
  }
  if (!full && out.band_high_mm - out.band_low_mm < 2.0 * half - 1e-9) {
    out.warnings.push_back(fmt::format("the band was clipped to [{:.4f}, {:.4f}] mm by the scanned span",
                                       out.band_low_mm, out.band_high_mm));
  }
  Summarise(circles, sums, band_width, full, map.noise_sigma_mm, options, out);
  SetMap(circles, cells, map);
  SetSections(cells, map.noise_sigma_mm, out);
  SetMapMetrics(map, options, out);
  return out;
}

}  // namespace

WheelFit FitWheelToSamples(std::span<const double> rho_mm, const processing::HelixGeometry& geometry,
                           processing::WheelMap& map, const WheelFitOptions& options) {
  return FitToSamples(rho_mm, geometry, map, options);
}

WheelFit FitWheelToSamples(std::span<const float> rho_mm, const processing::HelixGeometry& geometry,
                           processing::WheelMap& map, const WheelFitOptions& options) {
  return FitToSamples(rho_mm, geometry, map, options);
}

}  // namespace arcwheel::fitting
