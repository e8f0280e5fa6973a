#include "characteristics/wheel_characteristics.h"

#include <fmt/core.h>

#include <algorithm>
#include <bit>
#include <boost/random/mersenne_twister.hpp>
#include <boost/random/normal_distribution.hpp>
#include <cmath>
#include <functional>
#include <future>
#include <iterator>
#include <limits>
#include <numbers>
#include <numeric>
#include <random>

#include "characteristics/gaussian_filter.h"
#include "characteristics/roundness.h"
#include "core/error.h"
#include "core/nan.h"
#include "core/parallel.h"

namespace arcwheel::characteristics {
namespace {

constexpr std::string_view kWheelCharacteristicsStage = "characteristics.wheel";

// The cosines and sines of a turn's phases, for all the turns.
struct UnitCircle {
  std::vector<double> cos, sin;
};

// The points of one node: values (with their 1-sigma, in the values' unit), the coordinate the
// operator needs and its extra constants.
struct Node {
  std::vector<double> values, sigma, coordinate, extra;
  std::vector<double> truth_estimate;  // the values with the noise's share taken out (the bootstrap's base)
  const UnitCircle* unit = nullptr;    // a turn's: its phases' cosines and sines
};

// One evaluation of an operator on one node's points; NaN where it cannot be evaluated. A closed
// profile's filter (op.cutoff_upr) is applied before (LargestWithBootstrap), not by the operator.
using NodeOperator = double (*)(const FormOperator& op, std::span<const double> values, const Node& node);

std::vector<double> PhaseGridDeg(std::size_t n_phase) {
  std::vector<double> phase(n_phase);
  for (std::size_t i = 0; i < n_phase; ++i)
    phase[i] = 360.0 * static_cast<double>(i) / static_cast<double>(n_phase);
  return phase;
}

// As EvaluateRoundness turns the phases into directions, so that its points are the same.
UnitCircle UnitCircleOf(std::span<const double> phase_deg) {
  UnitCircle unit;
  for (const double phase : phase_deg) {
    const double angle_rad = phase * std::numbers::pi / 180.0;
    unit.cos.push_back(std::cos(angle_rad));
    unit.sin.push_back(std::sin(angle_rad));
  }
  return unit;
}

// Branch-free, so that GCC vectorises it: a bootstrap asks it of every candidate turn of every
// replicate.
bool AllFinite(std::span<const double> values) {
  int non_finite = 0;
  for (const double v : values) non_finite |= static_cast<int>(!FiniteWithoutBranch(v));
  return non_finite == 0;
}

// work(i, worker) for i = 0 .. n - 1 on both cores, worker w taking i = w, w + 2, ...: the
// per-node evaluations are independent, so their results do not depend on the sharing.
void ForEachOnBothCores(std::size_t n, const std::function<void(std::size_t, int)>& work) {
  RunOnWorkers(2, [&](int worker) {
    for (std::size_t i = static_cast<std::size_t>(worker); i < n; i += 2) work(i, worker);
  });
}

// RONt (um) of one turn of (filtered) radii about the spindle axis, as EvaluateRoundness takes it.
double Roundness(const FormOperator& op, std::span<const double> radius_mm, const Node& node) {
  if (!AllFinite(radius_mm)) return kNaN;
  const std::size_t n = radius_mm.size();
  std::vector<double> x(n), y(n);
  for (std::size_t i = 0; i < n; ++i) {
    x[i] = radius_mm[i] * node.unit->cos[i];
    y[i] = radius_mm[i] * node.unit->sin[i];
  }
  const AssociatedCircle circle = AssociateCircle(x, y, {.association = *op.association});
  if (!circle.IsCertified()) return kNaN;
  return ParametersAbout(circle, x, y).ront_um;
}

// An upper bound of Roundness at a filter and a pass over the points: a minimum zone's width is at
// most the filtered points' range of distances from any one centre; the noise-free estimate's
// reference centre (extra = {x, y}, mm), near the replicate's own, bounds it closely, else the
// turn's first harmonic (the least-squares centre to first order). +inf where it bounds nothing
// (another association's RONt is not the least over the centres).
double RoundnessBound(const FormOperator& op, std::span<const double> radius_mm, const Node& node) {
  if (op.association != Association::kMinimumZone || !AllFinite(radius_mm))
    return std::numeric_limits<double>::infinity();
  const std::size_t n = radius_mm.size();
  const std::vector<double>& cos = node.unit->cos;
  const std::vector<double>& sin = node.unit->sin;
  double cx = 0.0, cy = 0.0;
  if (node.extra.size() == 2) {
    cx = node.extra[0], cy = node.extra[1];
  } else {
    for (std::size_t i = 0; i < n; ++i) cx += radius_mm[i] * cos[i], cy += radius_mm[i] * sin[i];
    cx *= 2.0 / static_cast<double>(n);
    cy *= 2.0 / static_cast<double>(n);
  }
  // The range of the squared distances: the square root is monotonic and correctly rounded, so
  // the roots of their extremes are the extremes of the roots, to the bit.
  double low2 = std::numeric_limits<double>::infinity(), high2 = -low2;
  for (std::size_t i = 0; i < n; ++i) {
    const double dx = radius_mm[i] * cos[i] - cx, dy = radius_mm[i] * sin[i] - cy;
    const double d2 = dx * dx + dy * dy;
    low2 = std::min(low2, d2);
    high2 = std::max(high2, d2);
  }
  // A rounding's margin: the operator computes the same distances its own way.
  return (std::sqrt(high2) - std::sqrt(low2)) * 1000.0 * (1.0 + 1e-9) + 1e-9;
}

// Total indicator reading (um) of one turn about the spindle axis.
double Runout(const FormOperator&, std::span<const double> radius_mm, const Node&) {
  if (!AllFinite(radius_mm)) return kNaN;
  const auto [low, high] = std::minmax_element(radius_mm.begin(), radius_mm.end());
  return (*high - *low) * 1000.0;
}

// Peak-to-valley (um) of one section about its associated arc. `residual_um` are the points'
// distances from the phase's least-squares arc minus its radius, at axial offsets `dy_mm` from
// its centre; extra = {radius_mm, spacing_mm}.
double ArcProfile(const FormOperator& op, std::span<const double> residual_um, const Node& node) {
  const std::vector<double>& dy_mm = node.coordinate;
  const std::vector<double>& extra = node.extra;
  std::vector<double> r(residual_um.begin(), residual_um.end());
  if (r.size() < 4) return kNaN;
  if (op.cutoff_mm) r = FilterOpenProfile(r, extra[1], *op.cutoff_mm);
  // The points in the section's plane about the arc's centre: their distance from it is the
  // radius plus the residual, so the association sees the section as measured.
  std::vector<double> x(r.size()), y(r.size());
  for (std::size_t i = 0; i < r.size(); ++i) {
    const double distance = extra[0] + r[i] / 1000.0;
    x[i] = dy_mm[i];
    y[i] = std::sqrt(std::max(0.0, distance * distance - dy_mm[i] * dy_mm[i]));
  }
  const AssociatedCircle circle = AssociateCircle(x, y, {.association = *op.association});
  if (!circle.IsCertified()) return kNaN;
  double low = std::numeric_limits<double>::infinity(), high = -low;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const double d = std::hypot(x[i] - circle.center_x_mm, y[i] - circle.center_y_mm);
    low = std::min(low, d);
    high = std::max(high, d);
  }
  return (high - low) * 1000.0;
}

// An upper bound of ArcProfile at a few operations a point: the minimum zone's width is at most
// the points' range about any one centre, the least-squares arc's among them, where a point's
// distance is the radius plus its residual. +inf where it bounds nothing (a least-squares
// association's PV is not the least over the centres).
double ArcProfileBound(const FormOperator& op, std::span<const double> residual_um, const Node& node) {
  const std::vector<double>& extra = node.extra;
  if (residual_um.size() < 4 || op.association != Association::kMinimumZone)
    return std::numeric_limits<double>::infinity();
  std::vector<double> r(residual_um.begin(), residual_um.end());
  if (op.cutoff_mm) r = FilterOpenProfile(r, extra[1], *op.cutoff_mm);
  const auto [low, high] = std::minmax_element(r.begin(), r.end());
  // The operator's distances are computed through the section's plane: a rounding's margin.
  return (*high - *low) * (1.0 + 1e-9) + 1e-9;
}

// A closed profile's filter (an operator's UPR cut-off; none without one), made once a length:
// a bootstrap filters each candidate turn of each replicate.
class TurnFilter {
 public:
  explicit TurnFilter(std::optional<double> cutoff_upr) : cutoff_upr_(cutoff_upr) {}

