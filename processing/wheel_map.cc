#include "processing/wheel_map.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>

#include "core/error.h"
#include "core/free_memory.h"
#include "core/interrupt.h"
#include "core/nan.h"
#include "core/parallel.h"
#include "processing/cubic_interpolation.h"
#include "processing/valid_span.h"

namespace arcwheel::processing {
namespace {

double ChooseKnotStep(const MapOptions& options, const HelixGeometry& geometry, std::size_t valid_samples) {
  if (options.knot_step_deg > 0) return options.knot_step_deg;
  const double phase_step = 360.0 / options.phases;
  const double span_deg = geometry.PhaseAt(geometry.size() - 1) - geometry.PhaseAt(0);
  const double degrees_per_sample = span_deg / std::max<double>(1.0, static_cast<double>(valid_samples));
  // At least 2.5 samples per knot interval keeps every coefficient determined by data.
  double step = phase_step;
  while (step < 2.5 * degrees_per_sample) step += phase_step;
  return step;
}

// The valid samples, counted a block at a time until ChooseKnotStep keeps its first step (one
// phase step): a larger count cannot change that, so a long scan is not read to its end for it.
template <typename T>
std::size_t ValidSamplesToChooseTheKnotStep(std::span<const T> rho, const HelixGeometry& geometry,
                                            const MapOptions& options) {
  if (options.knot_step_deg > 0) return 0;  // given, not chosen
  constexpr std::size_t kCountedAtOnce = std::size_t{1} << 20;
  const double phase_step = 360.0 / options.phases;
  std::size_t valid = 0;
  for (std::size_t from = 0; from < rho.size(); from += kCountedAtOnce) {
    const std::span<const T> block = rho.subspan(from, std::min(kCountedAtOnce, rho.size() - from));
    valid += static_cast<std::size_t>(
        std::count_if(block.begin(), block.end(), [](T v) { return std::isfinite(static_cast<double>(v)); }));
    if (ChooseKnotStep(options, geometry, valid) == phase_step) break;
  }
  return valid;
}

// The spline at one phase node on every turn it covers, in the order of the helix (ascending u);
// sigmas are set by SetSectionSigmas.
Section SampleSection(const HelixSpline& spline, const HelixGeometry& geometry, double phase_deg,
                      int min_support) {
  Section section;
  const double first = spline.first_phase_deg();
  const double last = spline.last_phase_deg();
  double u = phase_deg + 360.0 * std::ceil((first - phase_deg) / 360.0);
  // Room for a point on every turn (and one spare): no arrays left behind by growing.
  const auto turns = static_cast<std::size_t>(std::max(0.0, (last - u) / 360.0)) + 2;
  section.u_deg.reserve(turns);
  section.y_mm.reserve(turns);
  section.rho_mm.reserve(turns);
  section.sigma_mm.reserve(turns);
  for (; u <= last; u += 360.0) {
    if (spline.Support(u) < min_support) continue;
    section.u_deg.push_back(u);
    section.y_mm.push_back(geometry.AxialAtPhase(u));
    section.rho_mm.push_back(spline.Value(u));
  }
  return section;
}

// Every section point's sigma, from one sweep of the spline's variances over all sections; then
// each section in the order of its axial positions (the feed may run towards -y).
void SetSectionSigmas(const HelixSpline& spline, double noise_sigma_mm, std::vector<Section>& sections) {
  std::vector<std::span<const double>> u_lists;
  std::vector<std::span<double>> factors;
  for (Section& section : sections) {
    section.sigma_mm.resize(section.u_deg.size());
    u_lists.emplace_back(section.u_deg);
    factors.emplace_back(section.sigma_mm);
  }
  spline.VarianceFactors(u_lists, factors);
  for (Section& section : sections) {
    for (double& sigma : section.sigma_mm) sigma = noise_sigma_mm * std::sqrt(std::max(0.0, sigma));
    if (section.y_mm.size() > 1 && section.y_mm.front() > section.y_mm.back()) {
      std::reverse(section.u_deg.begin(), section.u_deg.end());
      std::reverse(section.y_mm.begin(), section.y_mm.end());
      std::reverse(section.rho_mm.begin(), section.rho_mm.end());
      std::reverse(section.sigma_mm.begin(), section.sigma_mm.end());
    }
  }
}

// Leaves out the section points whose sigma exceeds `ratio` times the median point's. They rest
// on a few samples at the edge of a gap (a dropout, a burst of spikes, the rim's edge), where
// even a penalised spline swings by many sigmas: left in, they set the peak-to-valley metrics
// (max arc error 2-4 um above truth on a scan with 1 % spikes). The median point rests on the
// full sample density, so the cut follows the scan's own sampling.
// The median of every section point's sigma (the element at half the count, as a sort would
// place it); 0 when there is no point.
double MedianPointSigma(const std::vector<Section>& sections) {
  std::vector<double> sigmas;
  for (const Section& s : sections) sigmas.insert(sigmas.end(), s.sigma_mm.begin(), s.sigma_mm.end());
  if (sigmas.empty()) return 0.0;
  const auto middle = sigmas.begin() + static_cast<long>(sigmas.size() / 2);
  std::nth_element(sigmas.begin(), middle, sigmas.end());
  return *middle;
}

void DropImpreciseSectionPoints(std::vector<Section>& sections, double ratio) {
  std::vector<double> sigmas;
  for (const Section& s : sections) sigmas.insert(sigmas.end(), s.sigma_mm.begin(), s.sigma_mm.end());
  if (sigmas.empty()) return;
  const auto middle = sigmas.begin() + static_cast<long>(sigmas.size() / 2);
  std::nth_element(sigmas.begin(), middle, sigmas.end());
  const double limit = ratio * *middle;
  for (Section& s : sections) {
    std::size_t kept = 0;
    for (std::size_t k = 0; k < s.y_mm.size(); ++k) {
      if (!(s.sigma_mm[k] <= limit)) continue;
      s.u_deg[kept] = s.u_deg[k];
      s.y_mm[kept] = s.y_mm[k];
      s.rho_mm[kept] = s.rho_mm[k];
      s.sigma_mm[kept] = s.sigma_mm[k];
      ++kept;
    }
    s.u_deg.resize(kept);
    s.y_mm.resize(kept);
    s.rho_mm.resize(kept);
    s.sigma_mm.resize(kept);
  }
}

// Interpolates one section onto the axial nodes. A gap of one missing point (up to 2.5 pitches)
// is bridged: the section is a smooth arc at that scale, and leaving such nodes empty takes
// phases out of the runout and roundness at that node, whose least-squares first harmonic then
// leaks the wheel's lobing into the roundness. Nodes in a wider gap, or outside the section, stay
// NaN.
void InterpolateSection(const Section& section, std::span<const double> nodes, double pitch_mm,
                        std::span<double> out) {
  std::fill(out.begin(), out.end(), kNaN);
  if (section.y_mm.size() < 2) return;
  const NaturalCubicSpline spline(section.y_mm, section.rho_mm);
  const double max_gap = 2.5 * std::abs(pitch_mm);
  for (std::size_t m = 0; m < nodes.size(); ++m) {
    const double y = nodes[m];
    if (y < section.y_mm.front() - 1e-9 || y > section.y_mm.back() + 1e-9) continue;
    const std::size_t i = spline.Interval(y);
    if (section.y_mm[i + 1] - section.y_mm[i] > max_gap) continue;
    out[m] = spline(y);
  }
}

// The map cell of a sample: the phase node nearest its phase in the turn, and the axial node
// nearest its axial position (-1 when outside the map). Exactly lround(fmod(u, 360) / phase step)
// and round((y - y_low) / axial step), without a libm call per sample (helix_geometry.h).
class CellOfSample {
 public:
  CellOfSample(std::size_t n_phase, std::size_t n_y, double y_low, double axial_step_mm)
      : n_phase_(static_cast<long>(n_phase)),
        n_y_(static_cast<long>(n_y)),
        phase_step_(360.0 / static_cast<double>(n_phase)),
        y_low_(y_low),
        axial_step_(axial_step_mm) {}

