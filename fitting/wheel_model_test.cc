#include "fitting/wheel_model.h"

#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <span>
#include <string>
#include <vector>

#include "acquisition/simulate.h"
#include "fitting/sample_fit.h"
#include "processing/process_scan.h"

namespace arcwheel::fitting {
namespace {

using acquisition::Harmonic;
using acquisition::ScanSettings;

// A simulated wheel scan processed, fitted per phase and modelled, as `arcwheel process` does.
struct Modelled {
  acquisition::WheelModel wheel;
  ScanSettings settings;
  WheelFit fit;
  WheelModel model;
};

Modelled Model(const acquisition::WheelModel& wheel, const ScanSettings& settings,
               const WheelModelOptions& options) {
  acquisition::Scan scan = acquisition::SimulateScan(wheel, settings).scan;
  processing::ProcessedScan processed = processing::ProcessScanInPlace(scan, processing::ProcessOptions{});
  const processing::HelixGeometry geometry(scan, processed.rpm_used);
  const WheelFit fit = FitWheelToSamples(scan.z_mm, geometry, processed.map, WheelFitOptions{});
  return {wheel, settings, fit, FitWheelModel(scan.z_mm, geometry, processed.map, fit, options)};
}

// The simulator's profile error is a Legendre series in u / (width / 2); this writes
// amplitude3 * P3(u / h) + amplitude4 * P4(u / h) in it, which is orthogonal to 1, u and u^2 over
// the band |u| <= h as the model's p must be.
std::vector<double> ProfileOrthogonalOverBand(double amplitude3_um, double amplitude4_um, double h_mm,
                                              double width_mm) {
  const auto legendre = [](int n, double x) {
    double p0 = 1.0, p1 = x;
    if (n == 0) return p0;
    for (int k = 2; k <= n; ++k) {
      const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
      p0 = p1;
      p1 = p2;
    }
    return p1;
  };
  Eigen::MatrixXd basis(9, 5);
  Eigen::VectorXd target(9);
  for (int i = 0; i < 9; ++i) {
    const double u = -h_mm + 2.0 * h_mm * i / 8.0;
    for (int n = 0; n < 5; ++n) basis(i, n) = legendre(n, u / (width_mm / 2.0));
    target[i] = amplitude3_um * legendre(3, u / h_mm) + amplitude4_um * legendre(4, u / h_mm);
  }
  const Eigen::VectorXd c = basis.colPivHouseholderQr().solve(target);
  return {c.data(), c.data() + c.size()};
}

acquisition::WheelModel LobedWheelWithProfileError() {
  acquisition::WheelModel wheel;
  wheel.arc_radius_harmonics_mm = {{2, 0.010, 30.0}, {3, 0.002, 0.0}};
  wheel.center_axial_harmonics_mm = {{1, 0.004, 45.0}};
  wheel.radial_harmonics_um = {{1, 5.0, 0.0}, {3, 0.8, 20.0}, {5, 0.4, 0.0}};
  wheel.profile_legendre_um = ProfileOrthogonalOverBand(0.6, -0.4, 8.0, wheel.width_mm);
  return wheel;
}

double Wrap180(double deg) { return std::remainder(deg, 360.0); }

TEST(WheelModel, RecoversEveryFunctionOfANoiseFreeWheelToAHundredthOfAMicrometre) {
  WheelModelOptions options;
  options.radius_knots = 32;
  options.axial_knots = 32;
  options.runout_knots = 32;
  const Modelled m = Model(LobedWheelWithProfileError(), ScanSettings{}, options);
  const WheelModel& model = m.model;
  ASSERT_TRUE(model.fitted);
  EXPECT_EQ(model.radius_knots, 32);
  EXPECT_FALSE(model.knots_chosen);
  double worst_um = 0.0;
  for (std::size_t i = 0; i < model.phase_deg.size(); ++i) {
    const double c = model.phase_deg[i];
    const double b_truth = m.wheel.CenterDistanceMm(c) - m.settings.sensor_zero_radius_mm;
    worst_um = std::max(worst_um, std::abs(model.arc_radius_mm[i] - m.wheel.ArcRadiusMm(c)) * 1e3);
    worst_um = std::max(worst_um, std::abs(model.center_axial_mm[i] - m.wheel.CenterAxialMm(c)) * 1e3);
    worst_um = std::max(worst_um, std::abs(model.center_radial_mm[i] - b_truth) * 1e3);
  }
  for (std::size_t i = 0; i < model.profile_u_mm.size(); ++i) {
    const double truth_um = m.wheel.ProfileErrorMm(model.profile_u_mm[i]) * 1e3;
    worst_um = std::max(worst_um, std::abs(model.profile_error_um[i] - truth_um));
  }
  EXPECT_LT(worst_um, 0.01);
  // The order-2 and -3 harmonics of Ra as the simulator set them.
  ASSERT_GE(model.radius_harmonics.size(), 3u);
  EXPECT_NEAR(model.radius_harmonics[1].amplitude_um, 10.0, 0.01);
  EXPECT_NEAR(Wrap180(model.radius_harmonics[1].phase_deg - 30.0), 0.0, 0.05);
  EXPECT_NEAR(model.radius_harmonics[2].amplitude_um, 2.0, 0.01);
  EXPECT_NEAR(model.radius_harmonics[0].amplitude_um, 0.0, 0.01);
  double high = -1e9, low = 1e9;
  for (const double c : model.phase_deg) {
    high = std::max(high, m.wheel.ArcRadiusMm(c));
    low = std::min(low, m.wheel.ArcRadiusMm(c));
  }
  EXPECT_NEAR(model.arc_radius_range_mm, high - low, 1e-5);
  EXPECT_NEAR(model.mean_arc_radius_mm, m.wheel.arc_radius_mm, 1e-5);
  EXPECT_TRUE(model.variation_significant);
}

// A scan at the paper's speed and feed (500 rpm, 0.2 mm per turn) with 0.5 um of sensor noise, the
// wheel's radius constant at every phase unless `radius_harmonics_mm` says otherwise.
ScanSettings NoisyScan(std::uint64_t seed, double noise_um = 0.5) {
  ScanSettings settings;
  settings.sample_period_s = 2e-4;  // 5 kHz: half the paper's samples, for the many draws below
  settings.noise_um = noise_um;
  settings.seed = seed;
  return settings;
}

ScanSettings PaperScan(std::uint64_t seed, double noise_um) {
  ScanSettings settings;  // 500 rpm, 0.2 mm per turn, 10 kHz
  settings.noise_um = noise_um;
  settings.seed = seed;
  return settings;
}

acquisition::WheelModel EccentricWheel(std::vector<Harmonic> radius_harmonics_mm) {
  acquisition::WheelModel wheel;
  wheel.radial_harmonics_um = {{1, 5.0, 0.0}};
  wheel.arc_radius_harmonics_mm = std::move(radius_harmonics_mm);
  return wheel;
}

// Over many noise draws the reported sigmas must describe the scatter about the truth: the
// harmonics' z-scores spread with a standard deviation of 1.
TEST(WheelModelStatistics, HarmonicAmplitudesAndPhasesScatterAsTheirSigmasSay) {
  acquisition::WheelModel wheel = EccentricWheel({{2, 0.004, 30.0}, {3, 0.002, -60.0}});
  WheelModelOptions options;
  options.radius_knots = 32;
  options.axial_knots = 4;
  options.runout_knots = 8;
  std::vector<double> z;
  double worst_amplitude_z = 0.0;
  for (std::uint64_t seed = 1; seed <= 40; ++seed) {
    const WheelModel model = Model(wheel, NoisyScan(seed), options).model;
    for (const Harmonic& truth : wheel.arc_radius_harmonics_mm) {
      const RadiusHarmonic& h = model.radius_harmonics.at(static_cast<std::size_t>(truth.order - 1));
      const double amplitude_z = (h.amplitude_um - truth.amplitude * 1e3) / h.amplitude_sigma_um;
      worst_amplitude_z = std::max(worst_amplitude_z, std::abs(amplitude_z));
      z.push_back(amplitude_z);
      z.push_back(Wrap180(h.phase_deg - truth.phase_deg) / h.phase_sigma_deg);
    }
  }
  double sum = 0.0, sum2 = 0.0;
  for (const double v : z) {
    sum += v;
    sum2 += v * v;
  }
  const double n = static_cast<double>(z.size());
  const double mean = sum / n;
  const double spread = std::sqrt(sum2 / n - mean * mean);
  EXPECT_LT(worst_amplitude_z, 3.0);
  EXPECT_NEAR(spread, 1.0, 0.15);
  EXPECT_NEAR(mean, 0.0, 3.0 / std::sqrt(n));
}

// The paper's question at its settings: over several noise draws, the model's Ra(c) scatters
// about the truth at least ten times less than the per-phase fits' radii do.
TEST(WheelModel, RadiusPerPhaseIsTenTimesLessNoisyThanThePerPhaseFits) {
  double model_sum2 = 0.0, phase_sum2 = 0.0;
  int phases = 0, model_phases = 0;
  for (std::uint64_t seed = 11; seed < 17; ++seed) {
    const Modelled m = Model(EccentricWheel({}), PaperScan(seed, 0.5), WheelModelOptions{});
    EXPECT_TRUE(m.model.knots_chosen);
    for (std::size_t i = 0; i < m.model.phase_deg.size(); ++i) {
      const double truth = m.wheel.ArcRadiusMm(m.model.phase_deg[i]);
      model_sum2 += std::pow(m.model.arc_radius_mm[i] - truth, 2);
      ++model_phases;
      if (!m.fit.phases[i].usable) continue;
      phase_sum2 += std::pow(m.fit.phases[i].arc_radius_mm - truth, 2);
      ++phases;
    }
  }
  ASSERT_GT(phases, 6 * 300);
  EXPECT_GT(std::sqrt((phase_sum2 / phases) / (model_sum2 / model_phases)), 10.0);
}

// The test "Ra(c) varies" at the 1 % level: a constant radius is called varying in about 1 % of
// noise draws (the level); a three-lobe variation of 2 um amplitude at the paper's settings under
// 0.1 um of sensor noise in every draw. (Under 0.5 um the per-phase fits' radius scatters by
// 10 um and a harmonic's sigma is about 0.5 um: 2 um is then seen in most draws, not in all.)
TEST(WheelModelStatistics, RadiusVariationIsSignificantOnlyWhenThereIsOne) {
  int false_alarms = 0, draws = 0;
  for (std::uint64_t seed = 100; seed < 200; ++seed, ++draws) {
    false_alarms +=
        Model(EccentricWheel({}), NoisyScan(seed), WheelModelOptions{}).model.variation_significant;
  }
  EXPECT_LE(false_alarms, 2) << "of " << draws;
  for (std::uint64_t seed = 300; seed < 310; ++seed) {
    const WheelModel model =
        Model(EccentricWheel({{3, 0.002, 0.0}}), PaperScan(seed, 0.1), WheelModelOptions{}).model;
    EXPECT_TRUE(model.variation_significant) << "seed " << seed << " p " << model.variation_p_value;
  }
}

// How close a faster fit must come to the reference: every output to `relative` of itself or
// `of_sigma` of its own sigma, whichever is larger; the sigmas to `sigma_relative` of themselves;
// the residual RMS to `rms_relative`; each cell of the residual map to `of_sigma` of the
// residual RMS / sqrt(cell_samples), at most `of_sigma` of its mean's sigma when no cell holds
// more than cell_samples samples.
struct Tolerance {
  double relative = 1e-6;
  double of_sigma = 1e-3;
  double sigma_relative = 1e-3;
  double rms_relative = 1e-6;
  double cell_samples = 100.0;
};

// The warm-up on a subsample must not change the answer: the same knots, and every output as
// when every Gauss-Newton iteration passes over every sample (warm_start_samples = 0, the
// algorithm as it was first written) to 1e-6 relative or 1e-3 of its own sigma; the sigmas
// themselves to 1e-3 relative (a sigma's own uncertainty is some 1e-3 relative at these sizes).
constexpr Tolerance kWarmStart{};

void ExpectNear(double fast, double reference, double sigma, const std::string& what, const Tolerance& tol) {
  const double tolerance = std::max(tol.relative * std::abs(reference), tol.of_sigma * sigma);
  EXPECT_NEAR(fast, reference, tolerance) << what;
}

// The model from float32 samples is the one from the same values widened to double, to the bit
// (residuals where the double fit gives one).
void ExpectBitForBit(const WheelModel& from_float, const WheelModel& from_double) {
  EXPECT_EQ(from_float.coefficients, from_double.coefficients);
  EXPECT_EQ(from_float.covariance, from_double.covariance);
  ASSERT_EQ(from_float.residual_um.size(), from_double.residual_um.size());
  for (std::size_t i = 0; i < from_float.residual_um.size(); ++i) {
    if (!std::isnan(from_double.residual_um[i])) {
      EXPECT_EQ(from_float.residual_um[i], from_double.residual_um[i]);
    }
  }
}

void ExpectSameModel(const WheelModel& fast, const WheelModel& reference, const Tolerance& tol = kWarmStart) {
  ASSERT_TRUE(fast.fitted);
  ASSERT_TRUE(reference.fitted);
  EXPECT_EQ(fast.radius_knots, reference.radius_knots);
  EXPECT_EQ(fast.axial_knots, reference.axial_knots);
  EXPECT_EQ(fast.runout_knots, reference.runout_knots);
  EXPECT_EQ(fast.samples, reference.samples);
  EXPECT_EQ(fast.parameters, reference.parameters);
  ASSERT_EQ(fast.coefficients.size(), reference.coefficients.size());
  const std::size_t n = reference.coefficients.size();
  for (std::size_t i = 0; i < n; ++i) {
    const double sigma = std::sqrt(reference.covariance[i * n + i]);
    ExpectNear(fast.coefficients[i], reference.coefficients[i], sigma, "coefficient " + std::to_string(i),
               tol);
    EXPECT_NEAR(std::sqrt(fast.covariance[i * n + i]), sigma, tol.sigma_relative * sigma) << "sigma " << i;
  }
  for (std::size_t i = 0; i < reference.phase_deg.size(); ++i) {
    ExpectNear(fast.arc_radius_mm[i], reference.arc_radius_mm[i], reference.arc_radius_sigma_mm[i], "Ra",
               tol);
    ExpectNear(fast.center_axial_mm[i], reference.center_axial_mm[i], reference.center_axial_sigma_mm[i], "a",
               tol);
    ExpectNear(fast.center_radial_mm[i], reference.center_radial_mm[i], reference.center_radial_sigma_mm[i],
               "b", tol);
    EXPECT_NEAR(fast.arc_radius_sigma_mm[i], reference.arc_radius_sigma_mm[i],
                tol.sigma_relative * reference.arc_radius_sigma_mm[i]);
  }
  for (std::size_t i = 0; i < reference.profile_u_mm.size(); ++i) {
    ExpectNear(fast.profile_error_um[i], reference.profile_error_um[i], reference.profile_error_sigma_um[i],
               "p", tol);
  }
  ASSERT_EQ(fast.radius_harmonics.size(), reference.radius_harmonics.size());
  for (std::size_t i = 0; i < reference.radius_harmonics.size(); ++i) {
    const RadiusHarmonic &f = fast.radius_harmonics[i], &r = reference.radius_harmonics[i];
    ExpectNear(f.amplitude_um, r.amplitude_um, r.amplitude_sigma_um, "amplitude", tol);
    ExpectNear(f.phase_deg, r.phase_deg, r.phase_sigma_deg, "phase", tol);
    EXPECT_NEAR(f.amplitude_sigma_um, r.amplitude_sigma_um, tol.sigma_relative * r.amplitude_sigma_um);
  }
  ExpectNear(fast.mean_arc_radius_mm, reference.mean_arc_radius_mm, reference.mean_arc_radius_sigma_mm,
             "mean Ra", tol);
  ExpectNear(fast.arc_radius_range_mm, reference.arc_radius_range_mm, reference.arc_radius_range_sigma_mm,
             "Ra range", tol);
  // The chi-square's own sigma: sqrt(2 (dof + 2 lambda)), lambda (the non-centrality) estimated
  // by chi2 - dof; sqrt(2 dof) for a constant radius.
  const double dof = reference.variation_dof;
  const double lambda = std::max(reference.variation_chi2 - dof, 0.0);
  ExpectNear(fast.variation_chi2, reference.variation_chi2, std::sqrt(2.0 * (dof + 2.0 * lambda)), "chi2",
             tol);
  EXPECT_EQ(fast.variation_significant, reference.variation_significant);
  EXPECT_NEAR(fast.residual_rms_um, reference.residual_rms_um, tol.rms_relative * reference.residual_rms_um);
  // A cell's mean residual has a sigma of at least the noise over the root of the samples in it.
  ASSERT_EQ(fast.residual_um.size(), reference.residual_um.size());
  int cells = 0;
  for (std::size_t i = 0; i < reference.residual_um.size(); ++i) {
    if (std::isnan(reference.residual_um[i])) {
      EXPECT_TRUE(std::isnan(fast.residual_um[i])) << "cell " << i;
      continue;
    }
    ++cells;
    EXPECT_NEAR(fast.residual_um[i], reference.residual_um[i],
                tol.of_sigma * reference.residual_rms_um / std::sqrt(tol.cell_samples))
        << "cell " << i;
  }
  EXPECT_GT(cells, 1000);
}

// A noisy lobed wheel scanned at 20 kHz (2.6e5 samples), processed and fitted phase by phase.
struct WarmStartScan {
  explicit WarmStartScan(unsigned seed)
      : scan(acquisition::SimulateScan(LobedWheelWithProfileError(), Settings(seed)).scan),
        processed(processing::ProcessScanInPlace(scan, processing::ProcessOptions{})),
        geometry(scan, processed.rpm_used),
        fit(FitWheelToSamples(scan.z_mm, geometry, processed.map, WheelFitOptions{})) {}
  static ScanSettings Settings(unsigned seed) {
    ScanSettings settings = NoisyScan(seed, 0.5);
    settings.sample_period_s = 50e-6;
    return settings;
  }
  acquisition::Scan scan;
  processing::ProcessedScan processed;
  processing::HelixGeometry geometry;
  WheelFit fit;
};

// A noisy lobed wheel scanned at 20 kHz (2.6e5 samples), modelled with a warm-up on every 13th
// sample and without one.
TEST(WheelModelWarmStart, GivesTheFitOverEverySampleWithTheKnotsChosen) {
  const WarmStartScan scanned(7);
  const acquisition::Scan& scan = scanned.scan;
  const processing::ProcessedScan& processed = scanned.processed;
  const WheelFit& fit = scanned.fit;
  const processing::HelixGeometry& geometry = scanned.geometry;
  WheelModelOptions fast_options;
  fast_options.warm_start_samples = scan.size() / 13;
  WheelModelOptions reference_options;
  reference_options.warm_start_samples = 0;
  const WheelModel fast = FitWheelModel(scan.z_mm, geometry, processed.map, fit, fast_options);
  const WheelModel reference = FitWheelModel(scan.z_mm, geometry, processed.map, fit, reference_options);
  EXPECT_TRUE(fast.knots_chosen);
  EXPECT_LT(fast.iterations, reference.iterations);  // the warm-up did take work off
  ExpectSameModel(fast, reference);

  // float32 samples are read as they are: the same model as from the same values widened.
  const std::vector<float> narrow(scan.z_mm.begin(), scan.z_mm.end());
  const std::vector<double> widened(narrow.begin(), narrow.end());
  const WheelModel from_float =
      FitWheelModel(std::span<const float>(narrow), geometry, processed.map, fit, fast_options);
  const WheelModel from_double = FitWheelModel(widened, geometry, processed.map, fit, fast_options);
  ExpectBitForBit(from_float, from_double);
  // And as from the double samples, to float32's rounding of the scan.
  ExpectSameModel(from_float, fast);
}

// The same with the knots given (the fine fit is then the final one) and a float32 scan.
TEST(WheelModelWarmStart, GivesTheFitOverEverySampleWithTheKnotsGiven) {
  const WarmStartScan scanned(8);
  const acquisition::Scan& scan = scanned.scan;
  const processing::ProcessedScan& processed = scanned.processed;
  const WheelFit& fit = scanned.fit;
  const processing::HelixGeometry& geometry = scanned.geometry;
  const std::vector<float> narrow(scan.z_mm.begin(), scan.z_mm.end());
  WheelModelOptions options;
  options.radius_knots = 16;
  options.axial_knots = 8;
  options.runout_knots = 16;
  options.warm_start_samples = scan.size() / 13;
  const WheelModel fast =
      FitWheelModel(std::span<const float>(narrow), geometry, processed.map, fit, options);
  options.warm_start_samples = 0;
  const WheelModel reference =
      FitWheelModel(std::span<const float>(narrow), geometry, processed.map, fit, options);
  EXPECT_FALSE(fast.knots_chosen);
  EXPECT_EQ(fast.radius_knots, 16);
  ExpectSameModel(fast, reference);
}

// The binned fit (binned_above_samples lowered to 0) against the fit over every sample on the
// same noisy scans: the same knots, every output within a hundredth of its own sigma, the sigmas
// within 1e-3 relative, the residual RMS within 1e-5 relative and each cell of the residual map
// within a hundredth of its mean's sigma. (Measured: 2e-3 sigma at most on these scans, 1e-4 on
// the benchmark's 1e6- and 1e7-sample scans; docs/wheel_model.md.)
Tolerance BinnedTolerance(const processing::WheelMap& map) {
  const int most = *std::max_element(map.sample_count.begin(), map.sample_count.end());
  return {.relative = 0.0,
          .of_sigma = 0.01,
          .sigma_relative = 1e-3,
          .rms_relative = 1e-5,
          .cell_samples = static_cast<double>(most)};
}

WheelModelOptions Exact(WheelModelOptions options) {
  options.binned_above_samples = std::numeric_limits<std::size_t>::max();
  return options;
}

WheelModelOptions Binned(WheelModelOptions options) {
  options.binned_above_samples = 0;
  return options;
}

TEST(WheelModelBinned, GivesTheFitOverEverySampleToAHundredthOfItsSigmaWithTheKnotsChosen) {
  const WarmStartScan scanned(7);
  const acquisition::Scan& scan = scanned.scan;
  const processing::ProcessedScan& processed = scanned.processed;
  const processing::HelixGeometry& geometry = scanned.geometry;
  const WheelModel reference = FitWheelModel(scan.z_mm, geometry, processed.map, scanned.fit, Exact({}));
  const WheelModel binned = FitWheelModel(scan.z_mm, geometry, processed.map, scanned.fit, Binned({}));
  EXPECT_TRUE(binned.knots_chosen);
  EXPECT_NE(binned.coefficients, reference.coefficients);  // the binned fit did run
  ExpectSameModel(binned, reference, BinnedTolerance(processed.map));

  // float32 samples: the same model as from the same values widened, bit for bit.
  const std::vector<float> narrow(scan.z_mm.begin(), scan.z_mm.end());
  const std::vector<double> widened(narrow.begin(), narrow.end());
  const WheelModel from_float =
      FitWheelModel(std::span<const float>(narrow), geometry, processed.map, scanned.fit, Binned({}));
  const WheelModel from_double = FitWheelModel(widened, geometry, processed.map, scanned.fit, Binned({}));
  ExpectBitForBit(from_float, from_double);
}

// The same with the knots given (the fine fit is then the final one; 12 knots for a, which do not
// divide the cells' 64 per turn) on a float32 scan.
TEST(WheelModelBinned, GivesTheFitOverEverySampleToAHundredthOfItsSigmaWithTheKnotsGiven) {
  const WarmStartScan scanned(8);
  const std::vector<float> narrow(scanned.scan.z_mm.begin(), scanned.scan.z_mm.end());
  WheelModelOptions options;
  options.radius_knots = 16;
  options.axial_knots = 12;
  options.runout_knots = 32;
  const auto model = [&](const WheelModelOptions& o) {
    return FitWheelModel(std::span<const float>(narrow), scanned.geometry, scanned.processed.map, scanned.fit,
                         o);
  };
  const WheelModel binned = model(Binned(options));
  const WheelModel reference = model(Exact(options));
  EXPECT_FALSE(binned.knots_chosen);
  EXPECT_EQ(binned.axial_knots, 12);
  EXPECT_NE(binned.coefficients, reference.coefficients);
  ExpectSameModel(binned, reference, BinnedTolerance(scanned.processed.map));
}

TEST(WheelModelOptions, EveryProblemIsReportedWithItsValue) {
  WheelModelOptions options;
  options.radius_knots = 3;
  options.profile_knot_step_mm = 0.0;
  const std::vector<std::string> problems = options.Problems();
  ASSERT_EQ(problems.size(), 2u);
  EXPECT_EQ(problems[0], "model-knots = 3 violates 0 (chosen from the data), 1 or 4..360");
  EXPECT_EQ(problems[1], "model-profile-step-mm = 0 violates 0.05..10");
}

}  // namespace
}  // namespace arcwheel::fitting