  // `values` filtered in place; empty or non-finite values are left as they are.
  void Apply(std::vector<double>& values) {
    if (!cutoff_upr_ || values.empty() || !AllFinite(values)) return;
    if (!filter_ || size_ != values.size()) {
      filter_.emplace(values.size(), *cutoff_upr_);
      size_ = values.size();
    }
    filter_->Apply(values, values);
  }

 private:
  std::optional<double> cutoff_upr_;
  std::optional<ClosedProfileFilter> filter_;
  std::size_t size_ = 0;
};

// One characteristic the bootstrap takes over a set of nodes: its operator, the operator's
// evaluation on a node's (filtered) points and an upper bound of it (nullptr: none).
struct Measure {
  FormOperator op;
  NodeOperator evaluate = nullptr;
  NodeOperator bound = nullptr;
};

// A measure prepared for the bootstrap: its operator without the closed profile's filter, which
// is applied before the bound and the operator see the points (once for the measures that share
// a cut-off), its candidates, and the result so far.
struct Prepared {
  FormOperator unfiltered;
  std::size_t filter_group = 0;         // measures of one cut-off share their filtered turns
  std::vector<std::size_t> candidates;  // node indices, largest measured value first
  FormCharacteristic out;
  double base_max = kNaN;  // the largest value on the noise-free estimates
};

// What one bootstrap worker keeps from replicate to replicate: a node's noisy points, filtered
// once for each cut-off, and each measure's order of its candidates.
struct Workspace {
  std::vector<TurnFilter> filters;                         // one per filter group
  std::vector<std::vector<double>> noisy;                  // per node
  std::vector<std::vector<std::vector<double>>> filtered;  // per filter group, per node
  std::vector<std::vector<char>> filtered_ready;           // per filter group, per node
  std::vector<std::pair<double, std::size_t>> order;
};

// The largest value over measure `m`'s candidates of one replicate: each candidate in order of its
// bound, down to the first whose bound is below the largest value so far. With a cheap bound, the
// same largest value from a few of the candidates (the arc profile's minimum zone, some 20 us a
// section, from about a tenth of 360). NaN when none can be evaluated.
double ReplicateLargest(const Measure& measure, const Prepared& prepared, const std::vector<Node>& nodes,
                        Workspace& workspace) {
  const std::size_t g = prepared.filter_group;
  std::vector<std::pair<double, std::size_t>>& order = workspace.order;
  order.clear();
  for (const std::size_t j : prepared.candidates) {
    std::vector<double>& points = workspace.filtered[g][j];
    if (!workspace.filtered_ready[g][j]) {
      points = workspace.noisy[j];
      workspace.filters[g].Apply(points);
      workspace.filtered_ready[g][j] = 1;
    }
    const double limit = measure.bound ? measure.bound(prepared.unfiltered, points, nodes[j])
                                       : std::numeric_limits<double>::infinity();
    order.emplace_back(std::isnan(limit) ? std::numeric_limits<double>::infinity() : limit, j);
  }
  std::sort(order.begin(), order.end(), [](const auto& x, const auto& y) { return x.first > y.first; });
  double top = -std::numeric_limits<double>::infinity();
  for (const auto& [limit, j] : order) {
    if (limit < top) break;  // no candidate left can exceed the largest value
    const double value = measure.evaluate(prepared.unfiltered, workspace.filtered[g][j], nodes[j]);
    if (std::isfinite(value)) top = std::max(top, value);
  }
  return std::isfinite(top) ? top : kNaN;
}

// Replicate `b`: fresh noise about each drawn node's estimate, from a stream of the replicate's own
// (the seed and its number), so that the result does not depend on how the workers share them;
// then each measure's largest value. The measures of one set of nodes see the same noise: a
// replicate is one simulated scan.
void RunReplicate(std::span<const Measure> measures, std::span<const Prepared> prepared,
                  const std::vector<Node>& nodes, const std::vector<std::size_t>& drawn, std::uint64_t seed,
                  int b, Workspace& workspace, std::vector<std::vector<double>>& largest) {
  std::seed_seq seeds{seed, seed >> 32, static_cast<std::uint64_t>(b)};
  // Boost's Mersenne Twister: the standard's mt19937_64 stream to the bit, but its state refill
  // has no branch on a random bit (the standard library's mispredicted every other word).
  boost::random::mt19937_64 rng(seeds);
  // Boost's ziggurat: a replicate draws a deviate a point (some 10^5 of them for a turn's map),
  // and the standard library's polar method took a third of the step.
  boost::random::normal_distribution<double> normal(0.0, 1.0);
  for (const std::size_t j : drawn) {
    const Node& node = nodes[j];
    std::vector<double>& noisy = workspace.noisy[j];
    noisy.resize(node.values.size());
    for (std::size_t i = 0; i < noisy.size(); ++i)
      noisy[i] = node.truth_estimate[i] + node.sigma[i] * normal(rng);
  }
  for (std::vector<char>& ready : workspace.filtered_ready) std::fill(ready.begin(), ready.end(), 0);
  for (std::size_t m = 0; m < measures.size(); ++m) {
    if (prepared[m].candidates.empty()) continue;
    largest[m][static_cast<std::size_t>(b)] = ReplicateLargest(measures[m], prepared[m], nodes, workspace);
  }
}

// A measure's value at every node, its largest, and the candidates that can become the largest.
// `noise_um` (a sigma in the value's unit) sets how far below the largest a candidate may be.
Prepared Prepare(const Measure& measure, std::size_t filter_group, const std::vector<Node>& nodes,
                 std::span<const double> at, const CharacteristicsOptions& options, double noise_um) {
  Prepared p;
  p.filter_group = filter_group;
  p.unfiltered = measure.op;
  p.unfiltered.cutoff_upr = std::nullopt;
  FormCharacteristic& out = p.out;
  out.op = measure.op;
  // The nodes' values on both cores, a filter each (a thousand minimum zones at 1e8 samples).
  std::vector<TurnFilter> filters;
  for (int worker = 0; worker < 2; ++worker) filters.emplace_back(measure.op.cutoff_upr);
  const auto evaluate_filtered = [&](std::vector<double> values, const Node& node, int worker) {
    filters[static_cast<std::size_t>(worker)].Apply(values);
    return measure.evaluate(p.unfiltered, values, node);
  };
  out.per_node_um.assign(nodes.size(), kNaN);
  ForEachOnBothCores(nodes.size(), [&](std::size_t j, int worker) {
    if (!nodes[j].values.empty()) out.per_node_um[j] = evaluate_filtered(nodes[j].values, nodes[j], worker);
  });
  for (std::size_t j = 0; j < nodes.size(); ++j) {
    if (std::isfinite(out.per_node_um[j]) &&
        (out.worst_index < 0 ||
         out.per_node_um[j] > out.per_node_um[static_cast<std::size_t>(out.worst_index)]))
      out.worst_index = static_cast<int>(j);
  }
  if (out.worst_index < 0) {
    out.measured_um = out.value_um = out.u_um = kNaN;
    return p;
  }
  out.measured_um = out.per_node_um[static_cast<std::size_t>(out.worst_index)];
  out.worst_at = at[static_cast<std::size_t>(out.worst_index)];

  for (std::size_t j = 0; j < nodes.size(); ++j) {
    if (std::isfinite(out.per_node_um[j]) &&
        out.per_node_um[j] >= out.measured_um - options.candidate_sigmas * noise_um)
      p.candidates.push_back(j);
  }
  std::sort(p.candidates.begin(), p.candidates.end(),
            [&](std::size_t a, std::size_t b) { return out.per_node_um[a] > out.per_node_um[b]; });
  if (p.candidates.size() > static_cast<std::size_t>(options.max_candidates))
    p.candidates.resize(static_cast<std::size_t>(options.max_candidates));

  // The bootstrap simulates the noise about the best estimate of the noise-free profile (a
  // node's `truth_estimate`: the smoothed fit of the turns or the sections, below), not about the
  // measured one, whose peaks the noise has already raised: mean(f(estimate + noise)) -
  // f(estimate) is the bias, their spread u. The estimate must hold little noise itself: noise
  // left in it raises f(estimate) and the replicates' maximum less than the measured one (a
  // section's own points as the estimate made the arc profile's bias 0.78 um short).
  std::vector<double> base(p.candidates.size(), kNaN);
  ForEachOnBothCores(base.size(), [&](std::size_t c, int worker) {
    const Node& node = nodes[p.candidates[c]];
    base[c] = evaluate_filtered(node.truth_estimate, node, worker);
  });
  for (const double value : base)
    if (std::isfinite(value) && !(value <= p.base_max)) p.base_max = value;
  return p;
}

// The replicates' largest values made into the measure's bias, value and u.
void Conclude(const std::vector<double>& largest, Prepared& p) {
  FormCharacteristic& out = p.out;
  std::vector<double> replicate_max;
  std::copy_if(largest.begin(), largest.end(), std::back_inserter(replicate_max),
               [](double v) { return std::isfinite(v); });
  out.replicates = static_cast<int>(replicate_max.size());
  if (out.replicates < 2 || !std::isfinite(p.base_max)) {
    out.value_um = out.measured_um;
    out.u_um = kNaN;
    return;
  }
  const double mean = std::accumulate(replicate_max.begin(), replicate_max.end(), 0.0) / out.replicates;
  double sum2 = 0.0;
  for (const double v : replicate_max) sum2 += (v - mean) * (v - mean);
  out.u_um = std::sqrt(sum2 / (out.replicates - 1));
  out.bias_um = mean - p.base_max;
  out.value_um = std::max(0.0, out.measured_um - out.bias_um);
}

// The largest of the nodes' values of each measure and its bootstrap (header). `noise_um`
// converts a sigma into the values' unit (um) to choose the candidates.
std::vector<FormCharacteristic> LargestWithBootstrap(std::span<const Measure> measures,
                                                     const std::vector<Node>& nodes,
                                                     std::span<const double> at,
                                                     const CharacteristicsOptions& options, double noise_um,
                                                     std::uint64_t seed) {
  std::vector<std::optional<double>> cutoffs;  // of the filter groups
  std::vector<Prepared> prepared;
  std::vector<char> is_drawn(nodes.size(), 0);
  for (const Measure& measure : measures) {
    const auto found = std::find(cutoffs.begin(), cutoffs.end(), measure.op.cutoff_upr);
    const std::size_t group = static_cast<std::size_t>(found - cutoffs.begin());
    if (found == cutoffs.end()) cutoffs.push_back(measure.op.cutoff_upr);
    prepared.push_back(Prepare(measure, group, nodes, at, options, noise_um));
    for (const std::size_t j : prepared.back().candidates) is_drawn[j] = 1;
  }
  std::vector<std::size_t> drawn;
  for (std::size_t j = 0; j < nodes.size(); ++j)
    if (is_drawn[j]) drawn.push_back(j);

  std::vector<std::vector<double>> largest(
      measures.size(), std::vector<double>(static_cast<std::size_t>(options.replicates), kNaN));
  if (!drawn.empty()) {
    RunOnWorkers(2, [&](int worker) {
      Workspace workspace;
      for (const std::optional<double>& cutoff : cutoffs) workspace.filters.emplace_back(cutoff);
      workspace.noisy.resize(nodes.size());
      workspace.filtered.assign(cutoffs.size(), std::vector<std::vector<double>>(nodes.size()));
      workspace.filtered_ready.assign(cutoffs.size(), std::vector<char>(nodes.size(), 0));
      for (int b = worker; b < options.replicates; b += 2)
        RunReplicate(measures, prepared, nodes, drawn, seed, b, workspace, largest);
    });
  }
  std::vector<FormCharacteristic> out;
  for (std::size_t m = 0; m < measures.size(); ++m) {
    if (!prepared[m].candidates.empty()) Conclude(largest[m], prepared[m]);
    out.push_back(std::move(prepared[m].out));
  }
  return out;
}

// The seed mixed with the measured values, so that the same map gives the same numbers and two
// scans independent draws.
std::uint64_t MixedSeed(std::uint64_t seed, std::span<const double> values) {
  std::uint64_t h = seed ^ 0x9e3779b97f4a7c15ULL;
  for (const double v : values) {
    if (!std::isfinite(v)) continue;
    h ^= std::bit_cast<std::uint64_t>(v) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
  }
  return h;
}

void CheckSizes(const WheelForm& form, std::size_t n_phase, std::size_t n_y) {
  if (n_y == 0 || form.rho_mm.size() != n_phase * n_y || n_phase < 8 ||
      form.arc_radius_mm.size() != n_phase || form.center_axial_mm.size() != n_phase ||
      form.center_radial_mm.size() != n_phase || form.usable.size() != n_phase)
    throw Error(ErrorCode::kBadInput, kWheelCharacteristicsStage,
                fmt::format("the map ({} values, {} nodes) and the {} phase fits do not match",
                            form.rho_mm.size(), n_y, form.arc_radius_mm.size()));
  const std::size_t cells = n_phase * static_cast<std::size_t>(std::max(form.section_bins, 0));
  if (form.section_residual_um.size() != cells || form.section_y_mm.size() != cells ||
      form.section_sigma_um.size() != cells)
    throw Error(ErrorCode::kBadInput, kWheelCharacteristicsStage,
                "the sections' arrays do not match their bins");
}

// The 1-sigma of the map's value `cell` (WheelForm::rho_sigma_mm).
double ValueSigmaMm(const WheelForm& form, std::size_t cell) {
  if (form.rho_sigma_mm.size() != form.rho_mm.size()) return form.map_sigma_mm;
  const double sigma = form.rho_sigma_mm[cell];
  return std::isfinite(sigma) && sigma > 0.0 ? sigma : form.map_sigma_mm;
}

// The noise-free estimate of the band's `band_node`-th turn `values` (mm about the axis).
std::vector<double> TurnEstimate(const WheelForm& form, const std::vector<double>& values,
                                 std::size_t band_node) {
  const std::size_t n_phase = values.size();
  if (form.turn_smooth_um.size() >= (band_node + 1) * n_phase) {
    std::vector<double> turn(n_phase);
    for (std::size_t i = 0; i < n_phase; ++i)
      turn[i] = form.radius_offset_mm + form.turn_smooth_um[band_node * n_phase + i] / 1000.0;
    if (AllFinite(turn)) return turn;
  }
  // A noise-only harmonic exceeds nine times its expected power with probability exp(-9): over a
  // turn's 180 harmonics, one profile in sixty keeps one.
  return form.map_sigma_mm > 0.0 ? SignificantHarmonics(values, form.map_sigma_mm, 9.0) : values;
}

// The centre (x, y, mm) of the minimum-zone reference of a turn's noise-free estimate, for
// RoundnessBound; empty for another association or where there is none.
std::vector<double> EstimateCentre(const FormOperator& roundness, const std::vector<double>& turn,
                                   const std::vector<double>& phase_deg) {
  if (roundness.association != Association::kMinimumZone) return {};
  const RoundnessResult result = EvaluateRoundness(phase_deg, turn,
                                                   {.filter_cutoff_upr = roundness.cutoff_upr,
                                                    .association = *roundness.association,
                                                    .max_harmonic_upr = 1});
  if (!result.reference.IsCertified()) return {};
  return {result.reference.center_x_mm, result.reference.center_y_mm};
}

// The turns of the map at the band's nodes.
std::vector<Node> TurnNodes(const WheelForm& form, const FormOperator& roundness, std::size_t n_phase,
                            const std::vector<double>& phase_deg, const UnitCircle& unit,
                            std::vector<double>& at) {
  const std::size_t n_y = form.y_mm.size();
  std::vector<Node> nodes;
  for (std::size_t j = 0; j < n_y; ++j) {
    const double y = form.y_mm[j];
    if (y < form.band_low_mm || y > form.band_high_mm) continue;
    Node node;
    node.values.resize(n_phase);
    for (std::size_t i = 0; i < n_phase; ++i)
      node.values[i] = form.radius_offset_mm + form.rho_mm[i * n_y + j];
    node.sigma.resize(n_phase);
    for (std::size_t i = 0; i < n_phase; ++i) node.sigma[i] = ValueSigmaMm(form, i * n_y + j);
    node.coordinate = phase_deg;
    node.unit = &unit;
    if (!AllFinite(node.values)) node.values.clear();
    nodes.push_back(std::move(node));
    at.push_back(y);
  }
  if (nodes.empty())
    throw Error(ErrorCode::kBadInput, kWheelCharacteristicsStage,
                fmt::format("no axial node of the map lies in the band [{:g}, {:g}] mm", form.band_low_mm,
                            form.band_high_mm));
  // Each turn's noise-free estimate and its reference centre, on both cores.
  ForEachOnBothCores(nodes.size(), [&](std::size_t k, int) {
    Node& node = nodes[k];
    if (node.values.empty()) return;
    node.truth_estimate = TurnEstimate(form, node.values, k);
    node.extra = EstimateCentre(roundness, node.truth_estimate, phase_deg);
  });
  return nodes;
}

// The factor the sections' sigmas take to the noise the sections show. The estimator's Birge
// ratio counts the section's residuals about its fitted curve, but each section's points are
// residuals about the phase's least-squares arc too, which took three of their degrees of freedom:
// without them the ratio reads sqrt(1 - 3 / N) low (1.9 % at 80 bins), and the bias of a maximum
// over 360 sections, some 1.3 um, came out 0.02 um short (0.3 u) over 60 simulated scans.
double SectionSigmaScale(const WheelForm& form, std::size_t columns) {
  const double birge = form.section_sigma_scale > 0.0 ? form.section_sigma_scale : 1.0;
  if (columns <= 3) return birge;
  return birge * std::sqrt(static_cast<double>(columns) / static_cast<double>(columns - 3));
}

// Each usable phase's section: the sections' bins where the fit gives them, else the map's
// nodes in the band. Each point's noise-free estimate is the sections' smoothed fit
// (WheelForm::section_smooth_um) where it has one.
std::vector<Node> SectionNodes(const WheelForm& form, std::size_t n_phase, const FormOperator& op) {
  const std::size_t n_y = form.y_mm.size();
  const std::size_t bins = static_cast<std::size_t>(std::max(form.section_bins, 0));
  std::size_t columns = bins;
  if (bins == 0)
    columns = static_cast<std::size_t>(std::count_if(form.y_mm.begin(), form.y_mm.end(), [&](double y) {
      return y >= form.band_low_mm && y <= form.band_high_mm;
    }));
  const bool smoothed = form.section_smooth_um.size() == n_phase * columns;
  const double scale = SectionSigmaScale(form, columns);
  std::vector<Node> nodes(n_phase);
  for (std::size_t p = 0; p < n_phase; ++p) {
    if (form.usable[p] == 0 || !std::isfinite(form.arc_radius_mm[p])) continue;
    Node& node = nodes[p];
    const double a = form.center_axial_mm[p], radius = form.arc_radius_mm[p];
    const auto add = [&](std::size_t column, double y, double residual_um, double sigma_um) {
      if (!std::isfinite(y) || !std::isfinite(residual_um)) return false;
      node.coordinate.push_back(y - a);
      node.values.push_back(residual_um);
      node.sigma.push_back(scale * (std::isfinite(sigma_um) ? sigma_um : form.map_sigma_mm * 1000.0));
      const double smooth = smoothed ? form.section_smooth_um[p * columns + column] : kNaN;
      node.truth_estimate.push_back(std::isfinite(smooth) ? smooth : residual_um);
      return true;
    };
    bool complete = true;
    if (bins > 0) {
      for (std::size_t b = 0; b < bins; ++b)
        complete &= add(b, form.section_y_mm[p * bins + b], form.section_residual_um[p * bins + b],
                        form.section_sigma_um[p * bins + b]);
    } else {
      std::size_t column = 0;
      for (std::size_t j = 0; j < n_y; ++j) {
        const double y = form.y_mm[j];
        if (y < form.band_low_mm || y > form.band_high_mm) continue;
        const double rho = form.rho_mm[p * n_y + j];
        const double residual_um = (std::hypot(y - a, rho - form.center_radial_mm[p]) - radius) * 1000.0;
        complete &= add(column++, y, residual_um, ValueSigmaMm(form, p * n_y + j) * 1000.0);
      }
    }
    const double spacing = (form.band_high_mm - form.band_low_mm) /
                           static_cast<double>(std::max<std::size_t>(node.values.size(), 1));
    node.extra = {radius, spacing};
    // An open-profile filter needs the section's points equally spaced over the band.
    if (op.cutoff_mm && (!complete || *op.cutoff_mm < 5.0 * spacing)) node.values.clear();
  }
  return nodes;
}

RoundnessSection WorstRoundnessSection(const FormCharacteristic& roundness, const std::vector<Node>& turns,
                                       const std::vector<double>& at) {
  RoundnessSection section;
  if (roundness.worst_index < 0) return section;
  const Node& node = turns[static_cast<std::size_t>(roundness.worst_index)];
  return RoundnessSectionOf(node.coordinate, node.values, roundness.op,
                            at[static_cast<std::size_t>(roundness.worst_index)]);
}

}  // namespace

