#include "uncertainty/wheel_uncertainty.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <future>
#include <limits>

#include "core/error.h"
#include "core/nan.h"
#include "core/number_format.h"
#include "schema/summary.h"

namespace arcwheel::uncertainty {
namespace {

constexpr const char* kWheelUncertaintyStage = "uncertainty.wheel";
namespace s = schema::summary;

Input TypeA(std::string source, std::string unit, double sigma, double dof) {
  return Input{.name = "data",
               .source = std::move(source),
               .unit = std::move(unit),
               .distribution = Distribution::kNormal,
               .spread = sigma,
               .coverage_factor = 1.0,
               .sensitivity = 1.0,
               .dof = dof,
               .type = EvaluationType::kA};
}

std::string BootstrapSource(const NoiseCorrectedPv& pv, std::string_view basis) {
  return "noise-corrected PV by a parametric bootstrap of " + std::to_string(pv.replicates) + " data sets (" +
         std::string(basis) + " up to order " + std::to_string(pv.order) + ", " +
         std::to_string(pv.rows_used) + (pv.rows_used == 1 ? " row)" : " rows)");
}

// The bootstrap's seed: `base` mixed with a digest (FNV-1a) of the per-phase fits and the map,
// so that one scan always gives the same numbers and two scans draw independent streams. With
// one stream for every scan, the Monte Carlo error of each figure's u (7 % at 100 replicates) was
// the same in all of them: over 200 simulated scans it moved the coverage of one figure by up to
// 2.3 points, and history's chi-square between scans would inherit it. FNV-1a rather than a
// library's hash: its value is fixed by its definition, so the numbers do not move with a Boost or
// standard-library version.
std::uint64_t BootstrapSeed(const WheelObservations& o, std::uint64_t base) {
  std::uint64_t hash = 14695981039346656037ULL ^ base;
  const auto mix = [&hash](std::span<const double> values) {
    for (const double v : values) {
      std::uint64_t bits = 0;
      std::memcpy(&bits, &v, sizeof bits);
      for (int byte = 0; byte < 8; ++byte) {
        hash ^= (bits >> (8 * byte)) & 0xffU;
        hash *= 1099511628211ULL;
      }
    }
  };
  mix(o.arc_radius_mm);
  mix(o.center_axial_mm);
  mix(o.rho_mm);
  return hash;
}

// The largest order the basis can take on `columns` values.
int FitOrder(SmoothBasis basis, int wanted, int columns) {
  const int most = basis == SmoothBasis::kFourier ? (columns - 2) / 2 : columns - 2;
  return std::max(0, std::min(wanted, most));
}

}  // namespace

std::vector<std::string> WheelUncertaintyOptions::Problems() const {
  std::vector<std::string> problems;
  if (max_harmonic < 1)
    problems.push_back("WheelUncertaintyOptions::max_harmonic = " + std::to_string(max_harmonic) +
                       " violates >= 1");
  if (max_degree < 1)
    problems.push_back("WheelUncertaintyOptions::max_degree = " + std::to_string(max_degree) +
                       " violates >= 1");
  if (replicates < 20)
    problems.push_back("WheelUncertaintyOptions::replicates = " + std::to_string(replicates) +
                       " violates >= 20");
  return problems;
}

const QuantityUncertainty* WheelUncertainty::Find(std::string_view key) const {
  for (const QuantityUncertainty& q : quantities)
    if (q.key == key) return &q;
  return nullptr;
}

// The sections' points, rows = phases: the fit's (WheelObservations::section_*), or the map's
// nodes in the band with their geometric residuals against each phase's circle.
struct SectionPoints {
  int columns = 0;
  std::vector<double> residual_um, sigma_um, y_mm;
};

SectionPoints SectionPointsOf(const WheelObservations& o) {
  const std::size_t n_phase = o.arc_radius_mm.size();
  SectionPoints points;
  if (o.section_bins > 0) {
    const auto n = n_phase * static_cast<std::size_t>(o.section_bins);
    if (o.section_residual_um.size() != n || o.section_y_mm.size() != n || o.section_sigma_um.size() != n) {
      throw Error(ErrorCode::kBadInput, kWheelUncertaintyStage,
                  std::to_string(o.section_residual_um.size()) + " section points for " +
                      std::to_string(n_phase) + " phases of " + std::to_string(o.section_bins) + " bins");
    }
    points.columns = o.section_bins;
    points.residual_um.assign(o.section_residual_um.begin(), o.section_residual_um.end());
    points.sigma_um.assign(o.section_sigma_um.begin(), o.section_sigma_um.end());
    points.y_mm.assign(o.section_y_mm.begin(), o.section_y_mm.end());
    for (std::size_t p = 0; p < n_phase; ++p)
      if (o.usable[p] == 0)
        std::fill_n(points.residual_um.begin() + static_cast<std::ptrdiff_t>(p * o.section_bins),
                    o.section_bins, kNaN);
    return points;
  }
  const std::size_t n_y = o.y_mm.size();
  std::vector<std::size_t> band;
  for (std::size_t j = 0; j < n_y; ++j)
    if (o.y_mm[j] >= o.band_low_mm && o.y_mm[j] <= o.band_high_mm) band.push_back(j);
  points.columns = static_cast<int>(band.size());
  for (std::size_t p = 0; p < n_phase; ++p) {
    for (const std::size_t j : band) {
      const double dy = o.y_mm[j] - o.center_axial_mm[p];
      const double drho = o.rho_mm[p * n_y + j] - o.center_radial_mm[p];
      points.residual_um.push_back(o.usable[p] != 0 ? (std::hypot(dy, drho) - o.arc_radius_mm[p]) * 1000.0
                                                    : kNaN);
      points.sigma_um.push_back(o.map_sigma_mm * 1000.0);
      points.y_mm.push_back(o.y_mm[j]);
    }
  }
  return points;
}

// The max arc error: each section's residuals fitted with Legendre degrees at their own positions
// across the band, the degrees' coefficients fitted along the phases, the PV of the fitted
// residual over the whole band (the interval the fits read).
std::optional<NoiseCorrectedPv> EstimateArcError(const WheelObservations& o,
                                                 const WheelUncertaintyOptions& options) {
  const SectionPoints points = SectionPointsOf(o);
  const double centre = 0.5 * (o.band_low_mm + o.band_high_mm);
  const double half = 0.5 * (o.band_high_mm - o.band_low_mm);
  const bool has_noise =
      std::any_of(points.sigma_um.begin(), points.sigma_um.end(), [](double s) { return s > 0.0; });
  if (points.columns < 4 || !(half > 0.0) || !has_noise) return std::nullopt;
  std::vector<double> u(points.y_mm.size());
  for (std::size_t k = 0; k < u.size(); ++k) u[k] = (points.y_mm[k] - centre) / half;
  const int phases = static_cast<int>(o.arc_radius_mm.size());
  const NoiseCorrectedPvOptions across{
      .basis = SmoothBasis::kLegendre,
      .max_order = FitOrder(SmoothBasis::kLegendre, options.max_degree, points.columns),
      .pv_from_order = 0,
      .replicates = options.replicates,
      // The rows are the phases, over a full turn: each degree's coefficient varies smoothly
      // with the phase (the arc centre's and radius's harmonics move the residual's shape).
      .across_rows_max_degree = FitOrder(SmoothBasis::kFourier, options.max_harmonic, phases),
      .across_rows_basis = SmoothBasis::kFourier,
      // Ten standard deviations of a function's chi-square (a drop over 15.1 for one function,
      // p = 1e-4): each of some 240 candidates (five degrees x 24 harmonics x cos, sin) is tried; at
      // five (8.1, p = 0.0045) about one harmonic of noise a scan rode on the fit, whose maximum
      // over the phases the bootstrap does not correct: over the coverage test's 1000 scans the
      // errors scattered by 0.0165 um, u 0.0148 um, covered 97.2 % (twice the scatter in most
      // scans, too narrow in the fifth that took noise in); at ten 0.0065 um, u 0.0062 um, 95.3 %.
      // (At three, 91.5 % over 200 scans.)
      .across_rows_keep_sd = 10.0,
      .seed = options.seed + 4};
  return EstimateNoiseCorrectedPv(points.residual_um, points.sigma_um, u, phases, points.columns, across);
}

WheelUncertainty EvaluateWheelUncertainty(const WheelObservations& o, const BudgetFile& budget,
                                          const WheelUncertaintyOptions& given) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kWheelUncertaintyStage, given.Problems());
  WheelUncertaintyOptions options = given;
  options.seed = BootstrapSeed(o, given.seed);
  const std::size_t n_phase = o.arc_radius_mm.size();
  const std::size_t n_y = o.y_mm.size();
  if (o.arc_radius_sigma_mm.size() != n_phase || o.center_axial_mm.size() != n_phase ||
      o.center_axial_sigma_mm.size() != n_phase || o.center_radial_mm.size() != n_phase ||
      o.usable.size() != n_phase || o.rho_mm.size() != n_phase * n_y || n_phase < 8) {
    throw Error(ErrorCode::kBadInput, kWheelUncertaintyStage,
                "per-phase arrays and the map do not match (" + std::to_string(n_phase) + " phases, " +
                    std::to_string(n_y) + " axial nodes, " + std::to_string(o.rho_mm.size()) +
                    " map values)");
  }
  const int phases = static_cast<int>(n_phase);
  const auto usable = [&](std::size_t p) { return o.usable[p] != 0; };

  // Per-phase series, unusable phases missing.
  std::vector<double> radius(n_phase), radius_sigma(n_phase), axial(n_phase), axial_sigma(n_phase);
  for (std::size_t p = 0; p < n_phase; ++p) {
    radius[p] = usable(p) ? o.arc_radius_mm[p] : kNaN;
    radius_sigma[p] = o.arc_radius_sigma_mm[p];
    axial[p] = usable(p) ? o.center_axial_mm[p] : kNaN;
    axial_sigma[p] = o.center_axial_sigma_mm[p];
  }
  // The arc error's estimate (the largest, with a serial setup of a fit a section) on a thread of its
  // own beside the map's four: each bootstrap's two workers leave a core idle part of the time.
  std::future<std::optional<NoiseCorrectedPv>> arc_error_estimate =
      std::async(std::launch::async, [&] { return EstimateArcError(o, options); });
  NoiseCorrectedPvOptions series{.basis = SmoothBasis::kFourier,
                                 .max_order = FitOrder(SmoothBasis::kFourier, options.max_harmonic, phases),
                                 .pv_from_order = 0,
                                 .replicates = options.replicates,
                                 .seed = options.seed};
  const NoiseCorrectedPv range = EstimateNoiseCorrectedPv(radius, radius_sigma, 1, phases, series);
  series.seed = options.seed + 1;
  const NoiseCorrectedPv centre = EstimateNoiseCorrectedPv(axial, axial_sigma, 1, phases, series);

  // The map over the band: rows = axial nodes, columns = phases (runout, roundness).
  std::vector<std::size_t> band;
  for (std::size_t j = 0; j < n_y; ++j)
    if (o.y_mm[j] >= o.band_low_mm && o.y_mm[j] <= o.band_high_mm) band.push_back(j);
  const double map_sigma_um = o.map_sigma_mm * 1000.0;
  std::optional<NoiseCorrectedPv> runout, roundness, arc_error;
  if (!band.empty() && map_sigma_um > 0.0) {
    std::vector<double> rows(band.size() * n_phase), sigmas(rows.size(), map_sigma_um);
    for (std::size_t i = 0; i < band.size(); ++i)
      for (std::size_t p = 0; p < n_phase; ++p) rows[i * n_phase + p] = o.rho_mm[p * n_y + band[i]] * 1000.0;
    NoiseCorrectedPvOptions turn = series;
    // u is the replicates' spread, as for the other figures: over the coverage test's 1000 scans
    // the runout's errors scatter by 1.07 u (covered 95.1 %), the roundness's by 1.10 u (95.6 %).
    // A double bootstrap (each replicate's own bias from two data sets drawn from its fit) was
    // needed while the map carried a sawtooth of the profile's slope over the turn; without it,
    // it made the intervals too wide (0.93 u and 0.97 u, covered 96.8 % and 98.5 %).
    // The rows are the band's axial nodes in order: each harmonic varies smoothly along them.
    turn.across_rows_max_degree = std::min(options.max_degree, static_cast<int>(band.size()) - 2);
    turn.seed = options.seed + 2;
    runout = EstimateNoiseCorrectedPv(rows, sigmas, static_cast<int>(band.size()), phases, turn);
    turn.pv_from_order = std::min(2, turn.max_order);
    turn.seed = options.seed + 3;
    roundness = EstimateNoiseCorrectedPv(rows, sigmas, static_cast<int>(band.size()), phases, turn);
  }
  arc_error = arc_error_estimate.get();

  WheelUncertainty out;
  out.budget = budget;
  if (arc_error) {
    out.smoothed_section_um = arc_error->fitted_rows;
    out.section_sigma_scale = arc_error->sigma_scale;
  }
  for (const std::string& key : BudgetQuantityKeys()) {
    QuantityUncertainty q;
    q.key = key;
    q.unit = QuantityUnit(key);
    double estimate = kNaN;
    if (key == s::kMeanArcRadiusMm) {
      q.measured = o.mean_arc_radius_mm;
      estimate = q.measured;
      q.type_a_method = "per-phase fits: sigma of the mean from the noise";
      q.inputs.push_back(TypeA(q.type_a_method, "mm", o.mean_arc_radius_sigma_mm, kInfiniteDof));
    } else {
      const NoiseCorrectedPv* pv = nullptr;
      double scale = 1.0;
      std::string_view basis = "harmonics";
      if (key == s::kArcRadiusRangeMm) {
        q.measured = o.arc_radius_range_mm, pv = &range;
      } else if (key == s::kArcRadiusFluctuationPct) {
        q.measured = o.arc_radius_fluctuation_pct, pv = &range, scale = 100.0 / o.mean_arc_radius_mm;
      } else if (key == s::kCenterAxialDeviationMm) {
        q.measured = o.center_axial_deviation_mm, pv = &centre;
      } else if (key == s::kMaxRunoutUm) {
        q.measured = o.max_runout_um, pv = runout ? &*runout : nullptr;
      } else if (key == s::kMaxRoundnessUm) {
        q.measured = o.max_roundness_um, pv = roundness ? &*roundness : nullptr;
      } else if (key == s::kMaxArcErrorUm) {
        q.measured = o.max_arc_error_um, pv = arc_error ? &*arc_error : nullptr, basis = "Legendre degrees";
      }
      if (pv) {
        estimate = pv->value * scale;
        q.noise_bias = q.measured - estimate;
        q.type_a_method = BootstrapSource(*pv, basis);
        q.inputs.push_back(TypeA(q.type_a_method, q.unit, pv->standard_uncertainty * scale, pv->dof));
      } else {
        q.type_a_method = "not available: no map values in the band";
        q.inputs.push_back(TypeA(q.type_a_method, q.unit, kNaN, kInfiniteDof));
      }
    }
    const auto found = budget.quantities.find(key);
    if (found != budget.quantities.end()) {
      for (Input& input : ResolveInputs(found->second, estimate)) q.inputs.push_back(std::move(input));
    }
    if (std::isfinite(q.inputs.front().spread)) {
      q.combined = Combine(q.inputs, budget.combine);
      q.value = estimate + q.combined.correction;
    } else {
      q.combined.standard_uncertainty = q.combined.expanded = q.combined.coverage_factor = kNaN;
      q.value = kNaN;
    }
    out.quantities.push_back(std::move(q));
  }
  return out;
}

void DecideConformity(WheelUncertainty& uncertainty,
                      const std::map<std::string, Specification>& specifications, DecisionRule rule) {
  uncertainty.rule = rule;
  uncertainty.decisions.clear();
  for (const auto& [key, specification] : specifications) {
    const QuantityUncertainty* q = uncertainty.Find(key);
    if (q == nullptr)
      throw Error(ErrorCode::kBadInput, kWheelUncertaintyStage,
                  "no uncertainty is evaluated for '" + key + "'");
  }
  // In the budget's order (the report's), not the map's.
  for (const QuantityUncertainty& q : uncertainty.quantities) {
    const auto found = specifications.find(q.key);
    if (found == specifications.end()) continue;
    uncertainty.decisions.push_back(
        {.key = q.key,
         .specification = found->second,
         .decision = Decide(q.value, q.combined.expanded, found->second, {.rule = rule})});
  }
}

}  // namespace arcwheel::uncertainty
