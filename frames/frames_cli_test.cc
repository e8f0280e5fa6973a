// End-to-end tests of `arcwheel frame`, `arcwheel transform` and `arcwheel headcenter`.

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "core/testing/testing.h"

namespace arcwheel::frames {
namespace {

using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)

std::string Read(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream buffer;
  buffer << in.rdbuf();
  return buffer.str();
}

nlohmann::json RunJson(const std::string& arguments) {
  const auto result = RunArcwheel(arguments);
  EXPECT_EQ(result.exit_status, 0) << result.output;
  return nlohmann::json::parse(result.output);
}

// Runs a command that must be refused: exit status, words in the message, and no new file.
void ExpectRefused(const TempDir& dir, const std::string& arguments, int status, const std::string& words) {
  const std::string before = ListFolder(dir.path());
  const auto result = RunArcwheel(arguments);
  EXPECT_EQ(result.exit_status, status) << arguments << "\n" << result.output;
  EXPECT_NE(result.output.find(words), std::string::npos) << arguments << "\n" << result.output;
  EXPECT_EQ(ListFolder(dir.path()), before) << arguments;
}

TEST(TransformFitCommand, WritesTheFormatsSection5Object) {
  TempDir dir;
  // target = 1.00002 * Rz(25 deg) * source + (10, -20, 5), exact.
  const double angle = 25.0 * M_PI / 180.0, scale = 1.00002;
  const Eigen::Matrix3d r = Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Vector3d t(10.0, -20.0, 5.0);
  std::string csv = "xs_mm,ys_mm,zs_mm,xt_mm,yt_mm,zt_mm\n";
  std::mt19937 rng(9101);
  std::uniform_real_distribution<double> coordinate(-200.0, 200.0);
  for (int i = 0; i < 7; ++i) {
    const Eigen::Vector3d s(coordinate(rng), coordinate(rng), coordinate(rng));
    const Eigen::Vector3d target = scale * r * s + t;
    csv += fmt::format("{},{},{},{},{},{}\n", s.x(), s.y(), s.z(), target.x(), target.y(), target.z());
  }
  WriteText(dir / "pairs.csv", csv);
  const nlohmann::json out =
      RunJson(fmt::format("transform fit {} --model similarity3d", (dir / "pairs.csv").string()));
  EXPECT_EQ(out["model"], "similarity3d");
  EXPECT_EQ(out["convention"], "target = scale * R * source + translation");
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col)
      EXPECT_NEAR(out["rotation_matrix"][row][col].get<double>(), r(row, col), 1e-12);
  }
  EXPECT_NEAR(out["rotation_matrix"][0][1].get<double>(), -std::sin(angle), 1e-12);  // row-major
  EXPECT_NEAR(out["scale"].get<double>(), scale, 1e-12);
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(out["translation"][k].get<double>(), t(k), 1e-9);
  EXPECT_LT(out["rms_residual_mm"].get<double>(), 1e-9);
  EXPECT_EQ(out["residuals_mm"].size(), 7u);
  EXPECT_NEAR(out["rotation_angles"]["position_vector_deg"][2].get<double>(), 25.0, 1e-9);
  EXPECT_NEAR(out["rotation_angles"]["coordinate_frame_deg"][2].get<double>(), -25.0, 1e-9);
  EXPECT_NEAR(out["scale_ppm"].get<double>(), 20.0, 1e-6);
}