RoundnessSection RoundnessSectionOf(std::span<const double> phase_deg, std::span<const double> radius_mm,
                                    const FormOperator& op, double y_mm) {
  RoundnessResult result = EvaluateRoundness(
      phase_deg, radius_mm, {.filter_cutoff_upr = op.cutoff_upr, .association = *op.association});
  RoundnessSection section;
  section.y_mm = y_mm;
  section.phase_deg.assign(phase_deg.begin(), phase_deg.end());
  section.filtered_radius_mm = std::move(result.filtered_radius_mm);
  section.reference = result.reference;
  section.ront_um = result.ront_um;
  section.ronp_um = result.ronp_um;
  section.ronv_um = result.ronv_um;
  section.harmonic_amplitude_um = std::move(result.harmonic_amplitude_um);
  return section;
}

std::string FormOperator::Describe() const {
  std::string filter = "no filter";
  if (cutoff_upr) filter = fmt::format("{:g} UPR", *cutoff_upr);
  if (cutoff_mm) filter = fmt::format("λc {:g} mm", *cutoff_mm);
  const std::string reference =
      association ? std::string(AssociationAbbreviation(*association)) : "spindle axis";
  return fmt::format("{}, {}, {}", parameter, filter, reference);
}

FormOperator DefaultRoundnessOperator() {
  return {.cutoff_upr = 50.0,
          .cutoff_mm = std::nullopt,
          .association = Association::kMinimumZone,
          .parameter = "RONt"};
}

