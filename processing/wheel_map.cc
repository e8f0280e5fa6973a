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
#include "core/parallel.h"
#include "processing/cubic_interpolation.h"

namespace arcwheel::processing {
namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

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
    const double t = (y_mm - y_low_) / axial_step_;
    if (!(t > -0.5) || !(t < static_cast<double>(n_y_))) return -1;  // round(-0.4) is -0: row 0
    const long m = RoundHalfAway(t);
    if (m >= n_y_) return -1;
    // The phase in the turn lies in [0, 360): its node is 0 .. n_phase, and n_phase is node 0
    // (a comparison instead of a 64-bit division per sample).
    long j = RoundHalfAway(PhaseInTurn(u_deg) / phase_step_);
    if (j == n_phase_) j = 0;
    return j * n_y_ + m;
  }

 private:
  long n_phase_, n_y_;
  double phase_step_, y_low_, axial_step_;
};

// Coverage diagnostics: raw and despiked samples per cell around each node. Two workers count the
// two halves of the scan (integer sums: the same on any machine).
template <typename T>
void CountCoverage(std::span<const T> rho, const HelixGeometry& geometry,
                   std::span<const std::size_t> despiked, double y_low, WheelMap& map) {
  const CellOfSample cell_of(map.n_phase(), map.n_y(), y_low, map.axial_step_mm);
  const std::size_t cells = map.n_phase() * map.n_y();
  std::vector<int> upper(cells, 0);
  map.sample_count.assign(cells, 0);
  RunOnWorkers(2, [&](int half) {
    std::vector<int>& counts = half == 0 ? map.sample_count : upper;
    const std::size_t begin = half == 0 ? 0 : rho.size() / 2;
    const std::size_t end = half == 0 ? rho.size() / 2 : rho.size();
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

template <typename T>
WheelMap Build(std::span<const T> rho, const HelixGeometry& geometry, double noise_sigma_mm,
               std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  ThrowIfProblems(ErrorCode::kInvalidOption, "processing.map", options.Problems());
  if (clock != nullptr) clock->Start("helix spline");
  const auto valid = static_cast<std::size_t>(
      std::count_if(rho.begin(), rho.end(), [](T v) { return std::isfinite(static_cast<double>(v)); }));
  WheelMap map;
  map.noise_sigma_mm = noise_sigma_mm;
  map.knot_step_deg = ChooseKnotStep(options, geometry, valid);
  map.pitch_mm = geometry.PitchMm();
  auto spline = std::make_shared<HelixSpline>(rho, geometry, map.knot_step_deg);

  if (clock != nullptr) clock->Start("sections and map");
  const auto n_phase = static_cast<std::size_t>(options.phases);
  map.phase_deg.resize(n_phase);
  map.sections.resize(n_phase);
  for (std::size_t j = 0; j < n_phase; ++j) {
    map.phase_deg[j] = 360.0 * static_cast<double>(j) / options.phases;
    map.sections[j] = SampleSection(*spline, geometry, map.phase_deg[j], options.min_support);
  }
  spline->ReleaseValues();  // the sections were their last use
  SetSectionSigmas(*spline, noise_sigma_mm, map.sections);
  DropImpreciseSectionPoints(map.sections, options.max_sigma_ratio);
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

  map.axial_step_mm = options.axial_step_mm > 0 ? options.axial_step_mm : std::abs(map.pitch_mm);
  const auto n_y = static_cast<std::size_t>(std::floor((y_high - y_low) / map.axial_step_mm + 1e-9)) + 1;
  map.y_mm.resize(n_y);
  for (std::size_t m = 0; m < n_y; ++m) map.y_mm[m] = y_low + static_cast<double>(m) * map.axial_step_mm;
  map.rho_mm.assign(n_phase * n_y, kNaN);
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

WheelMap BuildWheelMap(std::span<const float> rho_mm, const HelixGeometry& geometry, double noise_sigma_mm,
                       std::span<const std::size_t> despiked, const MapOptions& options, StageClock* clock) {
  return Build(rho_mm, geometry, noise_sigma_mm, despiked, options, clock);
}

}  // namespace arcwheel::processing