TEST(TransformFitCommand, RefusesBadInputWithoutWritingOutput) {
  TempDir dir;
  WriteText(dir / "two.csv", "xs_mm,ys_mm,zs_mm,xt_mm,yt_mm,zt_mm\n0,0,0,1,1,1\n1,0,0,2,1,1\n");
  WriteText(dir / "line.csv", "xs_mm,ys_mm,zs_mm,xt_mm,yt_mm,zt_mm\n0,0,0,1,1,1\n1,0,0,2,1,1\n2,0,0,3,1,1\n");
  WriteText(dir / "ragged.csv", "xs_mm,ys_mm,xt_mm,yt_mm\n0,0,1,1\n1,0,2,1\n0,1\n");
  WriteText(dir / "nan.csv", "xs_mm,ys_mm,xt_mm,yt_mm\n0,0,1,1\n1,0,2,1\n0,1,nan,2\n");
  WriteText(dir / "flat.csv", "xs_mm,ys_mm,xt_mm,yt_mm\n0,0,1,1\n1,0,2,1\n0,1,1,2\n");
  const std::string out = (dir / "out.json").string();
  ExpectRefused(dir, fmt::format("transform fit {} --model rigid3d -o {}", (dir / "two.csv").string(), out),
                3, "needs at least 3");
  ExpectRefused(dir, fmt::format("transform fit {} --model rigid3d -o {}", (dir / "line.csv").string(), out),
                3, "collinear");
  ExpectRefused(dir,
                fmt::format("transform fit {} --model rigid2d -o {}", (dir / "ragged.csv").string(), out), 3,
                "line 4: 2 cells");
  ExpectRefused(dir, fmt::format("transform fit {} --model affine2d -o {}", (dir / "nan.csv").string(), out),
                3, "line 4, column 'xt_mm'");
  ExpectRefused(dir, fmt::format("transform fit {} --model rigid3d -o {}", (dir / "flat.csv").string(), out),
                3, "no column 'zs_mm'");
  ExpectRefused(dir, fmt::format("transform fit {} --model helmert -o {}", (dir / "flat.csv").string(), out),
                2, "unknown model 'helmert'");
}

TEST(FrameCommand, FrameAppliedToAToolpathAndBackRestoresIt) {
  TempDir dir;
  const nlohmann::json frame =
      RunJson("frame --origin 250,-120,33 --x-point 400,-100,33 --xy-point 260,-20,34");
  // The x axis is along P2 - P1.
  const Eigen::Vector3d x_axis = Eigen::Vector3d(150, 20, 0).normalized();
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(frame["frame"]["x_axis"][k].get<double>(), x_axis(k), 1e-14);
  WriteText(dir / "frame.json", frame.dump());
  const std::string toolpath =
      "# surface: test\nxw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min\n"
      "1.5,2.5,60.0,1.5,2.5,10.0,0.0,0.0,1.0,1200\n-40.25,12.0,55.0,-40.25,12.0,5.0,0.1,0.0,0.99498743710662,"
      "1200\n";
  WriteText(dir / "path.csv", toolpath);
  const auto forward = RunArcwheel(fmt::format("transform apply {} {} -o {}", (dir / "frame.json").string(),
                                               (dir / "path.csv").string(), (dir / "machine.csv").string()));
  ASSERT_EQ(forward.exit_status, 0) << forward.output;
  const std::string machine = Read(dir / "machine.csv");
  // The first contact point, by the method.md formula P' = P1 + [i j k] P, is in the file.
  const Eigen::Vector3d y_axis =
      (Eigen::Vector3d(10, 100, 1) - Eigen::Vector3d(10, 100, 1).dot(x_axis) * x_axis).normalized();
  const Eigen::Vector3d p =
      Eigen::Vector3d(250, -120, 33) + 1.5 * x_axis + 2.5 * y_axis + 10.0 * x_axis.cross(y_axis);
  std::stringstream lines(machine);
  std::string line;
  std::getline(lines, line);
  EXPECT_EQ(line, "# surface: test");
  std::getline(lines, line);
  std::getline(lines, line);
  double x = 0, y = 0, z = 0;
  ASSERT_EQ(std::sscanf(line.c_str(), "%*[^,],%*[^,],%*[^,],%lf,%lf,%lf", &x, &y, &z), 3) << line;
  EXPECT_NEAR(x, p.x(), 1e-9);
  EXPECT_NEAR(y, p.y(), 1e-9);
  EXPECT_NEAR(z, p.z(), 1e-9);
  EXPECT_NE(line.find(",1200"), std::string::npos);
  const auto back =
      RunArcwheel(fmt::format("transform apply {} {} --inverse -o {}", (dir / "frame.json").string(),
                              (dir / "machine.csv").string(), (dir / "back.csv").string()));
  ASSERT_EQ(back.exit_status, 0) << back.output;
  std::stringstream original(toolpath), restored(Read(dir / "back.csv"));
  std::string a, b;
  while (std::getline(original, a) && std::getline(restored, b)) {
    if (a.front() == '#' || a.front() == 'x') {
      EXPECT_EQ(a, b);
      continue;
    }
    std::stringstream ca(a), cb(b);
    std::string va, vb;
    while (std::getline(ca, va, ',') && std::getline(cb, vb, ','))
      EXPECT_NEAR(std::stod(va), std::stod(vb), 1e-11);
  }
}