FormOperator DefaultRunoutOperator() {
  return {.cutoff_upr = 50.0, .cutoff_mm = std::nullopt, .association = std::nullopt, .parameter = "TIR"};
}

FormOperator DefaultArcProfileOperator() {
  return {.cutoff_upr = std::nullopt,
          .cutoff_mm = std::nullopt,
          .association = Association::kMinimumZone,
          .parameter = "PV"};
}

std::string RoundnessOperatorProblem(const FormOperator& op, int points_per_turn) {
  if (op.cutoff_mm) return "a roundness profile is closed: its filter takes a cut-off in UPR, not in mm";
  if (op.cutoff_upr && !(*op.cutoff_upr > 0.0 && *op.cutoff_upr <= points_per_turn / 2.0))
    return fmt::format("the cut-off {:g} UPR is not in (0, {}] (half the {} points per turn)", *op.cutoff_upr,
                       points_per_turn / 2, points_per_turn);
  if (!op.association) return "roundness needs an association";
  return "";
}

std::string RunoutOperatorProblem(const FormOperator& op, int points_per_turn) {
  if (op.cutoff_mm) return "a run-out profile is closed: its filter takes a cut-off in UPR, not in mm";
  if (op.cutoff_upr && !(*op.cutoff_upr > 0.0 && *op.cutoff_upr <= points_per_turn / 2.0))
    return fmt::format("the cut-off {:g} UPR is not in (0, {}] (half the {} points per turn)", *op.cutoff_upr,
                       points_per_turn / 2, points_per_turn);
  if (op.association) return "circular run-out is taken about the datum axis: it takes no association";
  return "";
}

