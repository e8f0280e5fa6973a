// The arcwheel binary as a user runs it: outputs, exit codes, messages, nothing left behind.

#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "acquisition/simulate.h"
#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using testing::RunArcwheel;
using testing::TempDir;
using testing::WriteText;

nlohmann::json ReadJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

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
                                             "helix spline",
                                             "sections and map",
                                             "coverage counts",
                                             "per-phase fits",
                                             "wheel model",
                                             "releasing the samples",
                                             "uncertainty",
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
       {"simulate", "process", "fit", "toolpath", "report", "compare", "history", "frame", "transform",
        "headcenter", "polish", "regenerate", "batch", "version", "help"}) {
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