  [[nodiscard]] long operator()(double u_deg, double y_mm) const {
    const long m = AxialNode(y_mm);
    if (m < 0 || m >= n_y_) return -1;
    return PhaseNode(u_deg) * n_y_ + m;
  }

  // The axial node nearest y: -1 below the map, n_y above it (both non-decreasing in y).
  [[nodiscard]] long AxialNode(double y_mm) const {
    const double t = (y_mm - y_low_) / axial_step_;
    if (!(t > -0.5)) return -1;  // round(-0.4) is -0: row 0
    if (!(t < static_cast<double>(n_y_))) return n_y_;
    return std::min(RoundHalfAway(t), n_y_);
  }

  // The phase in the turn lies in [0, 360): its node is 0 .. n_phase, and n_phase is node 0
  // (a comparison instead of a 64-bit division per sample).
  [[nodiscard]] long PhaseNode(double u_deg) const {
    const long j = RoundHalfAway(PhaseInTurn(u_deg) / phase_step_);
    return j == n_phase_ ? 0 : j;
  }

  [[nodiscard]] long n_phase() const { return n_phase_; }
  [[nodiscard]] long n_y() const { return n_y_; }
  [[nodiscard]] double phase_step() const { return phase_step_; }
  [[nodiscard]] double axial_step() const { return axial_step_; }
  [[nodiscard]] double y_low() const { return y_low_; }