std::string ArcProfileOperatorProblem(const FormOperator& op) {
  if (op.cutoff_upr) return "an arc profile is open: its filter takes a cut-off wavelength in mm, not in UPR";
  if (op.cutoff_mm && !(*op.cutoff_mm > 0.0))
    return fmt::format("the cut-off {:g} mm is not above 0", *op.cutoff_mm);
  if (!op.association) return "the arc profile needs an association";
  if (*op.association == Association::kMaximumInscribed ||
      *op.association == Association::kMinimumCircumscribed)
    return fmt::format(
        "the {} circle is not defined on an arc within half a turn (least-squares or minimum-zone)",
        AssociationName(*op.association));
  return "";
}

std::vector<std::string> CharacteristicsOptions::Problems() const {
  std::vector<std::string> problems;
  if (replicates < 20) problems.push_back(fmt::format("replicates = {} violates >= 20", replicates));
  if (!(candidate_sigmas > 0.0))
    problems.push_back(fmt::format("candidate_sigmas = {:g} violates > 0", candidate_sigmas));
  if (max_candidates < 1)
    problems.push_back(fmt::format("max_candidates = {} violates >= 1", max_candidates));
  if (const std::string p = ArcProfileOperatorProblem(arc_profile); !p.empty())
    problems.push_back("arc profile: " + p);
  return problems;
}

