// The arcwheel binary as a user runs it: outputs, exit codes, messages, nothing left behind.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/simulate.h"
#include "core/testing/json_file.h"
#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using testing::RunArcwheel;
using testing::TempDir;
using testing::WriteText;

using testing::ReadJson;

TEST(Cli, SimulateThenProcessWritesTheContractKeys) {
  TempDir dir;
  const auto sim =
      RunArcwheel("simulate " + (dir / "scan.h5").string() + " --noise-um 0.3 --radial-harmonic 1:4");
  ASSERT_EQ(sim.exit_status, 0) << sim.output;
  const auto run = RunArcwheel("process " + (dir / "scan.h5").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_NE(run.output.find("mean arc radius"), std::string::npos);
  EXPECT_EQ(testing::ListFolder(dir / "out"), "summary.json\nwheel_map.h5\n");
  const auto s = ReadJson(dir / "out" / "summary.json");
  for (const char* key :
       {"arcwheel_version", "input", "spindle_rpm_nominal", "spindle_rpm_estimated", "mean_arc_radius_mm",
        "mean_arc_radius_sigma_mm", "arc_radius_range_mm", "arc_radius_fluctuation_pct",
        "mean_center_axial_mm", "center_axial_deviation_mm", "band_half_width_mm", "max_arc_error_um",
        "max_runout_um", "max_roundness_um", "phases", "axial"}) {
    EXPECT_TRUE(s.contains(key)) << key;
  }
  EXPECT_EQ(s["input"]["sha256"].get<std::string>().size(), 64u);
  EXPECT_EQ(s["phases"]["phase_deg"].size(), 360u);
  EXPECT_NEAR(s["mean_arc_radius_mm"].get<double>(), 55.4423,
              4 * s["mean_arc_radius_sigma_mm"].get<double>());
  // Runout of a pure 4 um eccentricity is 8 um, plus the noise's peak-to-valley.
  EXPECT_NEAR(s["max_runout_um"].get<double>(), 8.0, 1.5);
}

// The file name's extension selects the reader in any case, and the record names that reader's
// format: an upper-case `SCAN.H5` is an HDF5 scan, not one from memory.
TEST(Cli, AnUpperCaseExtensionIsReadAndRecordedAsItsFormat) {
  TempDir dir;
  for (const auto& [name, format] : {std::pair{"SCAN.H5", "hdf5"}, std::pair{"SCAN.TXT", "csv"}}) {
    const std::filesystem::path scan = dir / name;
    ASSERT_EQ(RunArcwheel("simulate " + scan.string() + " --feed-mm-per-min 400").exit_status, 0) << name;
    const std::filesystem::path out = dir / (std::string(format) + "_out");
    const auto run = RunArcwheel("process -q --no-model " + scan.string() + " -o " + out.string());
    ASSERT_EQ(run.exit_status, 0) << run.output;
    EXPECT_EQ(ReadJson(out / "summary.json")["input"]["format"], format) << name;
  }
}

// --timings: a line per stage, in the order they ran, with wall time, CPU time of all threads and
// the peak memory so far; the total line sums the stages.
TEST(Cli, ProcessTimingsListEveryStageAndSumThem) {
  TempDir dir;
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "scan.h5").string() + " --noise-um 0.3").exit_status, 0);
  const auto run =
      RunArcwheel("process -q --timings " + (dir / "scan.h5").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  std::istringstream lines(run.output);
  std::vector<std::string> stages;
  double wall_s = 0.0, cpu_s = 0.0;
  const std::regex timing_line(R"(timing  (.+?) +([0-9.]+) s   cpu +([0-9.]+) s(.*))");
  for (std::string line; std::getline(lines, line);) {
    if (line.rfind("timing", 0) != 0) continue;
    std::smatch match;
    ASSERT_TRUE(std::regex_match(line, match, timing_line)) << line;
    const std::string name = match[1];
    const double wall = std::stod(match[2]);
    const double cpu = std::stod(match[3]);
    if (name == "total") {
      EXPECT_NEAR(wall, wall_s, 1e-3 * static_cast<double>(stages.size())) << line;
      EXPECT_NEAR(cpu, cpu_s, 1e-3 * static_cast<double>(stages.size())) << line;
      EXPECT_EQ(match[4], "") << line;
    } else {
      EXPECT_NE(match[4].str().find("peak memory"), std::string::npos) << line;
      stages.push_back(name);
      wall_s += wall;
      cpu_s += cpu;
    }
  }
  const std::vector<std::string> expected = {"reading",
                                             "valid span",
                                             "stuck readings",
                                             "noise and despike",
                                             "spindle speed",
                                             "map nodes and coverage",
                                             "per-phase fits",
                                             "wheel model",
                                             "releasing the samples",
                                             "uncertainty and turns",
                                             "characteristics",
                                             "waiting for the SHA-256",
                                             "writing"};
  EXPECT_EQ(stages, expected) << run.output;
}

