// Coverage of each characteristic's 95 % interval under its operator (docs/characteristics.md),
// over simulated scans of two wheels: the paper-like wheel of tests/uncertainty_coverage_test and
// a wheel lobed at 15, 30 and 50 UPR, near the 50 UPR cut-off where the filter's slope meets the
// noise. The truth of each characteristic is the same operator on the same wheel scanned without
// noise (its map's values are then the wheel's, and the bootstrap has nothing to add). The
// simulator injects no type B error, so the budget is empty: the interval is the type A part alone.
//
// CI runs ARCWHEEL_COVERAGE_SCANS = 12 scans a wheel (default) and checks coverage loosely; from
// 200 scans it checks 93-97 %. The long test of record:
//   ARCWHEEL_COVERAGE_SCANS=1000 build/tests/tests_tests --gtest_filter='CharacteristicsCoverage.*'
// prints the figures docs/characteristics.md quotes.

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <algorithm>
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

acquisition::WheelModel PaperLikeWheel() {
  acquisition::WheelModel wheel;
  wheel.arc_radius_harmonics_mm = {Harmonic{.order = 2, .amplitude = 0.004}};
  wheel.center_axial_harmonics_mm = {Harmonic{.order = 1, .amplitude = 0.003}};
  wheel.radial_harmonics_um = {Harmonic{.order = 1, .amplitude = 3.0},
                               Harmonic{.order = 3, .amplitude = 0.8}};
  wheel.profile_legendre_um = {0.0, 0.0, 0.6, 0.0, -0.4};
  return wheel;
}

acquisition::WheelModel LobedWheel() {
  acquisition::WheelModel wheel = PaperLikeWheel();
  wheel.radial_harmonics_um = {Harmonic{.order = 1, .amplitude = 2.0},
                               Harmonic{.order = 15, .amplitude = 0.5, .phase_deg = 10.0},
                               Harmonic{.order = 30, .amplitude = 0.4, .phase_deg = 70.0},
                               Harmonic{.order = 50, .amplitude = 0.4, .phase_deg = 200.0}};
  return wheel;
}

workflows::ProcessPipelineResult Scan(const acquisition::WheelModel& wheel, double noise_um, unsigned seed) {
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

int CoverageScans() {
  const char* text = std::getenv("ARCWHEEL_COVERAGE_SCANS");
  return text ? std::max(1, std::atoi(text)) : 12;
}

const std::vector<std::string> kForm = {"max_arc_error", "max_runout", "max_roundness"};

void CheckCoverage(const std::string& name, const acquisition::WheelModel& wheel) {
  const workflows::ProcessPipelineResult exact = Scan(wheel, 0.0, 1);
  // The operators' values on the noise-free scan, without the bootstrap's correction: that scan's
  // sigmas are its model misfit (some 0.01 um a section point), not noise, and the correction it
  // would take for them (0.02 um off the lobed wheel's arc error) is no part of the truth.
  const auto& form = exact.characteristics->form;
  const std::map<std::string, double> truth = {{"max_arc_error", form.arc_profile.measured_um},
                                               {"max_runout", form.runout.measured_um},
                                               {"max_roundness", form.roundness.measured_um}};
  const int scans = CoverageScans();
  std::map<std::string, int> covered;
  std::map<std::string, double> error_sum, error_squares, u_sum;
  for (int i = 0; i < scans; ++i) {
    const workflows::ProcessPipelineResult result = Scan(wheel, 0.4, 1000u + static_cast<unsigned>(i));
    for (const workflows::Characteristic& c : result.characteristics->items) {
      if (std::find(kForm.begin(), kForm.end(), c.name) == kForm.end()) continue;
      const double error = c.value - truth.at(c.name);
      covered[c.name] += std::abs(error) <= c.expanded;
      error_sum[c.name] += error;
      error_squares[c.name] += error * error;
      u_sum[c.name] += c.u;
    }
  }
  fmt::print("{}: coverage over {} scans (seeds 1000-{}, noise 0.4 um), 95 % intervals:\n", name, scans,
             999 + scans);
  fmt::print("{:<16} {:>10} {:>12} {:>12} {:>10} {:>12} {:>9}\n", "characteristic", "truth", "mean error",
             "sd of error", "mean u", "sd / u", "covered");
  for (const std::string& key : kForm) {
    const double mean_error = error_sum[key] / scans;
    const double sd_error = std::sqrt(std::max(0.0, error_squares[key] - scans * mean_error * mean_error) /
                                      std::max(1, scans - 1));
    const double mean_u = u_sum[key] / scans;
    fmt::print("{:<16} {:>10.4f} {:>12.4f} {:>12.4f} {:>10.4f} {:>12.3f} {:>8.1f}%\n", key,
               Shown(truth.at(key)), Shown(mean_error), Shown(sd_error), Shown(mean_u),
               Shown(sd_error / mean_u), Shown(100.0 * covered[key] / scans));
  }
  for (const std::string& key : kForm) {
    const double fraction = static_cast<double>(covered[key]) / scans;
    if (scans >= 200) {
      EXPECT_GE(fraction, 0.93) << name << " " << key;
      EXPECT_LE(fraction, 0.97) << name << " " << key;
    } else {
      // 12 scans at 95 %: at least 9 holds with p > 0.998.
      EXPECT_GE(covered[key], scans * 3 / 4) << name << " " << key;
    }
  }
}

TEST(CharacteristicsCoverage, PaperLikeWheel) { CheckCoverage("paper-like wheel", PaperLikeWheel()); }

TEST(CharacteristicsCoverage, WheelLobedNearTheCutOff) {
  CheckCoverage("wheel lobed at 15-50 UPR", LobedWheel());
}

}  // namespace
}  // namespace arcwheel
