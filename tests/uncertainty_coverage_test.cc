// Coverage of the 95 % intervals over simulated scans with known truth (issue 30, "Done when"):
// the fraction of scans whose value +- U covers the truth, for the mean arc radius and each
// noise-corrected peak-to-valley figure. The simulator injects no type B error, so the budget is
// empty: the interval is the type A part alone (the fit's sigma, the bootstrap's spread).
//
// The truth of each figure is what the same pipeline finds on the same wheel scanned without
// noise (for the mean arc radius too: with a profile error the least-squares circle over the band
// is not the model's 55.4423 mm, by some 0.09 mm here), except the max arc error's: the wheel
// model's own sections over the band (TrueMaxArcErrorUm), computed here without the pipeline. CI runs
// ARCWHEEL_COVERAGE_SCANS = 24 scans (default) and checks coverage loosely; from 200 scans it checks
// 93-97 %, and the long test of record,
//   ARCWHEEL_COVERAGE_SCANS=1000 build/tests/tests_tests --gtest_filter='UncertaintyCoverage.*'
// prints the figures docs/uncertainty.md quotes (at 200, six figures all inside is a coin toss).

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>
#include <vector>

#include "acquisition/simulate.h"
#include "core/number_format.h"
#include "core/progress.h"
#include "workflows/process_pipeline.h"

