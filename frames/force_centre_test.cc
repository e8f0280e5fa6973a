#include "frames/force_centre.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <random>

#include "core/error.h"
#include "core/testing/testing.h"
#include "frames/force_record_io.h"
#include "frames/transform_fit.h"

namespace arcwheel::frames {
namespace {

using arcwheel::testing::ErrorMessageOf;
using arcwheel::testing::ErrorOf;
using ::testing::HasSubstr;

ForceSimulation TypicalSimulation() {
  ForceSimulation s;
  s.centre_mm = {31.25, -18.5};
  s.platform_height_mm = 22.0;
  s.tare.force_N = {0.8, -0.4, -45.0};        // sensor offset plus the platform's weight
  s.tare.moment_Nmm = {120.0, 310.0, -12.0};  // the platform's centre of mass is off the axis
  return s;
}

ContactCentre Solve(const ForceSimulation& s, std::mt19937& rng) {
  const Wrench tare = MeanWrench(SimulateUnloadedRecord(s, rng));
  return SolveContactCentre(Tare(SimulateForceRecord(s, rng), tare),
                            {.platform_height_mm = s.platform_height_mm});
}

TEST(SolveContactCentre, IsExactForNoiseFreeRecords) {
  ForceSimulation s = TypicalSimulation();
  s.noise_fraction = 0.0;
  s.duration_s = 2.0;
  std::mt19937 rng(8001);
  const ContactCentre c = Solve(s, rng);
  EXPECT_NEAR(c.centre_mm.x(), s.centre_mm.x(), 1e-9 * std::abs(s.centre_mm.x()));
  EXPECT_NEAR(c.centre_mm.y(), s.centre_mm.y(), 1e-9 * std::abs(s.centre_mm.y()));
  EXPECT_LT(c.rms_moment_residual_Nmm.maxCoeff(), 1e-9);
}

TEST(SolveContactCentre, RecoversTheContactPointWithin10umAtHalfAPercentNoise) {
  // 30 s at 1 kHz, 0.5 % noise on every channel, tare from a noisy unloaded record.
  const ForceSimulation s = TypicalSimulation();
  std::mt19937 rng(8002);
  const ContactCentre c = Solve(s, rng);
  EXPECT_NEAR(c.centre_mm.x(), s.centre_mm.x(), 0.01);
  EXPECT_NEAR(c.centre_mm.y(), s.centre_mm.y(), 0.01);
  // The approach ramp's low-force samples are left out.
  EXPECT_LT(c.samples_used, c.samples_total);
  EXPECT_GT(c.samples_used, 0.9 * c.samples_total);
  // The pad's couple (simulated as proportional to the normal force) is recovered from Mz.
  const double expected_couple_Nmm = s.friction_couple_Nmm / 30.0 * std::abs(c.mean_normal_force_N);
  EXPECT_NEAR(c.friction_couple_Nmm, expected_couple_Nmm, 0.01 * expected_couple_Nmm);
}

TEST(SolveContactCentre, ReportedSigmaMatchesTheSpreadOverRepeatedRecords) {
  ForceSimulation s = TypicalSimulation();
  s.duration_s = 3.0;
  s.tare = {};
  std::mt19937 rng(8003);
  constexpr int kRecords = 60;
  Eigen::Vector2d sum_squares = Eigen::Vector2d::Zero(), predicted = Eigen::Vector2d::Zero();
  for (int i = 0; i < kRecords; ++i) {
    const ContactCentre c =
        SolveContactCentre(SimulateForceRecord(s, rng), {.platform_height_mm = s.platform_height_mm});
    sum_squares += (c.centre_mm - s.centre_mm).cwiseAbs2();
    predicted += c.covariance_mm2.diagonal();
  }
  // 60 records: the ratio of empirical to predicted variance has a relative sd of ~18 %.
  EXPECT_NEAR(sum_squares.x() / predicted.x(), 1.0, 0.6);
  EXPECT_NEAR(sum_squares.y() / predicted.y(), 1.0, 0.6);
}

TEST(SolveContactCentre, IgnoresMzAndTheSamplesWithoutContact) {
  ForceSimulation s = TypicalSimulation();
  s.noise_fraction = 0.0;
  s.duration_s = 2.0;
  s.approach_fraction = 0.5;
  std::mt19937 rng(8004);
  ForceRecord record = SimulateForceRecord(s, rng);
  const ContactCentre reference =
      SolveContactCentre(Tare(record, s.tare), {.platform_height_mm = s.platform_height_mm});
  for (size_t i = 0; i < record.size(); ++i)
    record.mz_Nmm[i] += 1e4 * std::sin(0.01 * static_cast<double>(i));
  // Garbage moments while the pad is not touching (|Fz| under 10 % of the median).
  for (size_t i = 0; i < 40; ++i) record.mx_Nmm[i] += 500.0;
  const ContactCentre disturbed =
      SolveContactCentre(Tare(record, s.tare), {.platform_height_mm = s.platform_height_mm});
  EXPECT_NEAR(disturbed.centre_mm.x(), s.centre_mm.x(), 1e-9);
  EXPECT_NEAR(disturbed.centre_mm.y(), s.centre_mm.y(), 1e-9);
  EXPECT_NEAR(reference.centre_mm.y(), s.centre_mm.y(), 1e-9);
}

TEST(SolveContactCentre, RefusesRecordsWithoutContactOrWithBadValues) {
  ForceSimulation s = TypicalSimulation();
  s.duration_s = 0.1;
  std::mt19937 rng(8005);
  const ForceRecord unloaded = SimulateUnloadedRecord(s, rng);
  s.noise_fraction = 0.0;
  s.tare = {};
  const ForceRecord flat = SimulateUnloadedRecord(s, rng);  // Fz == 0 everywhere
  EXPECT_EQ(ErrorOf([&] { (void)SolveContactCentre(flat, {.platform_height_mm = 20.0}); }).code(),
            ErrorCode::kFitFailed);
  ForceRecord nan_record = unloaded;
  nan_record.fz_N[7] = std::nan("");
  EXPECT_THAT(ErrorMessageOf([&] { (void)SolveContactCentre(nan_record, {.platform_height_mm = 20.0}); }),
              HasSubstr("Fz_N sample 8"));
  ForceRecord short_record = unloaded;
  short_record.my_Nmm.pop_back();
  EXPECT_THROW((void)MeanWrench(short_record), Error);
  EXPECT_THROW((void)SolveContactCentre(unloaded, {.platform_height_mm = std::nan("")}), Error);
}

TEST(TabulateMoves, ComputesRepeatabilityAndMoveAccuracy) {
  const std::vector<MoveSample> samples = {
      {{0, 0}, {10.0, 5.0}, "a"},
      {{0, 0}, {10.2, 5.0}, "b"},
      {{3, 4}, {13.1, 9.0}, "c"},
      {{3, 4}, {13.1, 9.2}, "d"},
  };
  const MoveTables tables = TabulateMoves(samples);
  ASSERT_EQ(tables.repeatability.size(), 2u);
  EXPECT_NEAR(tables.repeatability[0].mean_mm.x(), 10.1, 1e-12);
  EXPECT_NEAR(tables.repeatability[0].std_mm.x(), std::sqrt(0.02), 1e-12);  // sd of {10, 10.2}
  EXPECT_NEAR(tables.repeatability[0].max_deviation_mm, 0.1, 1e-12);
  ASSERT_EQ(tables.accuracy.size(), 1u);
  EXPECT_NEAR(tables.accuracy[0].commanded_move_mm, 5.0, 1e-12);
  EXPECT_NEAR(tables.accuracy[0].solved_move_mm, std::hypot(3.0, 4.1), 1e-12);
  EXPECT_NEAR(tables.worst_accuracy_mm, std::hypot(3.0, 4.1) - 5.0, 1e-12);
  EXPECT_THROW((void)TabulateMoves({}), Error);
}

// The patent's procedure end to end: calibrate the sensor against the machine by pressing at
// three points, command moves of 1, 2, 5 and 10 mm, and repeat at (0,0), (+1,0), (0,-1).
TEST(HeadCentre, ReproducesThePatentMoveTestInSimulation) {
  std::mt19937 rng(8006);
  ForceSimulation base = TypicalSimulation();
  base.duration_s = 10.0;
  // The sensor sits on the machine table rotated by 35 deg and shifted; the head's true removal
  // centre is off its commanded position by (0.30, -0.20) mm.
  const Eigen::Rotation2Dd rotation(35.0 * M_PI / 180.0);
  const Eigen::Vector2d shift(412.0, -96.5);
  const Eigen::Vector2d head_offset(0.30, -0.20);
  const auto machine_to_sensor = [&](const Eigen::Vector2d& machine) {
    return Eigen::Vector2d(rotation.inverse() * (machine - shift));
  };
  const Wrench tare = MeanWrench(SimulateUnloadedRecord(base, rng));
  const auto solve_at = [&](const Eigen::Vector2d& commanded) {
    ForceSimulation s = base;
    s.centre_mm = machine_to_sensor(commanded + head_offset);
    return SolveContactCentre(Tare(SimulateForceRecord(s, rng), tare),
                              {.platform_height_mm = s.platform_height_mm});
  };
  // Calibration presses with a probe at known machine points (no head offset for the probe).
  const Eigen::Vector2d sensor_centre_in_machine = shift;
  std::vector<PointPair> presses;
  for (const Eigen::Vector2d& p :
       {Eigen::Vector2d(-30, -30), Eigen::Vector2d(30, -30), Eigen::Vector2d(0, 35)}) {
    ForceSimulation s = base;
    s.centre_mm = machine_to_sensor(sensor_centre_in_machine + p);
    const ContactCentre c = SolveContactCentre(Tare(SimulateForceRecord(s, rng), tare),
                                               {.platform_height_mm = s.platform_height_mm});
    presses.push_back(
        {Eigen::Vector3d(c.centre_mm.x(), c.centre_mm.y(), 0),
         Eigen::Vector3d((sensor_centre_in_machine + p).x(), (sensor_centre_in_machine + p).y(), 0)});
  }
  const TransformFit calibration = FitTransform(presses, TransformModel::kRigid2d);
  EXPECT_NEAR(calibration.parameters(2), 35.0 * M_PI / 180.0, 1e-3);

  // Removal-centre offset: command the sensor's nominal centre, solve, map to the machine.
  const ContactCentre at_centre = solve_at(sensor_centre_in_machine);
  const Eigen::Vector3d actual =
      calibration.transform.ApplyToPoint({at_centre.centre_mm.x(), at_centre.centre_mm.y(), 0});
  EXPECT_NEAR(actual.x() - sensor_centre_in_machine.x(), head_offset.x(), 0.01);
  EXPECT_NEAR(actual.y() - sensor_centre_in_machine.y(), head_offset.y(), 0.01);

  // Moves of 1, 2, 5, 10 mm along machine X from the centre, three records at each position.
  std::vector<MoveSample> moves;
  for (const double move : {0.0, 1.0, 2.0, 5.0, 10.0}) {
    for (int repeat = 0; repeat < 3; ++repeat) {
      const Eigen::Vector2d commanded = sensor_centre_in_machine + Eigen::Vector2d(move, 0.0);
      moves.push_back({commanded, solve_at(commanded).centre_mm, ""});
    }
  }
  const MoveTables tables = TabulateMoves(moves);
  ASSERT_EQ(tables.accuracy.size(), 4u);
  const double commanded_moves[] = {1.0, 2.0, 5.0, 10.0};
  for (size_t i = 0; i < 4; ++i) {
    EXPECT_NEAR(tables.accuracy[i].commanded_move_mm, commanded_moves[i], 1e-9);
    EXPECT_NEAR(tables.accuracy[i].solved_move_mm, commanded_moves[i], 0.01);  // the patent: 0.5 mm
  }
  // Repeatability at (0,0), (+1,0), (0,-1): the patent reports better than 0.1 mm.
  std::vector<MoveSample> repeats;
  for (const Eigen::Vector2d& p : {Eigen::Vector2d(0, 0), Eigen::Vector2d(1, 0), Eigen::Vector2d(0, -1)}) {
    for (int repeat = 0; repeat < 5; ++repeat)
      repeats.push_back({p, solve_at(sensor_centre_in_machine + p).centre_mm, ""});
  }
  const MoveTables repeatability = TabulateMoves(repeats);
  EXPECT_EQ(repeatability.repeatability.size(), 3u);
  EXPECT_LT(repeatability.worst_repeatability_mm, 0.01);
}

TEST(ReadForceRecord, ConvertsUnitsAndRoundTripsCsvAndHdf5) {
  testing::TempDir dir;
  ForceSimulation s = TypicalSimulation();
  s.duration_s = 0.05;
  std::mt19937 rng(8007);
  const ForceRecord record = SimulateForceRecord(s, rng);
  { std::ofstream(dir / "a.csv") << ForceRecordCsv(record, {{"platform_height_mm", "22"}}); }
  const ForceRecordFile csv = ReadForceRecord(dir / "a.csv");
  EXPECT_EQ(csv.record.my_Nmm, record.my_Nmm);  // shortest round-trip text is exact
  EXPECT_EQ(*csv.platform_height_mm, 22.0);
  WriteForceRecordHdf5(dir / "a.h5", record, 22.0);
  const ForceRecordFile h5 = ReadForceRecord(dir / "a.h5");
  EXPECT_EQ(h5.record.fz_N, record.fz_N);
  EXPECT_EQ(*h5.platform_height_mm, 22.0);
  // The same samples in kN and N m, and with bare names and a unit note.
  {
    std::ofstream out(dir / "b.csv");
    out << "t_s,Fx_kN,Fy_kN,Fz_kN,Mx_Nm,My_Nm,Mz_Nm\n0,0.001,0.002,-0.03,0.5,-0.25,0.125\n";
    std::ofstream bare(dir / "c.csv");
    bare << "# force_unit: N\n# moment_unit: Nm\nt,Fx,Fy,Fz,Mx,My,Mz\n0,1,2,-30,0.5,-0.25,0.125\n";
  }
  for (const char* name : {"b.csv", "c.csv"}) {
    const ForceRecord r = ReadForceRecord(dir / name).record;
    EXPECT_DOUBLE_EQ(r.fz_N[0], -30.0) << name;
    EXPECT_DOUBLE_EQ(r.mx_Nmm[0], 500.0) << name;
    EXPECT_DOUBLE_EQ(r.mz_Nmm[0], 125.0) << name;
  }
}

TEST(ReadForceRecord, RefusesBadFilesNamingTheLine) {
  testing::TempDir dir;
  const auto expect_refusal = [&](const std::string& text, const std::string& words) {
    { std::ofstream(dir / "bad.csv") << text; }
    EXPECT_THAT(ErrorMessageOf([&] { (void)ReadForceRecord(dir / "bad.csv"); }), HasSubstr(words)) << text;
  };
  const std::string header = "t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_Nmm\n";
  expect_refusal(header + "0,1,2,3,4,5,6\n0.1,1,2,nan,4,5,6\n", "line 3, column 'Fz_N'");
  expect_refusal(header + "0,1,2,3,4,5,6\n0.1,1,2,3,4,5\n", "line 3: 6 cells");
  expect_refusal(header + "0,1,2,3,4,5,6\n0,1,2,3,4,5,6\n", "line 3: t_s");
  expect_refusal("t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm\n0,1,2,3,4,5\n", "no 'Mz' channel");
  expect_refusal("t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_lbin\n0,1,2,3,4,5,6\n", "unit 'lbin'");
  expect_refusal("t_s,Fx,Fy,Fz,Mx_Nmm,My_Nmm,Mz_Nmm\n0,1,2,3,4,5,6\n", "has no unit");
  expect_refusal(header, "no data rows");
}

TEST(ReadForceRecord, RefusesHdf5ChannelsOfDifferentLengthsOrWithNan) {
  testing::TempDir dir;
  ForceRecord record;
  record.source = "test";
  for (int i = 0; i < 5; ++i) {
    for (auto* channel : {&record.t_s, &record.fx_N, &record.fy_N, &record.fz_N, &record.mx_Nmm,
                          &record.my_Nmm, &record.mz_Nmm}) {
      channel->push_back(0.001 * i);
    }
  }
  ForceRecord short_channel = record;
  short_channel.my_Nmm.pop_back();
  WriteForceRecordHdf5(dir / "short.h5", short_channel);
  EXPECT_THAT(ErrorMessageOf([&] { (void)ReadForceRecord(dir / "short.h5"); }),
              HasSubstr("channel My_Nmm has 4 samples but t_s has 5"));
  ForceRecord nan_channel = record;
  nan_channel.fx_N[2] = std::nan("");
  WriteForceRecordHdf5(dir / "nan.h5", nan_channel);
  EXPECT_THAT(ErrorMessageOf([&] { (void)ReadForceRecord(dir / "nan.h5"); }), HasSubstr("Fx_N sample 3"));
}

}  // namespace
}  // namespace arcwheel::frames