TEST(Cli, ProcessWithReportWritesBothReportsBesideTheOutputs) {
  TempDir dir;
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "scan.h5").string() + " --radial-harmonic 1:4").exit_status, 0);
  const auto run = RunArcwheel("process -q " + (dir / "scan.h5").string() + " -o " + (dir / "out").string() +
                               " --report html,pdf");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(testing::ListFolder(dir / "out"), "report.html\nreport.pdf\nsummary.json\nwheel_map.h5\n");
  EXPECT_NE(RunArcwheel("process -q " + (dir / "scan.h5").string() + " -o " + (dir / "x").string() +
                        " --report docx")
                .exit_status,
            0);
}

TEST(Cli, CsvAndHdf5OfTheSameScanGiveTheSameNumbers) {
  TempDir dir;
  ASSERT_EQ(
      RunArcwheel("simulate " + (dir / "a.h5").string() + " --float64 --seed 3 --noise-um 0.2").exit_status,
      0);
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "a.csv").string() + " --seed 3 --noise-um 0.2").exit_status, 0);
  ASSERT_EQ(RunArcwheel("process -q " + (dir / "a.h5").string() + " -o " + (dir / "h").string()).exit_status,
            0);
  ASSERT_EQ(RunArcwheel("process -q " + (dir / "a.csv").string() + " -o " + (dir / "c").string()).exit_status,
            0);
  const auto h = ReadJson(dir / "h" / "summary.json");
  const auto c = ReadJson(dir / "c" / "summary.json");
  // The CSV keeps 1e-9 mm: the fits agree far below their sigmas.
  EXPECT_NEAR(h["mean_arc_radius_mm"].get<double>(), c["mean_arc_radius_mm"].get<double>(), 1e-6);
  EXPECT_EQ(h["input"]["valid_samples"], c["input"]["valid_samples"]);
}

struct BadInput {
  const char* name;
  const char* file_name;
  const char* contents;
  const char* expected_message;
};

class RefusedInput : public ::testing::TestWithParam<BadInput> {};

TEST_P(RefusedInput, GivesOneClearMessageAndWritesNothing) {
  const BadInput& bad = GetParam();
  TempDir dir;
  const auto input = dir / bad.file_name;
  WriteText(input, bad.contents);
  std::filesystem::create_directories(dir / "out");
  WriteText(dir / "out" / "summary.json", "{\"earlier\": true}");
  const auto run = RunArcwheel("process " + input.string() + " -o " + (dir / "out").string());
  EXPECT_NE(run.exit_status, 0);
  EXPECT_NE(run.output.find(bad.expected_message), std::string::npos) << run.output;
  EXPECT_NE(run.output.find(input.string()), std::string::npos)
      << "the message names the file: " << run.output;
  EXPECT_EQ(testing::ListFolder(dir / "out"), "summary.json\n");
  EXPECT_TRUE(ReadJson(dir / "out" / "summary.json")["earlier"].get<bool>());
}

const std::string kHeader = "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\n";

