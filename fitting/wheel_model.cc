#include "fitting/wheel_model.h"

#include <fmt/format.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <span>
#include <string>
#include <utility>
#include <vector>

#include "core/error.h"
#include "fitting/wheel_model_impl.h"

namespace arcwheel::fitting {
namespace {

using namespace internal;

Grid GridOf(const processing::WheelMap& map) {
  Grid grid;
  grid.n_phase = map.n_phase();
  grid.n_y = map.n_y();
  if (grid.empty()) return grid;
  grid.phase_step_deg = 360.0 / static_cast<double>(grid.n_phase);
  grid.y0_mm = map.y_mm.front();
  grid.y_step_mm = map.y_mm[1] - map.y_mm[0];
  return grid;
}

VectorXd StartingPoint(const Layout& layout, const WheelFit& fit) {
  VectorXd theta = VectorXd::Zero(layout.size());
  theta.head(layout.radius.knots).setConstant(fit.mean_arc_radius_mm);
  theta.segment(layout.a0(), layout.axial.knots).setConstant(fit.mean_center_axial_mm);
  theta.segment(layout.b0(), layout.runout.knots).setConstant(fit.mean_center_radial_mm);
  return theta;
}

}  // namespace

std::vector<std::string> WheelModelOptions::Problems() const {
  std::vector<std::string> problems;
  const auto knots = [&](const char* name, int value) {
    if (value != 0 && value != 1 && (value < 4 || value > 360)) {
      problems.push_back(fmt::format("{} = {} violates 0 (chosen from the data), 1 or 4..360", name, value));
    }
  };
  knots("model-knots", radius_knots);
  knots("model-axial-knots", axial_knots);
  knots("model-runout-knots", runout_knots);
  if (!(profile_knot_step_mm >= 0.05 && profile_knot_step_mm <= 10.0)) {
    problems.push_back(fmt::format("model-profile-step-mm = {} violates 0.05..10", profile_knot_step_mm));
  }
  if (max_iterations < 1)
    problems.push_back(fmt::format("model max_iterations = {} violates >= 1", max_iterations));
  if (!(significance_level > 0.0 && significance_level < 0.5)) {
    problems.push_back(
        fmt::format("model significance_level = {} violates 0 < level < 0.5", significance_level));
  }
  if (harmonics < 1) problems.push_back(fmt::format("model harmonics = {} violates >= 1", harmonics));
  return problems;
}

namespace {

// The warm-up's stride: one sample from each run of this many (1: no warm-up).
std::size_t WarmUpStride(std::size_t total, std::size_t warm_start_samples) {
  if (warm_start_samples == 0 || total < 4 * warm_start_samples) return 1;
  return total / warm_start_samples;
}

// Fits at the finest knots asked for, then, where the knots are to be chosen, picks them by the
// BIC from the fine fit's linearised normal equations and refits there, and maps the residuals.
//
// With a warm-up, the fine fit converges on a subsample; two Gauss-Newton steps over every sample
// from there give the fine fit's normal equations where the fit over every sample has them (the
// model is so nearly linear that one step from the subsample's optimum lands on the full one to
// many digits). They choose the knots, and their linearised solution at the chosen knots is so
// close to the optimum there that one more pass (J^T r and r^T r only, J^T J taken from the fine
// pass, the residual map beside) meets the convergence rule; else full iterations follow. Without
// the warm-up, every Gauss-Newton iteration passes over every sample, and the residual map takes
// a pass of its own.
template <typename Sample>
Fitted FitAndChoose(const Samples<Sample>& samples_in, const Grid& grid, const WheelFit& fit,
                    const WheelModelOptions& options, double half_width_mm, WheelModel& model) {
  const std::vector<int> choices[3] = {KnotCandidates(options.radius_knots, true),
                                       KnotCandidates(options.axial_knots, true),
                                       KnotCandidates(options.runout_knots, false)};
  const Layout fine = MakeLayout({choices[0].back(), choices[1].back(), choices[2].back()}, half_width_mm,
                                 options.profile_knot_step_mm);
  const MatrixXd null_space = ProfileNullSpace(fine.profile, half_width_mm);
  const MatrixXd fine_reduction = Reduction(fine, fine.knots(), null_space);
  VectorXd start = StartingPoint(fine, fit);
  // Binned: every pass but the residual map's runs on the cells, so no warm-up is needed.
  HelixCells cells;
  const bool binned =
      samples_in.rho_mm.size() > options.binned_above_samples && samples_in.geometry.from_settings();
  if (binned) cells = BinSamples(samples_in, fine);
  Samples<Sample> samples = samples_in;
  if (binned) samples.cells = &cells;
  const std::size_t stride = binned ? 1 : WarmUpStride(samples.rho_mm.size(), options.warm_start_samples);
  const bool warm = stride > 1;
  if (warm) {
    const Solution subsample = Converge(
        samples, fine, fine_reduction, start,
        {.stride = stride, .max_iterations = options.max_iterations, .throw_if_not_converged = false});
    // A subsample that cannot support the fine knots leaves the start as it was.
    if (subsample.converged && subsample.theta.allFinite()) start = subsample.theta;
  }
  Solution best =
      warm ? OneStep(samples, fine, fine_reduction, start)
           : Converge(samples, fine, fine_reduction, start, {.max_iterations = options.max_iterations});
  if (warm) {
    // J at the subsample's optimum is off J at the full data's in its fourth digit (through p'(u)
    // above all), and the knots, the test of Ra's constancy and the covariance depend on J^T J:
    // one more step puts it where the fit over every sample has it.
    const int first = best.iterations;
    best = OneStep(samples, fine, fine_reduction, best.theta);
    best.iterations += first;
  }
  model.knots_chosen = choices[0].size() > 1 || choices[1].size() > 1 || choices[2].size() > 1;
  const Knots knots = model.knots_chosen ? ChooseKnots(best, fine, choices, null_space) : fine.knots();
  Fitted fitted;
  fitted.layout = MakeLayout(knots, half_width_mm, options.profile_knot_step_mm);
  fitted.variation = VariationAtFineFit(best, fine, knots, null_space);
  const PartRanges ranges = best.ranges;
  const int iterations = best.iterations;
  ConvergeRequest request{
      .max_iterations = options.max_iterations, .grid = warm ? &grid : nullptr, .ranges = &ranges};
  if (!(knots == fine.knots())) {
    const LinearisedFit linear = Linearise(best, Reduction(fine, knots, null_space));
    const MatrixXd reduction = Reduction(fitted.layout, knots, null_space);
    if (warm) request.reduced_jtj = linear.reduced_jtj;
    best = Converge(samples, fitted.layout, reduction, reduction * linear.x, std::move(request));
    best.iterations += iterations;
  } else if (warm) {
    request.reduced_jtj = best.reduced_jtj;
    const VectorXd from = best.theta;
    best = Converge(samples, fine, fine_reduction, from, std::move(request));
    best.iterations += iterations;
  }
  if (warm) {
    fitted.residual_um = ResidualMap(grid, best.cells);
  } else if (binned) {
    fitted.residual_um = CellResidualMap(samples_in, cells, grid, fitted.layout, best.theta);
  } else {
    // As the fit was defined: the residuals at the solution, one more pass.
    const PassResult pass =
        Accumulate(samples, fitted.layout, best.theta, {.normal_matrix = false, .grid = &grid}, &best.ranges);
    fitted.residual_um = ResidualMap(grid, pass.cells);
  }
  fitted.solution = std::move(best);
  return fitted;
}

template <typename Sample>
WheelModel Fit(std::span<const Sample> rho_mm, const processing::HelixGeometry& geometry,
               const processing::WheelMap& map, const WheelFit& fit, const WheelModelOptions& options) {
  ThrowIfProblems(ErrorCode::kInvalidOption, kStage, options.Problems());
  WheelModel model;
  model.band_low_mm = fit.band_low_mm;
  model.band_high_mm = fit.band_high_mm;
  model.center_axial_reference_mm = fit.mean_center_axial_mm;
  const double half_width_mm =
      std::max(fit.mean_center_axial_mm - fit.band_low_mm, fit.band_high_mm - fit.mean_center_axial_mm);
  const Samples<Sample> samples{rho_mm, geometry, fit.band_low_mm, fit.band_high_mm};
  const Grid grid = GridOf(map);

  Fitted f = FitAndChoose(samples, grid, fit, options, half_width_mm, model);
  const Solution& s = f.solution;
  const auto parameters = static_cast<std::size_t>(s.reduction.cols());
  if (s.normal.samples < 4 * parameters) {
    throw Error(ErrorCode::kFitFailed, kStage,
                fmt::format("the band holds {} samples, too few for the wheel model's {} parameters",
                            s.normal.samples, parameters));
  }
  f.sigma2 = s.normal.rss / static_cast<double>(s.normal.samples - parameters);
  f.covariance = s.reduction * (f.sigma2 * s.reduced_jtj.inverse()) * s.reduction.transpose();

  model.fitted = true;
  model.radius_knots = f.layout.radius.knots;
  model.axial_knots = f.layout.axial.knots;
  model.runout_knots = f.layout.runout.knots;
  model.variation_chi2 = f.variation.chi2;
  model.variation_dof = f.variation.dof;
  model.variation_p_value = f.variation.p_value;
  model.profile_coefficients = f.layout.profile.size();
  model.samples = s.normal.samples;
  model.parameters = static_cast<int>(parameters);
  model.iterations = s.iterations;
  model.residual_rms_um = std::sqrt(s.normal.rss / static_cast<double>(s.normal.samples)) * 1e3;
  model.noise_sigma_um = map.noise_sigma_mm * 1e3;
  model.phase_deg = map.phase_deg;
  SampleFunctions(f, map.phase_deg, model);
  SummariseRadius(f, map.phase_deg, model);
  model.significance_level = options.significance_level;
  model.variation_significant = model.variation_p_value < options.significance_level;
  RadiusHarmonics(f, options.harmonics, model);
  SampleProfile(f, half_width_mm, model);
  model.residual_um = std::move(f.residual_um);
  model.coefficients.assign(s.theta.data(), s.theta.data() + s.theta.size());
  model.covariance.assign(f.covariance.data(), f.covariance.data() + f.covariance.size());
  return model;
}

}  // namespace

WheelModel FitWheelModel(std::span<const double> rho_mm, const processing::HelixGeometry& geometry,
                         const processing::WheelMap& map, const WheelFit& fit,
                         const WheelModelOptions& options) {
  return Fit(rho_mm, geometry, map, fit, options);
}

WheelModel FitWheelModel(std::span<const float> rho_mm, const processing::HelixGeometry& geometry,
                         const processing::WheelMap& map, const WheelFit& fit,
                         const WheelModelOptions& options) {
  return Fit(rho_mm, geometry, map, fit, options);
}

}  // namespace arcwheel::fitting