 private:
  long n_phase_, n_y_;
  double phase_step_, y_low_, axial_step_;
};

// Where a sample lies by CellOfSample: its phase node, its axial node (-1 below, n_y above) and
// its unwrapped phase and axial position in axial steps from the first node.
struct SampleCell {
  long phase_node = 0;
  long axial_node = 0;
  double u_deg = 0.0;
  double t = 0.0;
};

// Counts the samples of a scan whose phase and axial position follow from its settings
// (HelixGeometry::from_settings) run by run: a run is a stretch of samples in one cell, and it
// adds its finite samples at once. Every run is proven with the per-sample rule at its ends: u and
// y are then monotone in the sample index (products and sums of monotone roundings), so the axial
// node is monotone, and the phase node steps around the turn in one direction; two samples in the
// same cell less than 180 deg apart (n_phase >= 4, so leaving a cell and coming back takes 270 deg)
// have every sample between them in that cell too.
template <typename T>
class RunCounter {
 public:
  RunCounter(std::span<const T> rho, const HelixGeometry& geometry, const CellOfSample& cell_of)
      : rho_(rho), geometry_(geometry), cell_of_(cell_of) {
    const double n = std::max(1.0, static_cast<double>(geometry.size()) - 1.0);
    // Per-sample advances, only to guess where a run ends (each guess is checked).
    phase_step_per_sample_ = (geometry.PhaseAtIndex(n) - geometry.PhaseAtIndex(0.0)) / n;
    axial_nodes_per_sample_ =
        (geometry.AxialAtIndex(n) - geometry.AxialAtIndex(0.0)) / n / cell_of.axial_step();
  }

  // Runs pay when they are long: a run costs a few evaluations of the per-sample rule.
  [[nodiscard]] bool Pays() const { return std::abs(phase_step_per_sample_) < 0.25 * cell_of_.phase_step(); }

  void Count(std::size_t begin, std::size_t end, std::vector<int>& counts) const {
    std::size_t i = begin;
    while (i < end) {
      const SampleCell first = At(i);
      const std::size_t last = LastInRun(i, first, end - 1);
      if (first.axial_node >= 0 && first.axial_node < cell_of_.n_y()) {
        const auto cell = static_cast<std::size_t>(first.phase_node * cell_of_.n_y() + first.axial_node);
        counts[cell] += FiniteIn(i, last + 1);
      }
      i = last + 1;
    }
  }

 private:
  [[nodiscard]] SampleCell At(std::size_t i) const {
    const double u = geometry_.PhaseAt(i);
    const double y = geometry_.AxialAt(i);
    return {cell_of_.PhaseNode(u), cell_of_.AxialNode(y), u, (y - cell_of_.y_low()) / cell_of_.axial_step()};
  }

  [[nodiscard]] bool InRun(std::size_t k, const SampleCell& first) const {
    const SampleCell at = At(k);
    return at.phase_node == first.phase_node && at.axial_node == first.axial_node &&
           std::abs(at.u_deg - first.u_deg) < 180.0;
  }