INSTANTIATE_TEST_SUITE_P(
    Section2p3, RefusedInput,
    ::testing::Values(
        BadInput{"NotHdf5", "scan.h5", "this is not HDF5", "not an HDF5 file"},
        BadInput{"NoValidSamples", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: "
                 "0.0001\nz_mm\nnan\n-FFFFFFF\nALARM\n",
                 "no valid samples"},
        BadInput{"MissingRpm", "scan.csv",
                 "# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm\n0.1\n0.2\n", "lacks spindle_rpm"},
        BadInput{"MissingPeriod", "scan.csv", "# spindle_rpm: 500\n# feed_mm_per_min: 100\nz_mm\n0.1\n0.2\n",
                 "lacks sample_period_s"},
        BadInput{"NegativeRpm", "scan.csv",
                 "# spindle_rpm: -500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm\n0.1\n",
                 "spindle_rpm must be positive"},
        BadInput{"ZeroPeriod", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0\nz_mm\n0.1\n",
                 "sample_period_s must be positive"},
        BadInput{
            "TooShort", "scan.csv",
            "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm\n0.1\n0.2\n0.3\n",
            "at least 2 are needed"},
        BadInput{"Unparsable", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: "
                 "0.0001\nz_mm,t_s\n0.1,0\n0.2,abc\n",
                 "line 6"},
        BadInput{"DecimalComma", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm;t_s\n0,1;0\n",
                 "decimal comma"},
        BadInput{"EmptyTimeCell", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm,t_s\n0.1,\n",
                 "empty t_s cell"},
        BadInput{"RaggedRow", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.0001\nz_mm,t_s\n0.1,0,7\n",
                 "has 3 cells"},
        BadInput{"UnknownColumn", "scan.csv", "# spindle_rpm: 500\nz_mm,speed\n0.1,0\n",
                 "unknown column 'speed'"},
        BadInput{"TimeNotIncreasing", "scan.csv",
                 "# spindle_rpm: 500\n# feed_mm_per_min: 100\nz_mm,t_s\n0.1,0\n0.1,0.1\n0.1,0.05\n",
                 "does not increase"},
        BadInput{"UnknownType", "scan.dat", "1 2 3", "unknown scan file type"}),
    [](const ::testing::TestParamInfo<BadInput>& param_info) { return std::string(param_info.param.name); });