namespace {

// The options, the turns' operators at the map's phases and the sizes, checked before either part.
void Check(const WheelForm& form, const CharacteristicsOptions& options) {
  std::vector<std::string> problems = options.Problems();
  const int per_turn = static_cast<int>(form.arc_radius_mm.size());
  if (const std::string p = RoundnessOperatorProblem(options.roundness, per_turn); !p.empty())
    problems.push_back("roundness: " + p);
  if (const std::string p = RunoutOperatorProblem(options.runout, per_turn); !p.empty())
    problems.push_back("circular run-out: " + p);
  ThrowIfProblems(ErrorCode::kInvalidOption, kWheelCharacteristicsStage, problems);
  CheckSizes(form, form.arc_radius_mm.size(), form.y_mm.size());
}

}  // namespace

WheelCharacteristics EvaluateTurnCharacteristics(const WheelForm& form,
                                                 const CharacteristicsOptions& options) {
  Check(form, options);
  const std::size_t n_phase = form.arc_radius_mm.size();
  const std::vector<double> phase_deg = PhaseGridDeg(n_phase);
  std::vector<double> node_y;
  const UnitCircle unit = UnitCircleOf(phase_deg);
  const std::vector<Node> turns = TurnNodes(form, options.roundness, n_phase, phase_deg, unit, node_y);
  // Roundness and run-out are taken on the same turns: one replicate's noise serves both.
  const Measure turn_measures[] = {{options.roundness, Roundness, RoundnessBound},
                                   {options.runout, Runout, nullptr}};
  std::vector<FormCharacteristic> of_turns =
      LargestWithBootstrap(turn_measures, turns, node_y, options, form.map_sigma_mm * 1000.0,
                           MixedSeed(options.seed, form.rho_mm));
  WheelCharacteristics out;
  out.roundness = std::move(of_turns[0]);
  out.runout = std::move(of_turns[1]);
  out.worst_roundness_section = WorstRoundnessSection(out.roundness, turns, node_y);
  return out;
}

FormCharacteristic EvaluateArcProfile(const WheelForm& form, const CharacteristicsOptions& options) {
  Check(form, options);
  const std::size_t n_phase = form.arc_radius_mm.size();
  const std::vector<Node> sections = SectionNodes(form, n_phase, options.arc_profile);
  const Measure arc_measure[] = {{options.arc_profile, ArcProfile, ArcProfileBound}};
  return std::move(LargestWithBootstrap(arc_measure, sections, PhaseGridDeg(n_phase), options,
                                        form.map_sigma_mm * 1000.0,
                                        MixedSeed(options.seed, form.rho_mm) + 2)[0]);
}

WheelCharacteristics EvaluateWheelCharacteristics(const WheelForm& form,
                                                  const CharacteristicsOptions& options) {
  Check(form, options);
  // The sections' arc profile on a thread of its own beside the turns: each bootstrap's two
  // workers leave a core idle part of the time, and SectionNodes is serial.
  std::future<FormCharacteristic> arc_profile =
      std::async(std::launch::async, [&] { return EvaluateArcProfile(form, options); });
  WheelCharacteristics out = EvaluateTurnCharacteristics(form, options);
  out.arc_profile = arc_profile.get();
  return out;
}

}  // namespace arcwheel::characteristics