namespace arcwheel {
namespace {

using acquisition::Harmonic;

acquisition::WheelModel Wheel() {
  acquisition::WheelModel wheel;
  wheel.arc_radius_harmonics_mm = {Harmonic{.order = 2, .amplitude = 0.004}};
  wheel.center_axial_harmonics_mm = {Harmonic{.order = 1, .amplitude = 0.003}};
  wheel.radial_harmonics_um = {Harmonic{.order = 1, .amplitude = 3.0},
                               Harmonic{.order = 3, .amplitude = 0.8}};
  wheel.profile_legendre_um = {0.0, 0.0, 0.6, 0.0, -0.4};
  return wheel;
}

// The wheel's true max arc error over the band [-8, 8] mm (the mean arc centre is at 0): at each
// whole degree, the section R(c, y) of the model on 1601 points, its geometric least-squares
// circle by Gauss-Newton from the model's circle, and the PV of the residuals.
double TrueMaxArcErrorUm(const acquisition::WheelModel& wheel) {
  const int points = 1601;
  double largest = 0.0;
  for (int phase = 0; phase < 360; ++phase) {
    Eigen::VectorXd y(points), rho(points);
    for (int k = 0; k < points; ++k) {
      y[k] = -8.0 + 16.0 * k / (points - 1);
      rho[k] = wheel.SmoothRadiusMm(phase, y[k]);
    }
    Eigen::Vector3d circle(wheel.CenterAxialMm(phase), wheel.CenterDistanceMm(phase),
                           wheel.ArcRadiusMm(phase));
    Eigen::VectorXd e(points);
    for (int iteration = 0; iteration < 20; ++iteration) {
      Eigen::MatrixXd jacobian(points, 3);
      for (int k = 0; k < points; ++k) {
        const double dy = y[k] - circle[0], drho = rho[k] - circle[1];
        const double d = std::hypot(dy, drho);
        e[k] = d - circle[2];
        jacobian.row(k) << -dy / d, -drho / d, -1.0;
      }
      circle -= jacobian.colPivHouseholderQr().solve(e);
    }
    largest = std::max(largest, (e.maxCoeff() - e.minCoeff()) * 1000.0);
  }
  return largest;
}

workflows::ProcessPipelineResult Scan(double noise_um, unsigned seed,
                                      const acquisition::WheelModel& wheel = Wheel()) {
  acquisition::ScanSettings settings;
  settings.noise_um = noise_um;
  settings.seed = seed;
  auto simulated = acquisition::SimulateScan(wheel, settings);
  workflows::ProcessPipelineOptions options;
  options.no_model = true;
  options.uncertainty_budget = uncertainty::BudgetFile{};  // type A only: nothing else is injected
  Progress quiet(false);
  return workflows::RunProcessPipeline(std::move(simulated.scan), "", "", options, quiet);
}

int Scans() {
  const char* text = std::getenv("ARCWHEEL_COVERAGE_SCANS");
  return text ? std::max(1, std::atoi(text)) : 24;
}

// The first scan's seed (the scans take the next ones): 1000 unless ARCWHEEL_COVERAGE_FIRST_SEED
// says otherwise, so that a check on other scans than those the estimators were tuned on is one
// command (docs/uncertainty.md: 5000 for 300 scans).
unsigned FirstSeed() {
  const char* text = std::getenv("ARCWHEEL_COVERAGE_FIRST_SEED");
  return text ? static_cast<unsigned>(std::max(0, std::atoi(text))) : 1000u;
}

TEST(UncertaintyCoverage, NinetyFivePercentIntervalsCoverTheTruth) {
  const std::vector<std::string> keys = {
      "mean_arc_radius_mm", "arc_radius_range_mm", "center_axial_deviation_mm",
      "max_arc_error_um",   "max_runout_um",       "max_roundness_um"};
  const workflows::ProcessPipelineResult exact = Scan(0.0, 1);
  std::map<std::string, double> truth;
  for (const std::string& key : keys) truth[key] = exact.uncertainty->Find(key)->measured;
  fmt::print("max arc error: the model's {:.4f} um, the noise-free scan's {:.4f} um\n",
             TrueMaxArcErrorUm(Wheel()), truth["max_arc_error_um"]);
  truth["max_arc_error_um"] = TrueMaxArcErrorUm(Wheel());

  const int scans = Scans();
  std::map<std::string, int> covered;
  std::map<std::string, double> error_sum, error_squares, u_sum, raw_bias_sum;
  for (int i = 0; i < scans; ++i) {
    const workflows::ProcessPipelineResult result = Scan(0.4, FirstSeed() + i);
    for (const std::string& key : keys) {
      const uncertainty::QuantityUncertainty& q = *result.uncertainty->Find(key);
      const double error = q.value - truth[key];
      covered[key] += std::abs(error) <= q.combined.expanded;
      error_sum[key] += error;
      error_squares[key] += error * error;
      u_sum[key] += q.combined.standard_uncertainty;
      raw_bias_sum[key] += q.measured - truth[key];
    }
  }
  fmt::print("coverage over {} scans (seeds {}-{}, noise 0.4 um), 95 % intervals:\n", scans, FirstSeed(),
             FirstSeed() + scans - 1);
  fmt::print("{:<28} {:>12} {:>12} {:>12} {:>12} {:>12} {:>9}\n", "quantity", "truth", "raw bias",
             "mean error", "sd of error", "mean u", "covered");
  for (const std::string& key : keys) {
    const double mean_error = error_sum[key] / scans;
    const double sd_error = std::sqrt(std::max(0.0, error_squares[key] - scans * mean_error * mean_error) /
                                      std::max(1, scans - 1));
    fmt::print("{:<28} {:>12.6g} {:>12.3g} {:>12.3g} {:>12.3g} {:>12.3g} {:>8.1f}%\n", key, Shown(truth[key]),
               Shown(raw_bias_sum[key] / scans), Shown(mean_error), Shown(sd_error),
               Shown(u_sum[key] / scans), Shown(100.0 * covered[key] / scans));
  }
  for (const std::string& key : keys) {
    const double fraction = static_cast<double>(covered[key]) / scans;
    if (scans >= 200) {
      EXPECT_GE(fraction, 0.93) << key;
      EXPECT_LE(fraction, 0.97) << key;
    } else {
      // 24 scans at 95 %: 22.8 expected, binomial sd 1.1; at least 19 holds with p > 0.998.
      EXPECT_GE(fraction, 19.0 / 24.0) << key;
    }
  }
}

// A pure P3 profile error of 0.5 um over the rim's +-10 mm: over the band's +-8 mm (h = 0.8 of
// the rim) the least-squares circle takes the cubic's linear part, and the residual is 0.5 h^3
// P3(y / 8 mm), whose PV over the band is 0.5 x 0.8^3 x 2 = 0.512 um to first order (the circle
// is not a parabola: the model's sections give 0.508 um). The estimate's interval holds the
// model's figure; the raw figure of the noisy scan lies far above.
TEST(UncertaintyCoverage, TheArcErrorOfACubicProfileIsTheClosedForm) {
  acquisition::WheelModel wheel;
  wheel.profile_legendre_um = {0.0, 0.0, 0.0, 0.5};
  const double closed_form_um = 0.5 * 0.8 * 0.8 * 0.8 * 2.0;
  const double truth_um = TrueMaxArcErrorUm(wheel);
  EXPECT_NEAR(truth_um, closed_form_um, 0.01 * closed_form_um);
  const workflows::ProcessPipelineResult result = Scan(0.4, 77, wheel);
  const uncertainty::QuantityUncertainty& q = *result.uncertainty->Find("max_arc_error_um");
  EXPECT_NEAR(q.value, truth_um, q.combined.expanded);
  EXPECT_LT(q.combined.expanded, 0.05);
  EXPECT_GT(q.measured, closed_form_um + 0.5);
}

}  // namespace
}  // namespace arcwheel