TEST(FrameCommand, RefusesCollinearProbesAndUntransformablePrograms) {
  TempDir dir;
  const std::string out = (dir / "frame.json").string();
  ExpectRefused(dir, "frame --origin 0,0,0 --x-point 100,0,0 --xy-point 50,0,0 -o " + out, 3, "collinear");
  ExpectRefused(dir, "frame --origin 0,0,0 --x-point 0,0,0 --xy-point 50,10,0 -o " + out, 3, "coincide");
  WriteText(dir / "frame.json",
            RunArcwheel("frame --origin 0,0,0 --x-point 100,0,0 --xy-point 50,10,0").output);
  WriteText(dir / "arc.nc", "G90\nG0 X0 Y0 Z5\nG2 X10 Y0 I5 J0\n");
  ExpectRefused(dir,
                fmt::format("transform apply {} {} -o {}", (dir / "frame.json").string(),
                            (dir / "arc.nc").string(), (dir / "out.nc").string()),
                3, "line 3: G2");
}

TEST(HeadcenterCommand, SolvesASimulatedRecordAndRefusesNanForces) {
  TempDir dir;
  const std::string record = (dir / "rec.h5").string(), tare = (dir / "tare.csv").string();
  ASSERT_EQ(RunArcwheel(
                fmt::format("headcenter simulate -o {} --centre-mm 18.5,-6.25 --z0-mm 25 --seed 11", record))
                .exit_status,
            0);
  ASSERT_EQ(
      RunArcwheel(fmt::format("headcenter simulate -o {} --unloaded --z0-mm 25 --seed 12", tare)).exit_status,
      0);
  const nlohmann::json out = RunJson(fmt::format("headcenter solve {} --tare {}", record, tare));
  EXPECT_NEAR(out["centre_sensor_mm"][0].get<double>(), 18.5, 0.01);
  EXPECT_NEAR(out["centre_sensor_mm"][1].get<double>(), -6.25, 0.01);
  EXPECT_EQ(out["platform_height_mm"].get<double>(), 25.0);  // from the record's note

  WriteText(dir / "nan.csv",
            "t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_Nmm\n0,0,0,-30,10,10,0\n0.001,0,0,NaN,10,10,0\n");
  ExpectRefused(dir,
                fmt::format("headcenter solve {} --z0-mm 20 -o {}", (dir / "nan.csv").string(),
                            (dir / "o.json").string()),
                3, "line 3, column 'Fz_N'");
  WriteText(dir / "short.csv", "t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm\n0,0,0,-30,10,10\n");
  ExpectRefused(dir,
                fmt::format("headcenter solve {} --z0-mm 20 -o {}", (dir / "short.csv").string(),
                            (dir / "o.json").string()),
                3, "no 'Mz' channel");
  WriteText(dir / "plain.csv",
            "t_s,Fx_N,Fy_N,Fz_N,Mx_Nmm,My_Nmm,Mz_Nmm\n0,0,0,-30,10,10,0\n0.001,0,0,-30,10,10,0\n");
  ExpectRefused(
      dir, fmt::format("headcenter solve {} -o {}", (dir / "plain.csv").string(), (dir / "o.json").string()),
      2, "--z0-mm");
}