  // The last sample of the run that starts at i, in [i, last]: from a guess, by galloping and
  // bisection on InRun (true from i up to the run's end, false after it).
  [[nodiscard]] std::size_t LastInRun(std::size_t i, const SampleCell& first, std::size_t last) const {
    std::size_t good = i;
    std::size_t bad = last + 1;  // past the end: never evaluated
    const std::size_t guess = std::clamp(i + SamplesLeftGuess(first), i, last);
    if (guess > i) (InRun(guess, first) ? good : bad) = guess;
    if (bad == last + 1) {
      for (std::size_t step = 1; good < last; step *= 2) {
        const std::size_t probe = std::min(last, good + step);
        if (!InRun(probe, first)) {
          bad = probe;
          break;
        }
        good = probe;
      }
      if (good == last) return last;
    } else {
      for (std::size_t step = 1; bad - good > 1; step *= 2) {
        const std::size_t probe = bad - std::min(step, bad - good - 1);
        if (InRun(probe, first)) {
          good = probe;
          break;
        }
        bad = probe;
      }
    }
    while (bad - good > 1) {
      const std::size_t mid = good + (bad - good) / 2;
      (InRun(mid, first) ? good : bad) = mid;
    }
    return good;
  }

  // Samples after the first of a run to the nearer of the next phase and axial cell boundaries.
  [[nodiscard]] std::size_t SamplesLeftGuess(const SampleCell& first) const {
    const double left = std::min(PhaseSamplesLeft(first), AxialSamplesLeft(first));
    if (!(left >= 0.0)) return 0;
    return left < 1e15 ? static_cast<std::size_t>(left) : std::size_t{1} << 50;
  }

  [[nodiscard]] double PhaseSamplesLeft(const SampleCell& first) const {
    const double rate = phase_step_per_sample_;
    if (rate == 0.0) return std::numeric_limits<double>::infinity();
    const double c = PhaseInTurn(first.u_deg);
    // The node before folding (n_phase at the end of a turn): its cell spans +- half a step.
    const double node = std::round(c / cell_of_.phase_step());
    const double boundary = (node + (rate > 0.0 ? 0.5 : -0.5)) * cell_of_.phase_step();
    return (boundary - c) / rate;
  }

  [[nodiscard]] double AxialSamplesLeft(const SampleCell& first) const {
    const double rate = axial_nodes_per_sample_;
    const long m = first.axial_node;
    if (rate == 0.0 || (rate > 0.0 && m >= cell_of_.n_y()) || (rate < 0.0 && m < 0)) {
      return std::numeric_limits<double>::infinity();
    }
    const double boundary = static_cast<double>(m) + (rate > 0.0 ? 0.5 : -0.5);
    return (boundary - first.t) / rate;
  }

  [[nodiscard]] int FiniteIn(std::size_t begin, std::size_t end) const {
    int finite = 0;
    for (std::size_t k = begin; k < end; ++k) finite += std::isfinite(static_cast<double>(rho_[k])) ? 1 : 0;
    return finite;
  }

