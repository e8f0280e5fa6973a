// Numeric hazards in scans (issue: hardening): NaN and Inf in every column, duplicated or
// backward time and encoder values, a sensor stuck on one reading, sections without variance and
// fits that do not converge. Each must give a clear refusal or an honest, flagged result, never a
// plausible wrong number. Truth comes from the simulator's known wheel.

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <numbers>
#include <string>
#include <vector>

#include "acquisition/scan_reader.h"
#include "acquisition/simulate.h"
#include "core/error.h"
#include "core/testing/testing.h"
#include "fitting/circle_fit.h"
#include "fitting/wheel_fit.h"
#include "processing/process_scan.h"

namespace arcwheel {
namespace {

using acquisition::ScanSettings;
using acquisition::WheelModel;

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kTrueRadiusMm = 55.4423;  // WheelModel's default arc radius

// A plain arc wheel with eccentricity, scanned with 0.5 um sensor noise over 14 mm: about 8.4e4
// samples, 1200 a turn.
ScanSettings NoisyScan() {
  ScanSettings s;
  s.noise_um = 0.5;
  s.start_y_mm = -7.0;
  s.end_y_mm = 7.0;
  s.seed = 11;
  return s;
}

WheelModel EccentricWheel() {
  WheelModel w;
  w.radial_harmonics_um = {{1, 3.0, 20.0}};
  return w;
}

fitting::WheelFitOptions NarrowBand() {
  fitting::WheelFitOptions options;
  options.band_half_width_mm = 5.0;
  return options;
}

// A message check that shows the message when it fails.
void ExpectRefused(const std::function<void()>& run, ErrorCode code, const std::string& fragment) {
  try {
    run();
    ADD_FAILURE() << "not refused; expected: " << fragment;
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), code) << e.what();
    EXPECT_NE(std::string(e.what()).find(fragment), std::string::npos) << e.what();
  }
}