TEST(Cli, ProcessRefusesEveryBadOptionOfBothStagesInOneMessageBeforeReadingTheScan) {
  TempDir dir;
  WriteText(dir / "scan.csv", "never read\n");
  const auto run = RunArcwheel("process " + (dir / "scan.csv").string() + " -o " + (dir / "out").string() +
                               " --phases 2 --despike-sigmas 0 --min-points 3");
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_NE(run.output.find("process: --despike-sigmas = 0 violates > 0; --phases = 2 violates 4..36000; "
                            "--min-points = 3 violates >= 4"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(Cli, ProcessNamesTheFlagOfEveryUnknownChoiceInTheSameMessage) {
  TempDir dir;
  WriteText(dir / "scan.csv", "never read\n");
  const auto run = RunArcwheel("process " + (dir / "scan.csv").string() + " -o " + (dir / "out").string() +
                               " --despike mean --rpm-source guess --fit-span half --phases 2");
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_NE(run.output.find("process: --despike = mean violates median, moving-mean or none; --rpm-source = "
                            "guess violates auto, nominal, encoder or estimate; --fit-span = half violates "
                            "band or full; --phases = 2 violates 4..36000"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(Cli, TruncatedHdf5IsRefusedAndEarlierOutputsSurvive) {
  TempDir dir;
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "scan.h5").string()).exit_status, 0);
  ASSERT_EQ(
      RunArcwheel("process -q " + (dir / "scan.h5").string() + " -o " + (dir / "out").string()).exit_status,
      0);
  const auto before = ReadJson(dir / "out" / "summary.json");
  std::filesystem::resize_file(dir / "scan.h5", std::filesystem::file_size(dir / "scan.h5") / 2);
  const auto run = RunArcwheel("process " + (dir / "scan.h5").string() + " -o " + (dir / "out").string());
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_NE(run.output.find("scan.h5"), std::string::npos) << run.output;
  EXPECT_EQ(testing::ListFolder(dir / "out"), "summary.json\nwheel_map.h5\n");
  EXPECT_EQ(ReadJson(dir / "out" / "summary.json"), before);
}

TEST(Cli, FitCircleGivesTheExactLeastSquaresCircleOfAnOffsetShortArc) {
  // Points on a 10 deg arc of radius 55 mm around (1e5, -1e5), with radial errors made
  // orthogonal to (1, cos t, sin t): the least-squares circle is then exactly the generating one.
  TempDir dir;
  const int n = 41;
  std::vector<double> t(n), e(n);
  for (int i = 0; i < n; ++i) {
    t[i] = (-5.0 + 10.0 * i / (n - 1)) * M_PI / 180.0;
    e[i] = 1e-3 * std::cos(7.3 * i);
  }
  // Gram-Schmidt e against 1, cos t, sin t.
  std::vector<std::vector<double>> basis;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> b(n);
    for (int i = 0; i < n; ++i) b[i] = k == 0 ? 1.0 : k == 1 ? std::cos(t[i]) : std::sin(t[i]);
    for (const auto& q : basis) {
      double dot = 0;
      for (int i = 0; i < n; ++i) dot += b[i] * q[i];
      for (int i = 0; i < n; ++i) b[i] -= dot * q[i];
    }
    double norm = 0;
    for (double v : b) norm += v * v;
    for (double& v : b) v /= std::sqrt(norm);
    double dot = 0;
    for (int i = 0; i < n; ++i) dot += e[i] * b[i];
    for (int i = 0; i < n; ++i) e[i] -= dot * b[i];
    basis.push_back(b);
  }
  std::ofstream out(dir / "points.csv");
  out.precision(17);
  out << "x_mm,y_mm\n";
  for (int i = 0; i < n; ++i) {
    out << 1e5 + (55.0 + e[i]) * std::cos(t[i]) << "," << -1e5 + (55.0 + e[i]) * std::sin(t[i]) << "\n";
  }
  out.close();
  const auto run = RunArcwheel("fit circle " + (dir / "points.csv").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto fit = nlohmann::json::parse(run.output);
  // Coordinates of 1e5 carry ~1e-11 mm of rounding; a 10 deg arc amplifies it about 1e3 times.
  EXPECT_NEAR(fit["radius"].get<double>(), 55.0, 1e-7);
  EXPECT_NEAR(fit["center"][0].get<double>(), 1e5, 1e-7);
  EXPECT_NEAR(fit["center"][1].get<double>(), -1e5, 1e-7);
  EXPECT_EQ(fit["n"].get<int>(), n);
}

// ---- fit circle --association and roundness (formats.md sections 4 and 8) ----------------------

// A closed trace: an eccentric circle (e = 10 um) with 2 um of 3-lobe form, every 1 deg.
std::string LobedTrace(int n = 360, double step_deg = 1.0) {
  std::ostringstream out;
  out.precision(17);
  out << "angle_deg,radius_mm\n";
  for (int i = 0; i < n; ++i) {
    const double t = step_deg * i * M_PI / 180.0;
    out << step_deg * i << "," << 20.0 + 0.01 * std::cos(t - 0.5) + 0.002 * std::cos(3 * t) << "\n";
  }
  return out.str();
}

TEST(Cli, RoundnessReportsTheParametersAndTheOperator) {
  TempDir dir;
  WriteText(dir / "trace.csv", LobedTrace());
  const auto run = RunArcwheel("roundness " + (dir / "trace.csv").string() + " --filter-upr 50");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto out = nlohmann::json::parse(run.output);
  // 2 um lobes at 3 UPR pass a 50 UPR filter at 2^-(3/50)^2 = 0.9975: RONt = 4 * 0.9975 um.
  const double lobe_um = 2.0 * std::pow(2.0, -(3.0 / 50) * (3.0 / 50));
  EXPECT_NEAR(out["RONt_um"].get<double>(), 2 * lobe_um, 1e-3 * lobe_um);
  EXPECT_NEAR(out["RONp_um"].get<double>(), lobe_um, 1e-3 * lobe_um);
  EXPECT_NEAR(out["RONv_um"].get<double>(), lobe_um, 1e-3 * lobe_um);
  EXPECT_NEAR(out["RONq_um"].get<double>(), lobe_um / std::sqrt(2.0), 1e-3 * lobe_um);
  EXPECT_EQ(out["association"], "minimum-zone");
  EXPECT_EQ(out["filter"]["type"], "gaussian");
  EXPECT_EQ(out["filter"]["cutoff_upr"].get<double>(), 50.0);
  EXPECT_EQ(out["operator"], "RONt, 50 UPR, MZ");
  EXPECT_EQ(out["support_point_indices"].size(), 4u);
  ASSERT_EQ(out["harmonics"].size(), 179u);
  EXPECT_NEAR(out["harmonics"][0]["amplitude_um"].get<double>(), 10.0, 1e-6);
  EXPECT_NEAR(out["harmonics"][2]["amplitude_um"].get<double>(), 2.0, 1e-6);
  const auto unfiltered =
      RunArcwheel("roundness " + (dir / "trace.csv").string() + " --no-filter --association least-squares");
  ASSERT_EQ(unfiltered.exit_status, 0) << unfiltered.output;
  const auto ls = nlohmann::json::parse(unfiltered.output);
  EXPECT_NEAR(ls["RONt_um"].get<double>(), 4.0, 4e-3);
  EXPECT_EQ(ls["filter"]["type"], "none");
  EXPECT_FALSE(ls.contains("support_point_indices"));
}

// x_mm,y_mm gives the same trace as angle_deg,radius_mm.
TEST(Cli, RoundnessReadsCartesianTraces) {
  TempDir dir;
  std::ostringstream out;
  out.precision(17);
  out << "x_mm,y_mm\n";
  for (int i = 0; i < 360; ++i) {
    const double t = i * M_PI / 180.0;
    const double r = 20.0 + 0.01 * std::cos(t - 0.5) + 0.002 * std::cos(3 * t);
    out << r * std::cos(t) << "," << r * std::sin(t) << "\n";
  }
  WriteText(dir / "xy.csv", out.str());
  WriteText(dir / "polar.csv", LobedTrace());
  const auto xy = RunArcwheel("roundness " + (dir / "xy.csv").string());
  const auto polar = RunArcwheel("roundness " + (dir / "polar.csv").string());
  ASSERT_EQ(xy.exit_status, 0) << xy.output;
  ASSERT_EQ(polar.exit_status, 0) << polar.output;
  EXPECT_NEAR(nlohmann::json::parse(xy.output)["RONt_um"].get<double>(),
              nlohmann::json::parse(polar.output)["RONt_um"].get<double>(), 1e-9);
}

// A refused command line: its exit status and a part of its message.
struct Refusal {
  std::string arguments;
  int exit_status;
  std::string message;
};

// Each refusal: the exit status, the message, and no result (its first key) printed.
void ExpectRefusals(const std::string& command, const std::string& result_key,
                    const std::vector<Refusal>& cases) {
  for (const Refusal& c : cases) {
    const auto run = RunArcwheel(command + " " + c.arguments);
    EXPECT_EQ(run.exit_status, c.exit_status) << c.arguments << ": " << run.output;
    EXPECT_EQ(run.output.find(result_key), std::string::npos) << c.arguments << ": no result may be printed";
    EXPECT_NE(run.output.find(c.message), std::string::npos) << c.arguments << ": " << run.output;
  }
}

// Each refusal: non-zero exit, the file and line or option named, no result printed.
TEST(Cli, RoundnessRefusesWhatItCannotEvaluate) {
  TempDir dir;
  const std::string trace = (dir / "trace.csv").string();
  WriteText(dir / "trace.csv", LobedTrace());
  std::string gap = LobedTrace();
  const auto line_of_100 = gap.find("\n100,");
  gap.erase(line_of_100, gap.find('\n', line_of_100 + 1) - line_of_100);
  WriteText(dir / "gap.csv", gap);
  WriteText(dir / "short.csv", LobedTrace(7, 360.0 / 7));
  WriteText(dir / "half.csv", LobedTrace(180, 0.5));
  WriteText(dir / "columns.csv", "angle,radius\n0,1\n");
  const std::vector<Refusal> cases = {
      {trace + " --association chebyshev", 2, "--association: chebyshev not in"},
      {trace + " --filter-upr spline", 2, "--filter-upr"},
      {trace + " --filter-upr 0", 2, "--filter-upr 0 violates > 0"},
      {trace + " --filter-upr -5", 2, "--filter-upr -5 violates > 0"},
      {trace + " --filter-upr 181", 2,
       "--filter-upr 181 is above half the 360 points of '" + trace + "' (180 UPR)"},
      {trace + " --filter-upr 50 --no-filter", 2, "excludes"},
      {(dir / "short.csv").string(), 3, "short.csv': a closed profile needs at least 8 points, got 7"},
      {(dir / "gap.csv").string(), 3, "the largest gap is 2 deg, from line 101 to line 102"},
      {(dir / "half.csv").string(), 3, "half.csv': the angles are not equally spaced over one turn"},
      {(dir / "columns.csv").string(), 3,
       "columns.csv': the header names neither pair of columns angle_deg,radius_mm or x_mm,y_mm"},
  };
  ExpectRefusals("roundness", "\"RONt_um\"", cases);
}

// Minimum zone through the CLI: four contacts alternating on two circles 20 um apart, every other
// point strictly between, far from the origin.
TEST(Cli, FitCircleGivesTheMinimumZoneWithItsSupportPoints) {
  TempDir dir;
  std::ostringstream out;
  out.precision(17);
  out << "x_mm,y_mm\n";
  const double cx = 3000.0, cy = -4000.0;
  const std::vector<int> support = {10, 55, 100, 150};
  for (int i = 0; i < 200; ++i) {
    const double t = 2 * M_PI * i / 200;
    const auto k = std::find(support.begin(), support.end(), i) - support.begin();
    const double r = k < 4 ? (k % 2 == 0 ? 40.01 : 39.99) : 40.0 + 0.008 * std::sin(7.0 * i);
    out << cx + r * std::cos(t) << "," << cy + r * std::sin(t) << "\n";
  }
  WriteText(dir / "points.csv", out.str());
  const auto run = RunArcwheel("fit circle " + (dir / "points.csv").string() + " --association minimum-zone");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto fit = nlohmann::json::parse(run.output);
  EXPECT_NEAR(fit["center"][0].get<double>(), cx, 1e-7);
  EXPECT_NEAR(fit["center"][1].get<double>(), cy, 1e-7);
  EXPECT_NEAR(fit["radius_inner_mm"].get<double>(), 39.99, 1e-7);
  EXPECT_NEAR(fit["radius_outer_mm"].get<double>(), 40.01, 1e-7);
  EXPECT_NEAR(fit["zone_width_mm"].get<double>(), 0.02, 1e-7);
  EXPECT_EQ(fit["association"], "minimum-zone");
  std::vector<int> found = fit["support_point_indices"].get<std::vector<int>>();
  std::sort(found.begin(), found.end());
  EXPECT_EQ(found, support);
  EXPECT_EQ(fit["n"].get<int>(), 200);
  for (const char* association : {"maximum-inscribed", "minimum-circumscribed"}) {
    const auto other =
        RunArcwheel("fit circle " + (dir / "points.csv").string() + " --association " + association);
    ASSERT_EQ(other.exit_status, 0) << other.output;
    const auto circle = nlohmann::json::parse(other.output);
    EXPECT_EQ(circle["association"], association);
    // The zone's inner circle is inscribed and its outer circle encloses: the largest inscribed
    // circle is no smaller, the smallest enclosing one no larger.
    if (std::string(association) == "maximum-inscribed") {
      EXPECT_GE(circle["radius"].get<double>(), 39.99 - 1e-9);
    } else {
      EXPECT_LE(circle["radius"].get<double>(), 40.01 + 1e-9);
    }
    EXPECT_GE(circle["support_point_indices"].size(), 2u);
  }
}

TEST(Cli, FitCircleRefusesCollinearPointsAndUnknownAssociations) {
  TempDir dir;
  WriteText(dir / "line.csv", "x_mm,y_mm\n0,1\n1,3\n2,5\n3,7\n");
  WriteText(dir / "two.csv", "x_mm,y_mm\n0,1\n1,3\n");
  WriteText(dir / "arc.csv", "x_mm,y_mm\n10,0\n9.9,1.41\n9.6,2.8\n9.2,3.9\n8.7,4.9\n");
  const std::vector<Refusal> cases = {
      {(dir / "line.csv").string(), 3, "line.csv': all 4 points lie on one line"},
      {(dir / "line.csv").string() + " --association minimum-zone", 3, "all 4 points lie on one line"},
      {(dir / "two.csv").string(), 3, "two.csv': a circle needs at least 3 points, got 2"},
      {(dir / "arc.csv").string() + " --association minimum-circumscribed", 3,
       "not defined for points within half a turn"},
      {(dir / "line.csv").string() + " --association chebyshev", 2, "--association: chebyshev not in"},
  };
  ExpectRefusals("fit circle", "\"center\"", cases);
}

TEST(Cli, TheSameInputGivesByteIdenticalFiles) {
  TempDir dir;
  for (const char* name : {"a.h5", "b.h5"}) {
    ASSERT_EQ(RunArcwheel("simulate " + (dir / name).string() + " --noise-um 0.2 --seed 5").exit_status, 0);
  }
  std::ifstream a(dir / "a.h5", std::ios::binary), b(dir / "b.h5", std::ios::binary);
  const std::string bytes_a((std::istreambuf_iterator<char>(a)), {}),
      bytes_b((std::istreambuf_iterator<char>(b)), {});
  EXPECT_EQ(bytes_a, bytes_b) << "a scan's SHA-256 must not depend on when it was written";
}

TEST(Cli, UnknownCommandPointsToHelp) {
  const auto run = RunArcwheel("frobnicate");
  EXPECT_EQ(run.exit_status, 1);
  EXPECT_NE(run.output.find("unknown command 'frobnicate' (`arcwheel help`"), std::string::npos)
      << run.output;
}

TEST(Cli, AMistypedCommandIsAnsweredWithTheNearestOne) {
  const auto run = RunArcwheel("batchx");
  EXPECT_EQ(run.exit_status, 1);
  EXPECT_NE(run.output.find("unknown command 'batchx'; did you mean 'batch'?"), std::string::npos)
      << run.output;
  const auto help = RunArcwheel("help regenrate");
  EXPECT_EQ(help.exit_status, 1);
  EXPECT_NE(help.output.find("did you mean 'regenerate'?"), std::string::npos) << help.output;
}

// The commands the table holds, each with its one-line help, as a newcomer's first two tries show
// them: `arcwheel help` (exit 0) and a bare `arcwheel` (exit 1, a usage error).
TEST(Cli, HelpAndABareCallListEveryCommand) {
  const auto help = RunArcwheel("help");
  const auto bare = RunArcwheel("");
  EXPECT_EQ(help.exit_status, 0);
  EXPECT_EQ(bare.exit_status, 1);
  for (const char* command :
       {"simulate", "process", "fit", "roundness", "toolpath", "report", "compare", "history", "frame",
        "transform", "headcenter", "polish", "regenerate", "batch", "version", "help"}) {
    const std::string line = "\n  " + std::string(command) + " ";
    EXPECT_NE(help.output.find(line), std::string::npos) << command << " missing from:\n" << help.output;
    EXPECT_NE(bare.output.find(line), std::string::npos) << command << " missing from:\n" << bare.output;
  }
}

TEST(Cli, HelpOfACommandIsThatCommandsHelp) {
  const auto help = RunArcwheel("help process");
  const auto own = RunArcwheel("process --help");
  EXPECT_EQ(help.exit_status, 0);
  EXPECT_EQ(own.exit_status, 0);
  EXPECT_NE(help.output.find("--band-half-width-mm"), std::string::npos) << help.output;
  EXPECT_EQ(help.output, own.output);
}

}  // namespace
}  // namespace arcwheel