  std::span<const T> rho_;
  const HelixGeometry& geometry_;
  const CellOfSample& cell_of_;
  double phase_step_per_sample_ = 0.0;
  double axial_nodes_per_sample_ = 0.0;
};

// True when RunCounter applies: phase and axial position linear in the sample index, and finite
// at both ends (so at every sample: both are monotone).
bool CountableByRuns(const HelixGeometry& geometry) {
  if (!geometry.from_settings() || geometry.size() == 0) return false;
  const std::size_t last = geometry.size() - 1;
  return std::isfinite(geometry.PhaseAt(0)) && std::isfinite(geometry.PhaseAt(last)) &&
         std::isfinite(geometry.AxialAt(0)) && std::isfinite(geometry.AxialAt(last));
}

// Coverage diagnostics: raw and despiked samples per cell around each node. Two workers count the
// two halves of the scan (integer sums: the same on any machine).
template <typename T>
void CountCoverage(std::span<const T> rho, const HelixGeometry& geometry,
                   std::span<const std::size_t> despiked, double y_low, WheelMap& map) {
  const CellOfSample cell_of(map.n_phase(), map.n_y(), y_low, map.axial_step_mm);
  const std::size_t cells = map.n_phase() * map.n_y();
  std::vector<int> upper(cells, 0);
  map.sample_count.assign(cells, 0);
  const RunCounter<T> runs(rho, geometry, cell_of);
  const bool by_runs = CountableByRuns(geometry) && runs.Pays();
  RunOnWorkers(2, [&](int half) {
    std::vector<int>& counts = half == 0 ? map.sample_count : upper;
    const std::size_t begin = half == 0 ? 0 : rho.size() / 2;
    const std::size_t end = half == 0 ? rho.size() / 2 : rho.size();
    if (by_runs) {
      runs.Count(begin, end, counts);
      return;
    }
    for (std::size_t i = begin; i < end; ++i) {
      if (!std::isfinite(static_cast<double>(rho[i]))) continue;
      if (const long cell = cell_of(geometry.PhaseAt(i), geometry.AxialAt(i)); cell >= 0) {
        ++counts[static_cast<std::size_t>(cell)];
      }
    }
  });
  for (std::size_t c = 0; c < cells; ++c) map.sample_count[c] += upper[c];
  map.despiked_count.assign(cells, 0);
  for (const std::size_t i : despiked) {
    if (const long cell = cell_of(geometry.PhaseAt(i), geometry.AxialAt(i)); cell >= 0) {
      ++map.despiked_count[static_cast<std::size_t>(cell)];
    }
  }
}

// The axial nodes from y_low to y_high, one axial step apart (one helix pitch unless asked), and
// the map's values all NaN.
void SetAxialNodes(double y_low, double y_high, const MapOptions& options, WheelMap& map) {
  map.axial_step_mm = options.axial_step_mm > 0 ? options.axial_step_mm : std::abs(map.pitch_mm);
  const auto n_y = static_cast<std::size_t>(std::floor((y_high - y_low) / map.axial_step_mm + 1e-9)) + 1;
  map.y_mm.resize(n_y);
  for (std::size_t m = 0; m < n_y; ++m) map.y_mm[m] = y_low + static_cast<double>(m) * map.axial_step_mm;
  map.rho_mm.assign(map.n_phase() * n_y, kNaN);
}

// The phase nodes 0, 360 / phases, ...
std::vector<double> PhaseNodes(int phases) {
  std::vector<double> nodes(static_cast<std::size_t>(phases));
  for (std::size_t j = 0; j < nodes.size(); ++j) nodes[j] = 360.0 * static_cast<double>(j) / phases;
  return nodes;
}

// The axial span that every phase node covers: the helix crosses each node on every turn, and
// the span runs from the last of the nodes' first crossings inside the valid samples [u_first,
// u_last] to the first of their last ones. The crossings are stepped a turn at a time from the
// first at or after u_first, as the helix spline's sections were, so that the nodes are those
// its sections' ends gave (the same on the shipped scans, whose spline kept every end point).
std::pair<double, double> CommonAxialSpan(const HelixGeometry& geometry, std::span<const double> phase_deg,
                                          double u_first, double u_last) {
  double y_low = -std::numeric_limits<double>::infinity();
  double y_high = std::numeric_limits<double>::infinity();
  for (const double phase : phase_deg) {
    const double first = phase + 360.0 * std::ceil((u_first - phase) / 360.0);
    double last = first;
    for (double next = first + 360.0; next <= u_last; next += 360.0) last = next;
    if (!(last > first)) continue;  // a node crossed once or never bounds nothing
    const double y_first = geometry.AxialAtPhase(first);
    const double y_last = geometry.AxialAtPhase(last);
    y_low = std::max(y_low, std::min(y_first, y_last));
    y_high = std::min(y_high, std::max(y_first, y_last));
  }
  return {y_low, y_high};
}

// A map's settings before its nodes: the options checked, the noise, the knot step, the pitch.
template <typename T>
WheelMap StartMap(std::span<const T> rho, const HelixGeometry& geometry, double noise_sigma_mm,
                  const MapOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "processing.map", options.Problems());
  WheelMap map;
  map.noise_sigma_mm = noise_sigma_mm;
  map.knot_step_deg =
      ChooseKnotStep(options, geometry, ValidSamplesToChooseTheKnotStep(rho, geometry, options));
  map.pitch_mm = geometry.PitchMm();
  return map;
}

template <typename T>
WheelMap Plan(std::span<const T> rho, const HelixGeometry& geometry, double noise_sigma_mm,
              std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  if (clock != nullptr) clock->Start("map nodes and coverage");
  WheelMap map = StartMap(rho, geometry, noise_sigma_mm, options);
  map.phase_deg = PhaseNodes(options.phases);
  const auto [first, last] = ValidSpan(rho);
  const auto [y_low, y_high] =
      first < last
          ? CommonAxialSpan(geometry, map.phase_deg, geometry.PhaseAt(first), geometry.PhaseAt(last - 1))
          : std::pair<double, double>{0.0, 0.0};
  if (!(y_high > y_low)) {
    throw Error(ErrorCode::kBadInput, "processing.map",
                "the valid samples do not cover a common axial span at all phases");
  }
  SetAxialNodes(y_low, y_high, options, map);
  CountCoverage(rho, geometry, despiked, y_low, map);
  if (clock != nullptr) clock->Stop();
  return map;
}

template <typename T>
WheelMap Build(std::span<const T> rho, const HelixGeometry& geometry, double noise_sigma_mm,
               std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  if (clock != nullptr) clock->Start("helix spline");
  WheelMap map = StartMap(rho, geometry, noise_sigma_mm, options);
  auto spline = std::make_shared<HelixSpline>(rho, geometry, map.knot_step_deg);

  if (clock != nullptr) clock->Start("sections and map");
  const auto n_phase = static_cast<std::size_t>(options.phases);
  map.phase_deg = PhaseNodes(options.phases);
  map.sections.resize(n_phase);
  for (std::size_t j = 0; j < n_phase; ++j) {
    map.sections[j] = SampleSection(*spline, geometry, map.phase_deg[j], options.min_support);
  }
  spline->ReleaseValues();  // the sections were their last use
  SetSectionSigmas(*spline, noise_sigma_mm, map.sections);
  DropImpreciseSectionPoints(map.sections, options.max_sigma_ratio);
  map.map_sigma_mm = MedianPointSigma(map.sections);
  double y_low = -std::numeric_limits<double>::infinity();
  double y_high = std::numeric_limits<double>::infinity();
  for (const Section& s : map.sections) {
    if (s.y_mm.size() < 2) continue;
    y_low = std::max(y_low, s.y_mm.front());
    y_high = std::min(y_high, s.y_mm.back());
  }
  if (!(y_high > y_low)) {
    throw Error(ErrorCode::kBadInput, "processing.map",
                "the valid samples do not cover a common axial span at all phases");
  }
  ThrowIfInterrupted();

  SetAxialNodes(y_low, y_high, options, map);
  const std::size_t n_y = map.n_y();
  for (std::size_t j = 0; j < n_phase; ++j) {
    InterpolateSection(map.sections[j], map.y_mm, map.pitch_mm, std::span(map.rho_mm).subspan(j * n_y, n_y));
  }

  if (clock != nullptr) clock->Start("coverage counts");
  CountCoverage(rho, geometry, despiked, y_low, map);
  map.spline = std::move(spline);
  ReturnFreedMemory();  // the spline's values, the sections' sigmas copied for their median
  if (clock != nullptr) clock->Stop();
  return map;
}

}  // namespace