// The message of the Error that `run` throws, or "" when it throws none.
std::string ReasonOf(const std::function<void()>& run) {
  try {
    run();
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

// Samples 0.1 s apart at 500 rpm: a few samples cover the two turns a scan needs.
const std::string kCsvHeader = "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.1\n";

// --- NaN and Inf -----------------------------------------------------------------------------------

TEST(NumericHazards, InfinityInTheReadingsIsAnInvalidSampleInCsvAndHdf5Alike) {
  const std::string csv = kCsvHeader + "z_mm\n0.1\ninf\n0.2\n-Inf\nINFINITY\n0.3\nnan\n0.4\n";
  const acquisition::Scan from_csv = acquisition::ParseCsvScan(csv, "inf.csv");
  EXPECT_EQ(from_csv.size(), 8U);
  EXPECT_EQ(from_csv.CountValid(), 4U);

  testing::TempDir dir;
  acquisition::Scan scan = from_csv;
  scan.z_mm = {0.1, kInf, 0.2, -kInf, kInf, 0.3, std::nan(""), 0.4};
  acquisition::WriteHdf5Scan(scan, /*float32=*/true, (dir / "inf.h5").string());
  const acquisition::Scan from_hdf5 = acquisition::ReadHdf5Scan(dir / "inf.h5");
  EXPECT_EQ(from_hdf5.CountValid(), 4U);
  for (double z : from_hdf5.z_mm) EXPECT_TRUE(std::isnan(z) || std::isfinite(z)) << z;
}

TEST(NumericHazards, NonFiniteTimeAngleOrAxialValuesAreRefusedNamingTheLine) {
  ExpectRefused([] { (void)acquisition::ParseCsvScan(kCsvHeader + "z_mm,t_s\n0.1,0\n0.2,inf\n", "t.csv"); },
                ErrorCode::kBadInput, "line 6");
  ExpectRefused(
      [] { (void)acquisition::ParseCsvScan(kCsvHeader + "z_mm,angle_deg\n0.1,0\n0.2,nan\n", "a.csv"); },
      ErrorCode::kBadInput, "line 6");
  ExpectRefused([] { (void)acquisition::ParseCsvScan(kCsvHeader + "z_mm,y_mm\n0.1,-inf\n0.2,0\n", "y.csv"); },
                ErrorCode::kBadInput, "line 5");

  testing::TempDir dir;
  acquisition::Scan scan = acquisition::ParseCsvScan(
      kCsvHeader + "z_mm,t_s\n0.1,0\n0.2,0.1\n0.3,0.2\n0.4,0.3\n0.5,0.4\n", "t.csv");
  scan.t_s[1] = std::nan("");
  acquisition::WriteHdf5Scan(scan, /*float32=*/false, (dir / "t.h5").string());
  ExpectRefused([&] { (void)acquisition::ReadHdf5Scan(dir / "t.h5"); }, ErrorCode::kBadInput,
                "column 't' is not finite at sample 1");
}

TEST(NumericHazards, NonFiniteOrNonPositiveSettingsAreRefused) {
  for (const char* line : {"# spindle_rpm: inf\n", "# spindle_rpm: nan\n", "# spindle_rpm: 0\n"}) {
    const std::string csv =
        std::string(line) + "# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm\n0.1\n0.2\n0.3\n";
    ExpectRefused([&] { (void)acquisition::ParseCsvScan(csv, "rpm.csv"); }, ErrorCode::kBadInput,
                  "spindle_rpm must be positive and finite");
  }
  const std::string csv =
      "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: -inf\nz_mm\n0.1\n0.2\n";
  ExpectRefused([&] { (void)acquisition::ParseCsvScan(csv, "period.csv"); }, ErrorCode::kBadInput,
                "sample_period_s must be positive and finite");
}

// --- time and encoder order ------------------------------------------------------------------------

TEST(NumericHazards, DuplicatedOrBackwardTimeIsRefusedNamingTheSample) {
  ExpectRefused(
      [] { (void)acquisition::ParseCsvScan(kCsvHeader + "z_mm,t_s\n0.1,0\n0.2,0.1\n0.3,0.1\n", "d.csv"); },
      ErrorCode::kBadInput, "column 't' does not increase at sample 2");
  ExpectRefused(
      [] { (void)acquisition::ParseCsvScan(kCsvHeader + "z_mm,t_s\n0.1,0\n0.2,0.2\n0.3,0.1\n", "b.csv"); },
      ErrorCode::kBadInput, "column 't' does not increase at sample 2");
}

TEST(NumericHazards, DuplicatedOrBackwardEncoderIsRefusedButAWrappedEncoderIsNot) {
  ScanSettings settings = NoisyScan();
  settings.write_encoder = true;
  const acquisition::Scan wrapped = acquisition::SimulateScan(EccentricWheel(), settings).scan;
  // The simulator writes the angle wrapped to [0, 360); unwrapped by hand it must give the same.
  acquisition::Scan unwrapped = wrapped;
  double turns = 0.0;
  for (std::size_t i = 1; i < unwrapped.angle_deg.size(); ++i) {
    if (wrapped.angle_deg[i] < wrapped.angle_deg[i - 1]) turns += 360.0;
    unwrapped.angle_deg[i] = wrapped.angle_deg[i] + turns;
  }
  ASSERT_GT(turns, 3600.0);
  const auto a = fitting::FitWheel(processing::ProcessScan(wrapped, {}).map, NarrowBand());
  const auto b = fitting::FitWheel(processing::ProcessScan(unwrapped, {}).map, NarrowBand());
  EXPECT_NEAR(a.mean_arc_radius_mm, b.mean_arc_radius_mm, 1e-9);
  EXPECT_NEAR(a.mean_arc_radius_mm, kTrueRadiusMm, 3.0 * a.mean_arc_radius_sigma_mm);

  acquisition::Scan duplicated = unwrapped;
  duplicated.angle_deg[5000] = duplicated.angle_deg[4999];
  ExpectRefused([&] { (void)processing::ProcessScan(duplicated, {}); }, ErrorCode::kBadInput,
                "does not increase");
  acquisition::Scan backward = unwrapped;
  backward.angle_deg[5000] -= 30.0;  // a jump back that is not a wrap
  ExpectRefused([&] { (void)processing::ProcessScan(backward, {}); }, ErrorCode::kBadInput,
                "does not increase");
  EXPECT_EQ(ReasonOf([&] { acquisition::ValidateScan(backward); }).find("radians"), std::string::npos);
  // The same encoder in radians, wrapped at 2 pi: refused, saying what it looks like.
  acquisition::Scan radians = wrapped;
  for (double& angle : radians.angle_deg) angle *= std::numbers::pi / 180.0;
  ExpectRefused([&] { acquisition::ValidateScan(radians); }, ErrorCode::kBadInput,
                "every value lies within 0 .. 2 pi: radians? The angle column is in degrees");
}

// --- a stuck sensor and sections without variance ------------------------------------------------

TEST(NumericHazards, AStuckSensorIsDroppedAndTheRadiusStaysTrue) {
  acquisition::Scan scan = acquisition::SimulateScan(EccentricWheel(), NoisyScan()).scan;
  // The sensor hangs on one reading for two turns in the middle of the band.
  const std::size_t begin = 40000, length = 2400;
  for (std::size_t i = begin; i < begin + length; ++i) scan.z_mm[i] = scan.z_mm[begin];

  processing::ProcessOptions keep;
  keep.stuck_run_deg = 0.0;
  const auto kept = fitting::FitWheel(processing::ProcessScan(scan, keep).map, NarrowBand());
  // The hazard is real: left in, the run moves the radius far beyond its sigma.
  EXPECT_GT(std::abs(kept.mean_arc_radius_mm - kTrueRadiusMm), 50.0 * kept.mean_arc_radius_sigma_mm);

  const processing::ProcessedScan processed = processing::ProcessScan(scan, {});
  EXPECT_EQ(processed.stuck.dropped, length);
  EXPECT_EQ(processed.stuck.runs, 1U);
  EXPECT_EQ(processed.stuck.min_run, 67U);  // 20 deg of a 1200-sample turn
  ASSERT_FALSE(processed.warnings.empty());
  EXPECT_NE(processed.warnings.front().find("stuck"), std::string::npos);
  const auto fit = fitting::FitWheel(processed.map, NarrowBand());
  EXPECT_NEAR(fit.mean_arc_radius_mm, kTrueRadiusMm, 3.0 * fit.mean_arc_radius_sigma_mm);
}

TEST(NumericHazards, QuantisedOrNoiseFreeReadingsAreNotTakenForAStuckSensor) {
  // A 0.1 um sensor resolution with 0.5 um noise repeats values, but never for 20 deg.
  acquisition::Scan quantised = acquisition::SimulateScan(EccentricWheel(), NoisyScan()).scan;
  for (double& z : quantised.z_mm) z = std::round(z * 1e4) / 1e4;
  EXPECT_EQ(processing::ProcessScan(quantised, {}).stuck.dropped, 0U);

  // Noise-free float32 readings of a perfectly round wheel: the apex of the arc is flat to second
  // order, the hardest case for equal consecutive readings.
  ScanSettings clean = NoisyScan();
  clean.noise_um = 0.0;
  acquisition::Scan round = acquisition::SimulateScan(WheelModel{}, clean).scan;
  for (double& z : round.z_mm) z = static_cast<double>(static_cast<float>(z));
  EXPECT_EQ(processing::ProcessScan(round, {}).stuck.dropped, 0U);
}

TEST(NumericHazards, AScanWithoutVarianceIsRefusedClearly) {
  acquisition::Scan flat = acquisition::SimulateScan(EccentricWheel(), NoisyScan()).scan;
  for (double& z : flat.z_mm) z = 0.25;
  ExpectRefused([&] { (void)processing::ProcessScan(flat, {}); }, ErrorCode::kBadInput, "stuck");
  // With the stuck-sensor check off, every section is a straight line: no circle, and the fit says so.
  processing::ProcessOptions keep;
  keep.stuck_run_deg = 0.0;
  const processing::ProcessedScan processed = processing::ProcessScan(flat, keep);
  ExpectRefused([&] { (void)fitting::FitWheel(processed.map, NarrowBand()); }, ErrorCode::kFitFailed,
                "collinear");
}

// A speed in the wrong unit (1e12 rpm, say) made the helix outnumber its samples in turns, and
// the speed estimate looped over 2e11 empty turns without end.
TEST(NumericHazards, FewerThanSixteenSamplesATurnAreRefusedNamingTheSettings) {
  acquisition::Scan scan = acquisition::SimulateScan(EccentricWheel(), NoisyScan()).scan;
  scan.path = "fast.h5";
  scan.metadata.spindle_rpm = 1e12;
  ExpectRefused([&] { (void)processing::ProcessScan(scan, {}); }, ErrorCode::kBadInput,
                "'fast.h5': 6e-07 samples a turn at spindle_rpm 1e+12");
  // 1200 samples a turn at 500 rpm; 16 a turn at 37500 rpm is the least that is taken.
  scan.metadata.spindle_rpm = 37500.0 * 1.01;
  ExpectRefused([&] { (void)processing::ProcessScan(scan, {}); }, ErrorCode::kBadInput,
                "15.8 samples a turn");
  scan.metadata.spindle_rpm = 37500.0 * 0.99;
  processing::ProcessOptions nominal;
  nominal.rpm_source = processing::RpmSource::kNominal;
  EXPECT_NO_THROW((void)processing::ProcessScan(scan, nominal));
}

// An axial position in the wrong unit (nanometres as millimetres) left the coordinate 0.125 mm
// coarse at 1e15 mm, and the radius came out 0.65 um off and the runout three times too large,
// with nothing said.
TEST(NumericHazards, AxialPositionsBeyondAKilometreAreRefused) {
  acquisition::Scan scan = acquisition::SimulateScan(EccentricWheel(), NoisyScan()).scan;
  scan.path = "far.h5";
  scan.metadata.start_y_mm = 1e15;
  ExpectRefused([&] { acquisition::ValidateScan(scan); }, ErrorCode::kBadInput,
                "'far.h5': its axial positions reach 1e+15 mm");
  scan.metadata.start_y_mm = -1e6 + 20.0;
  EXPECT_NO_THROW(acquisition::ValidateScan(scan));
  scan.y_mm.assign(scan.size(), 0.0);
  for (std::size_t i = 0; i < scan.size(); ++i) scan.y_mm[i] = 2e6 + 1e-3 * static_cast<double>(i);
  ExpectRefused([&] { acquisition::ValidateScan(scan); }, ErrorCode::kBadInput, "reach 2000");
}

// Whole turns added to the start phase change nothing: at 1e18 deg the spacing of doubles is
// 128 deg, and the mean radius came out 4.7 um (13 sigma) off.
TEST(NumericHazards, WholeTurnsInTheStartPhaseChangeNoResult) {
  ScanSettings settings = NoisyScan();
  settings.start_phase_deg = 128.0;
  const acquisition::Scan scan = acquisition::SimulateScan(EccentricWheel(), settings).scan;
  acquisition::Scan turned = scan;
  turned.metadata.start_phase_deg = 128.0 + 360.0 * std::ldexp(1.0, 50);  // exactly representable
  ASSERT_EQ(std::fmod(turned.metadata.start_phase_deg, 360.0), 128.0);
  processing::ProcessOptions nominal;
  nominal.rpm_source = processing::RpmSource::kNominal;
  const fitting::WheelFit plain = fitting::FitWheel(processing::ProcessScan(scan, nominal).map, NarrowBand());
  const fitting::WheelFit far = fitting::FitWheel(processing::ProcessScan(turned, nominal).map, NarrowBand());
  EXPECT_NEAR(plain.mean_arc_radius_mm, kTrueRadiusMm, 3.0 * plain.mean_arc_radius_sigma_mm);
  EXPECT_EQ(far.mean_arc_radius_mm, plain.mean_arc_radius_mm);
  EXPECT_EQ(far.max_runout_um, plain.max_runout_um);
}

// --- fits that do not converge ----------------------------------------------------------------

TEST(NumericHazards, ACircleFitThatRunsOutOfIterationsSaysSoAndIsNotUsable) {
  // A quarter of an ellipse: the algebraic start is far from the geometric circle, so one
  // iteration cannot reach it; with the default iterations it converges.
  std::vector<double> x, y;
  for (int k = 0; k <= 50; ++k) {
    const double t = 0.5 * std::numbers::pi * k / 50.0;
    x.push_back(100.0 * std::cos(t));
    y.push_back(60.0 * std::sin(t));
  }
  const fitting::CircleFit starved = fitting::FitCircle(x, y, {}, {.max_iterations = 1});
  EXPECT_EQ(starved.status, fitting::FitStatus::kNoConvergence) << starved.message;
  EXPECT_FALSE(starved.IsUsable());
  EXPECT_NE(starved.message.find("did not converge"), std::string::npos) << starved.message;
  const fitting::CircleFit full = fitting::FitCircle(x, y, {}, {});
  EXPECT_EQ(full.status, fitting::FitStatus::kConverged) << full.message;
}

// One Gauss-Newton step cannot fit an arc from the starting circle: every phase's fit stops
// unconverged, and the wheel fit refuses (exit 5) naming why rather than averaging them.
TEST(NumericHazards, SectionFitsThatDoNotConvergeAreNotAveraged) {
  const processing::ProcessedScan processed =
      processing::ProcessScan(acquisition::SimulateScan(EccentricWheel(), NoisyScan()).scan, {});
  fitting::WheelFitOptions starved = NarrowBand();
  starved.circle.max_iterations = 1;
  const std::string message = testing::ErrorMessageOf(
      [&] { (void)fitting::FitWheel(processed.map, starved); }, ErrorCode::kFitFailed);
  EXPECT_NE(message.find("no phase gave a usable arc fit"), std::string::npos) << message;
  EXPECT_NE(message.find("did not converge"), std::string::npos) << message;
  // The same sections with the default iterations fit at every phase.
  const fitting::WheelFit fit = fitting::FitWheel(processed.map, NarrowBand());
  EXPECT_EQ(fit.usable_phases, static_cast<int>(fit.phases.size()));
}

}  // namespace
}  // namespace arcwheel