TEST(HeadcenterCommand, SimulateRefusesEveryBadSettingInOneMessage) {
  TempDir dir;
  ExpectRefused(
      dir, fmt::format("headcenter simulate -o {} --duration-s 0 --noise -1", (dir / "rec.csv").string()), 2,
      "frames.headcenter: --duration-s = 0 violates finite and > 0; --noise = -1 violates finite and >= 0");
}

TEST(HeadcenterCommand, CalibratesTheSensorAndTabulatesMoves) {
  TempDir dir;
  // Sensor frame = machine frame rotated by -20 deg and shifted by (300, 150).
  const Eigen::Rotation2Dd rotation(-20.0 * M_PI / 180.0);
  const Eigen::Vector2d shift(300.0, 150.0);
  const auto sensor = [&](const Eigen::Vector2d& machine) {
    return Eigen::Vector2d(rotation.inverse() * (machine - shift));
  };
  const auto simulate = [&](const std::string& name, const Eigen::Vector2d& machine, int seed) {
    const Eigen::Vector2d s = sensor(machine);
    const auto result = RunArcwheel(
        fmt::format("headcenter simulate -o {} --centre-mm {},{} --z0-mm 20 --duration-s 5 --seed {}",
                    (dir / name).string(), s.x(), s.y(), seed));
    ASSERT_EQ(result.exit_status, 0) << result.output;
  };
  ASSERT_EQ(RunArcwheel(fmt::format("headcenter simulate -o {} --unloaded --duration-s 5 --seed 1",
                                    (dir / "tare.csv").string()))
                .exit_status,
            0);
  std::string presses = "record,x_machine_mm,y_machine_mm\n";
  const Eigen::Vector2d points[] = {{270, 120}, {330, 125}, {300, 185}};
  for (int i = 0; i < 3; ++i) {
    simulate(fmt::format("press{}.csv", i), points[i], 10 + i);
    presses += fmt::format("press{}.csv,{},{}\n", i, points[i].x(), points[i].y());
  }
  WriteText(dir / "presses.csv", presses);
  const auto calibrate =
      RunArcwheel(fmt::format("headcenter calibrate {} --tare {} -o {}", (dir / "presses.csv").string(),
                              (dir / "tare.csv").string(), (dir / "cal.json").string()));
  ASSERT_EQ(calibrate.exit_status, 0) << calibrate.output;
  const nlohmann::json cal = nlohmann::json::parse(Read(dir / "cal.json"));
  EXPECT_NEAR(cal["rotation_deg"].get<double>(), -20.0, 0.05);
  EXPECT_NEAR(cal["translation"][0].get<double>(), 300.0, 0.02);

  std::string records = "record,commanded_x_mm,commanded_y_mm\n";
  int seed = 100;
  for (const double move : {0.0, 1.0, 2.0, 5.0, 10.0}) {
    for (int repeat = 0; repeat < 2; ++repeat) {
      const std::string name = fmt::format("move{}_{}.csv", move, repeat);
      simulate(name, shift + Eigen::Vector2d(move, 0.0), seed++);
      records += fmt::format("{},{},{}\n", name, shift.x() + move, shift.y());
    }
  }
  WriteText(dir / "moves.csv", records);
  const nlohmann::json tables =
      RunJson(fmt::format("headcenter moves {} --tare {} --calibration {}", (dir / "moves.csv").string(),
                          (dir / "tare.csv").string(), (dir / "cal.json").string()));
  ASSERT_EQ(tables["accuracy"].size(), 4u);
  const double moves[] = {1.0, 2.0, 5.0, 10.0};
  for (int i = 0; i < 4; ++i)
    EXPECT_NEAR(tables["accuracy"][i]["solved_move_mm"].get<double>(), moves[i], 0.02);
  EXPECT_EQ(tables["repeatability"][0]["count"], 2);
  EXPECT_LT(tables["worst_repeatability_mm"].get<double>(), 0.02);
  EXPECT_EQ(tables["frame"], "machine");
}

}  // namespace
}  // namespace arcwheel::frames