std::vector<std::string> MapOptions::Problems() const {
  std::vector<std::string> problems;
  if (phases < 4 || phases > 36000)
    problems.push_back(fmt::format("--phases = {} violates 4..36000", phases));
  if (!std::isfinite(knot_step_deg) || knot_step_deg > 90)
    problems.push_back(fmt::format("--knot-step-deg = {} violates finite and <= 90", knot_step_deg));
  if (!std::isfinite(axial_step_mm))
    problems.push_back(fmt::format("--axial-step-mm = {} violates finite", axial_step_mm));
  if (min_support < 1) problems.push_back(fmt::format("map.min_support = {} violates >= 1", min_support));
  if (!(max_sigma_ratio >= 1.0))
    problems.push_back(fmt::format("map.max_sigma_ratio = {} violates >= 1", max_sigma_ratio));
  return problems;
}

WheelMap BuildWheelMap(std::span<const double> rho_mm, const HelixGeometry& geometry, double noise_sigma_mm,
                       std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  return Build(rho_mm, geometry, noise_sigma_mm, despiked, options, clock);
}

WheelMap PlanWheelMap(std::span<const double> rho_mm, const HelixGeometry& geometry, double noise_sigma_mm,
                      std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  return Plan(rho_mm, geometry, noise_sigma_mm, despiked, options, clock);
}

WheelMap PlanWheelMap(std::span<const float> rho_mm, const HelixGeometry& geometry, double noise_sigma_mm,
                      std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  return Plan(rho_mm, geometry, noise_sigma_mm, despiked, options, clock);
}

WheelMap BuildWheelMap(std::span<const float> rho_mm, const HelixGeometry& geometry, double noise_sigma_mm,
                       std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  return Build(rho_mm, geometry, noise_sigma_mm, despiked, options, clock);
}

}  // namespace arcwheel::processing
