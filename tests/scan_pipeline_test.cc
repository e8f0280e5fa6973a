// The scan pipeline against simulated truth (issue: scan pipeline, "Done when").
// Expected values come from the simulator's known wheel, evaluated here, and from an
// independent Gauss-Newton circle fit written in this file.

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <cmath>
#include <numeric>
#include <vector>

#include "acquisition/simulate.h"
#include "core/testing/testing.h"
#include "fitting/outputs.h"
#include "fitting/wheel_fit.h"
#include "processing/process_scan.h"

namespace arcwheel {
namespace {

using acquisition::Harmonic;
using acquisition::ScanSettings;
using acquisition::WheelModel;

// The paper's wheel with runout, lobing, wobble, a per-phase radius variation and a
// non-circular profile error.
WheelModel PaperWheel() {
  WheelModel w = acquisition::LobedTestWheel();
  w.profile_legendre_um = {0.0, 0.0, 0.6, 0.8, 0.4};
  return w;
}

ScanSettings PaperScan() {
  ScanSettings s;
  s.sensor_zero_radius_mm = 199.5;
  return s;
}

struct Result {
  processing::ProcessedScan processed;
  fitting::WheelFit fit;
};

Result RunPipeline(const WheelModel& wheel, const ScanSettings& settings,
                   const processing::ProcessOptions& options = {}) {
  const auto simulated = acquisition::SimulateScan(wheel, settings);
  Result r{processing::ProcessScan(simulated.scan, options), {}};
  r.fit = fitting::FitWheel(r.processed.map, {});
  return r;
}

// Independent geometric circle fit (Gauss-Newton on (a, b, r)), for expected values.
Eigen::Vector3d ReferenceCircle(const std::vector<double>& y, const std::vector<double>& rho,
                                Eigen::Vector3d p) {
  for (int iteration = 0; iteration < 50; ++iteration) {
    Eigen::MatrixXd J(static_cast<Eigen::Index>(y.size()), 3);
    Eigen::VectorXd r(static_cast<Eigen::Index>(y.size()));
    for (std::size_t i = 0; i < y.size(); ++i) {
      const double d = std::hypot(y[i] - p(0), rho[i] - p(1));
      const auto k = static_cast<Eigen::Index>(i);
      r(k) = d - p(2);
      J(k, 0) = -(y[i] - p(0)) / d;
      J(k, 1) = -(rho[i] - p(1)) / d;
      J(k, 2) = -1.0;
    }
    const Eigen::Vector3d step = J.colPivHouseholderQr().solve(-r);
    p += step;
    if (step.norm() < 1e-13) break;
  }
  return p;
}

TEST(ScanPipeline, NoiseFreeScanRecoversTheWheelWithin50Nanometres) {
  const WheelModel wheel = PaperWheel();
  const ScanSettings settings = PaperScan();
  const Result r = RunPipeline(wheel, settings);
  const auto& map = r.processed.map;
  const double zero = settings.sensor_zero_radius_mm;
  ASSERT_EQ(r.fit.usable_phases, 360);

  // Truth per phase: the least-squares circle of the true section at the same axial positions
  // (the helix points in the band; the profile error shifts it from the generating circle).
  double truth_mean_radius = 0.0, truth_mean_axial = 0.0, truth_max_arc_error_um = 0.0;
  for (std::size_t j = 0; j < map.n_phase(); ++j) {
    const double c = map.phase_deg[j];
    std::vector<double> y, rho;
    const double band_center = 0.5 * (r.fit.band_low_mm + r.fit.band_high_mm);
    for (const double node : map.sections[j].y_mm) {
      if (std::abs(node - band_center) > 8.0) continue;
      y.push_back(node);
      rho.push_back(wheel.SmoothRadiusMm(c, node) - zero);
    }
    const Eigen::Vector3d p = ReferenceCircle(
        y, rho, {wheel.CenterAxialMm(c), wheel.CenterDistanceMm(c) - zero, wheel.ArcRadiusMm(c)});
    double low = 1e9, high = -1e9;
    for (std::size_t i = 0; i < y.size(); ++i) {
      const double e = std::hypot(y[i] - p(0), rho[i] - p(1)) - p(2);
      low = std::min(low, e);
      high = std::max(high, e);
    }
    const auto& f = r.fit.phases[j];
    EXPECT_NEAR(f.arc_radius_mm, p(2), 50e-6) << "phase " << c;
    EXPECT_NEAR(f.center_axial_mm, p(0), 50e-6) << "phase " << c;
    EXPECT_NEAR(f.center_radial_mm, p(1), 50e-6) << "phase " << c;
    EXPECT_NEAR(f.arc_error_um, (high - low) * 1000.0, 0.05) << "phase " << c;
    truth_mean_radius += p(2) / 360.0;
    truth_mean_axial += p(0) / 360.0;
    truth_max_arc_error_um = std::max(truth_max_arc_error_um, (high - low) * 1000.0);
  }
  EXPECT_NEAR(r.fit.mean_arc_radius_mm, truth_mean_radius, 50e-6);
  EXPECT_NEAR(r.fit.mean_center_axial_mm, truth_mean_axial, 50e-6);
  EXPECT_NEAR(r.fit.max_arc_error_um, truth_max_arc_error_um, 0.05);
  EXPECT_GT(truth_max_arc_error_um, 0.5)
      << "the profile error must be visible for this test to mean anything";

  // Runout truth: max - min over the 360 phases of the true rim at each band node.
  double truth_max_runout_um = 0.0;
  for (std::size_t m = 0; m < r.fit.axial_y_mm.size(); ++m) {
    double low = 1e9, high = -1e9;
    for (const double c : map.phase_deg) {
      const double rho = wheel.SmoothRadiusMm(c, r.fit.axial_y_mm[m]) - zero;
      low = std::min(low, rho);
      high = std::max(high, rho);
    }
    EXPECT_NEAR(r.fit.runout_um[m], (high - low) * 1000.0, 0.05) << "y " << r.fit.axial_y_mm[m];
    truth_max_runout_um = std::max(truth_max_runout_um, (high - low) * 1000.0);
  }
  EXPECT_NEAR(r.fit.max_runout_um, truth_max_runout_um, 0.05);
}

TEST(ScanPipeline, NoisyScansAreWithinThreeSigmasAndTheSigmasAreHonest) {
  WheelModel wheel = PaperWheel();
  wheel.profile_legendre_um.clear();  // the generating circle is then the truth
  std::vector<double> mean_z;
  std::vector<double> phase_z;
  for (std::uint64_t seed = 1; seed <= 12; ++seed) {
    ScanSettings s = PaperScan();
    s.noise_um = 0.5;
    s.spike_rate = 1e-4;
    s.burst_rate = 3e-5;
    s.dropout_rate = 2e-5;
    s.seed = seed;
    const Result r = RunPipeline(wheel, s);
    double truth_mean = 0.0;
    for (std::size_t j = 0; j < r.fit.phases.size(); ++j) {
      const auto& f = r.fit.phases[j];
      const double truth = wheel.ArcRadiusMm(r.processed.map.phase_deg[j]);
      truth_mean += truth / static_cast<double>(r.fit.phases.size());
      ASSERT_TRUE(f.usable) << f.flag;
      phase_z.push_back((f.arc_radius_mm - truth) / f.arc_radius_sigma_mm);
      EXPECT_LT(std::abs(phase_z.back()), 5.0);
    }
    const double z = (r.fit.mean_arc_radius_mm - truth_mean) / r.fit.mean_arc_radius_sigma_mm;
    EXPECT_LT(std::abs(z), 3.0) << "seed " << seed;
    mean_z.push_back(z);
  }
  const auto spread = [](const std::vector<double>& v) {
    const double m = std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
    double s = 0.0;
    for (const double x : v) s += (x - m) * (x - m);
    return std::sqrt(s / static_cast<double>(v.size() - 1));
  };
  // 4320 per-phase z-scores: their spread is 1 within a few percent if the sigmas are honest.
  EXPECT_NEAR(spread(phase_z), 1.0, 0.1);
  // 12 scans: the spread of the mean's z-scores has a sampling error of ~0.2.
  EXPECT_GT(spread(mean_z), 0.5);
  EXPECT_LT(spread(mean_z), 1.6);
}

class SpeedError : public ::testing::TestWithParam<double> {};

TEST_P(SpeedError, IsRecoveredWithin0p01PercentWithoutAnEncoder) {
  ScanSettings s = PaperScan();
  s.noise_um = 0.5;
  s.spindle_rpm_true = s.spindle_rpm_nominal * (1.0 + GetParam());
  WheelModel wheel = PaperWheel();
  wheel.profile_legendre_um.clear();  // the generating circle is then the truth
  const Result r = RunPipeline(wheel, s);
  EXPECT_EQ(r.processed.phase_source, processing::PhaseSource::kEstimated);
  EXPECT_NEAR(r.processed.rpm_used / s.spindle_rpm_true - 1.0, 0.0, 1e-4);
  // With the right speed the sections are circles again: the radius is right.
  EXPECT_NEAR(r.fit.mean_arc_radius_mm, wheel.arc_radius_mm, 4 * r.fit.mean_arc_radius_sigma_mm);
}

INSTANTIATE_TEST_SUITE_P(UpToHalfAPercent, SpeedError,
                         ::testing::Values(-0.005, -0.001, 0.0003, 0.002, 0.005));

TEST(ScanPipeline, NominalSpeedIsKeptWhenTheDataAgreeWithIt) {
  ScanSettings s = PaperScan();
  s.noise_um = 0.5;
  const Result r = RunPipeline(PaperWheel(), s);
  EXPECT_EQ(r.processed.phase_source, processing::PhaseSource::kNominal);
  EXPECT_EQ(r.processed.rpm_used, s.spindle_rpm_nominal);
  EXPECT_NEAR(r.processed.speed.fitted_rpm, s.spindle_rpm_nominal, 4 * r.processed.speed.sigma_rpm);
}

TEST(ScanPipeline, EncoderRadiusSignAndTimeColumnGiveTheSameWheel) {
  WheelModel wheel = PaperWheel();
  wheel.profile_legendre_um.clear();  // the generating circle is then the truth
  ScanSettings s = PaperScan();
  s.spindle_rpm_true = 503.0;  // the encoder knows; the nominal 500 is wrong
  s.write_encoder = true;
  s.write_time = true;
  s.radius_sign = -1.0;
  const Result r = RunPipeline(wheel, s);
  EXPECT_EQ(r.processed.phase_source, processing::PhaseSource::kEncoder);
  EXPECT_NEAR(r.processed.rpm_used, 503.0, 1e-6);
  for (std::size_t j = 0; j < r.fit.phases.size(); j += 17) {
    const double c = r.processed.map.phase_deg[j];
    EXPECT_NEAR(r.fit.phases[j].center_radial_mm, wheel.CenterDistanceMm(c) - s.sensor_zero_radius_mm, 2e-4)
        << c;
  }
}

TEST(ScanPipeline, BeamOffsetCorrectionRestoresTheArcRadius) {
  WheelModel wheel = PaperWheel();
  wheel.profile_legendre_um.clear();
  ScanSettings s = PaperScan();
  s.beam_offset_mm = 4.0;
  const Result uncorrected = RunPipeline(wheel, s);
  processing::ProcessOptions options;
  options.beam_offset_mm = 4.0;
  options.wheel_radius_mm = wheel.wheel_diameter_mm / 2.0;
  const Result corrected = RunPipeline(wheel, s, options);
  // Eq. 1 of method.md: the offset beam does not see the true section (here ~0.01 mm of radius).
  EXPECT_GT(std::abs(uncorrected.fit.mean_arc_radius_mm - wheel.arc_radius_mm), 5e-3);
  EXPECT_NEAR(corrected.fit.mean_arc_radius_mm, wheel.arc_radius_mm, 2e-4);
}

TEST(ScanPipeline, SectionsTooShortOrTooSparseAreFlaggedAndLeftOutOfTheMeans) {
  WheelModel wheel = PaperWheel();
  wheel.profile_legendre_um.clear();
  const auto simulated = acquisition::SimulateScan(wheel, PaperScan());
  processing::ProcessedScan processed = processing::ProcessScan(simulated.scan, {});
  auto& sections = processed.map.sections;
  const auto keep_below = [](processing::Section& section, double y_limit) {
    processing::Section kept;
    for (std::size_t k = 0; k < section.y_mm.size(); ++k) {
      if (section.y_mm[k] >= y_limit) continue;
      kept.y_mm.push_back(section.y_mm[k]);
      kept.rho_mm.push_back(section.rho_mm[k]);
      kept.sigma_mm.push_back(section.sigma_mm[k]);
      kept.u_deg.push_back(section.u_deg[k]);
    }
    section = kept;
  };
  for (std::size_t j = 10; j < 20; ++j) keep_below(sections[j], -3.0);  // covers 5 of the 16 mm band
  for (std::size_t j = 30; j < 35; ++j) keep_below(sections[j], -7.5);  // three points or so
  const fitting::WheelFit fit = fitting::FitWheel(processed.map, {});
  EXPECT_EQ(fit.usable_phases, 345);
  double truth_mean = 0.0;
  for (std::size_t j = 0; j < fit.phases.size(); ++j) {
    const bool damaged = (j >= 10 && j < 20) || (j >= 30 && j < 35);
    EXPECT_EQ(fit.phases[j].usable, !damaged) << j;
    EXPECT_EQ(fit.phases[j].flag.empty(), !damaged) << j << ": " << fit.phases[j].flag;
    if (!damaged) truth_mean += wheel.ArcRadiusMm(processed.map.phase_deg[j]) / 345.0;
  }
  EXPECT_NE(fit.phases[12].flag.find("covers"), std::string::npos) << fit.phases[12].flag;
  EXPECT_NE(fit.phases[31].flag.find("too few points"), std::string::npos) << fit.phases[31].flag;
  EXPECT_NEAR(fit.mean_arc_radius_mm, truth_mean, 50e-6);
}

TEST(ScanPipeline, BurstsOfSpikesAreRemovedBeforeTheFit) {
  WheelModel wheel = PaperWheel();
  wheel.profile_legendre_um.clear();
  ScanSettings s = PaperScan();
  s.burst_rate = 2e-4;
  s.burst_length_max = 5;
  s.spike_amplitude_um = 40.0;
  const Result r = RunPipeline(wheel, s);
  // Without noise a missed spike would show as tens of micrometres of arc error.
  EXPECT_LT(r.fit.max_arc_error_um, 0.05);
  EXPECT_GE(r.processed.despike.rejected, 20u);
}

// A run whose outputs cannot be written leaves nothing behind, not even the folder it made:
// metadata that is not UTF-8 (which no reader lets through) makes the summary's JSON refuse.
TEST(ScanPipeline, AFailedWriteLeavesNoFolderBehind) {
  const Result run = RunPipeline(PaperWheel(), PaperScan());
  const processing::ProcessedScan& processed = run.processed;
  const fitting::WheelFit& fit = run.fit;
  fitting::RunRecord record;
  record.metadata.wheel_id = "\xff\xfe not UTF-8";
  testing::TempDir dir;
  const std::filesystem::path outdir = dir / "new" / "out";
  EXPECT_ANY_THROW(fitting::WriteProcessOutputs(outdir, record, processed, fit, nullptr));
  EXPECT_FALSE(std::filesystem::exists(dir / "new")) << "the folders it made are removed";
  record.metadata.wheel_id = "D15";
  fitting::WriteProcessOutputs(outdir, record, processed, fit, nullptr);
  EXPECT_EQ(testing::ListFolder(outdir), "summary.json\nwheel_map.h5\n");
}

}  // namespace
}  // namespace arcwheel
