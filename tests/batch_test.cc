// `arcwheel batch` end to end: a folder of simulated scans with two bad files among them, the
// index against each scan's truth, a rerun that reuses what finished, an interrupted batch.

#include <gmock/gmock.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "core/testing/json_file.h"
#include "core/testing/testing.h"

namespace arcwheel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;
using testing::ReadText;
using testing::RunArcwheel;
using testing::TempDir;
using testing::WriteText;

using testing::ReadJson;

// The truth's mean arc radius and arc-centre axial position: the means over the per-phase
// generating circles that `simulate` wrote.
struct Truth {
  double mean_arc_radius_mm = 0.0;
  double mean_center_axial_mm = 0.0;
};
Truth ReadTruth(const fs::path& truth_json) {
  const json phases = ReadJson(truth_json)["phases"];
  Truth truth;
  const size_t n = phases["arc_radius_mm"].size();
  for (size_t i = 0; i < n; ++i) {
    truth.mean_arc_radius_mm += phases["arc_radius_mm"][i].get<double>() / static_cast<double>(n);
    truth.mean_center_axial_mm += phases["center_axial_mm"][i].get<double>() / static_cast<double>(n);
  }
  return truth;
}

// By default a short scan (4x the paper's feed: 3e4 samples, a fraction of a second to process).
void Simulate(const fs::path& scan, int seed, double arc_radius_mm, const std::string& extra = "",
              const std::string& sampling = "--feed-mm-per-min 400") {
  const auto run =
      RunArcwheel("simulate " + scan.string() + " " + sampling + " --noise-um 0.5 --seed " +
                  std::to_string(seed) + " --arc-radius-mm " + std::to_string(arc_radius_mm) + " " + extra);
  ASSERT_EQ(run.exit_status, 0) << run.output;
}

std::vector<std::string> Lines(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// Ten scans in one folder: eight good ones (HDF5 and CSV, arc radii 50-57 mm, some with a
// varying radius), a truncated HDF5 file and a CSV with a ragged line; batched at -j 2.
class BatchOfTen : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    const fs::path scans = *dir_ / "scans";
    fs::create_directories(scans);
    for (int i = 0; i < 8; ++i) {
      const std::string name = "wheel_" + std::to_string(i) + (i % 3 == 2 ? ".csv" : ".h5");
      Simulate(scans / name, 100 + i, 50.0 + i, i % 2 == 1 ? "--radius-harmonic 2:0.01" : "");
    }
    // A scan cut off part way: its HDF5 structures end early.
    Simulate(*dir_ / "whole.h5", 200, 55.0);
    const std::string whole = ReadText(*dir_ / "whole.h5");
    WriteText(scans / "truncated.h5", whole.substr(0, whole.size() / 2));
    // A CSV whose 200th line has three cells under a one-column header.
    Simulate(*dir_ / "ragged.csv", 201, 55.0);
    std::vector<std::string> lines = Lines(ReadText(*dir_ / "ragged.csv"));
    lines[199] = "0.1,0,7";
    std::string text;
    for (const std::string& line : lines) text += line + "\n";
    WriteText(scans / "ragged.csv", text);
    first_ = RunArcwheel("batch " + scans.string() + " -o " + (*dir_ / "out").string() + " -j 2");
  }
  static void TearDownTestSuite() { dir_.reset(); }

  static fs::path Out() { return *dir_ / "out"; }
  static json RowOf(const json& index, const std::string& file_name) {
    for (const json& row : index["scans"]) {
      if (fs::path(row["scan"].get<std::string>()).filename() == file_name) return row;
    }
    ADD_FAILURE() << "no row for " << file_name;
    return json::object();
  }

  static std::unique_ptr<TempDir> dir_;
  static testing::CommandResult first_;
};
std::unique_ptr<TempDir> BatchOfTen::dir_;
testing::CommandResult BatchOfTen::first_;

TEST_F(BatchOfTen, WritesEightResultsAndNamesTheTwoFailures) {
  EXPECT_EQ(first_.exit_status, 6) << first_.output;
  EXPECT_EQ(testing::ListFolder(Out()),
            "index.csv\nindex.json\nlogs\nwheel_0\nwheel_1\nwheel_2\nwheel_3\nwheel_4\nwheel_5\nwheel_"
            "6\nwheel_7\n");
  for (int i = 0; i < 8; ++i) {
    EXPECT_EQ(testing::ListFolder(Out() / ("wheel_" + std::to_string(i))),
              "step_inputs.json\nsummary.json\nwheel_map.h5\n");
  }
  const json index = ReadJson(Out() / "index.json");
  ASSERT_EQ(index["scans"].size(), 10u);
  EXPECT_EQ(index["counts"]["done"], 8);
  EXPECT_EQ(index["counts"]["failed"], 2);
  const json truncated = RowOf(index, "truncated.h5");
  EXPECT_EQ(truncated["status"], "failed");
  EXPECT_EQ(truncated["exit_code"], 3);
  EXPECT_THAT(truncated["message"].get<std::string>(), HasSubstr("truncated.h5"));
  EXPECT_THAT(truncated["message"].get<std::string>(), HasSubstr("damaged or truncated"));
  const json ragged = RowOf(index, "ragged.csv");
  EXPECT_EQ(ragged["status"], "failed");
  EXPECT_EQ(ragged["exit_code"], 3);
  EXPECT_THAT(ragged["message"].get<std::string>(), HasSubstr("ragged.csv"));
  EXPECT_THAT(ragged["message"].get<std::string>(), HasSubstr("line 200"));
  EXPECT_THAT(first_.output, HasSubstr("FAILED truncated"));
  EXPECT_THAT(first_.output, HasSubstr("FAILED ragged"));
}

// The index's numbers against the simulated truth, not against the summaries they were copied
// from: a 3-sigma miss of the arc radius or the arc centre would show a wrong or shuffled row.
TEST_F(BatchOfTen, TheIndexAgreesWithEachScansTruth) {
  const json index = ReadJson(Out() / "index.json");
  int checked = 0;
  for (const json& row : index["scans"]) {
    if (row["status"] != "done") continue;
    const fs::path scan = row["scan"].get<std::string>();
    const Truth truth = ReadTruth(scan.string() + ".truth.json");
    const double sigma = row["mean_arc_radius_sigma_mm"].get<double>();
    EXPECT_GT(sigma, 0.0);
    EXPECT_NEAR(row["mean_arc_radius_mm"].get<double>(), truth.mean_arc_radius_mm, 3 * sigma) << scan;
    EXPECT_NEAR(row["mean_center_axial_mm"].get<double>(), truth.mean_center_axial_mm,
                3 * row["mean_center_axial_sigma_mm"].get<double>())
        << scan;
    EXPECT_TRUE(row["max_runout_um"].is_number()) << scan;
    EXPECT_TRUE(row["model_mean_arc_radius_sigma_mm"].is_number()) << scan;
    ++checked;
  }
  EXPECT_EQ(checked, 8);
}

// The CSV carries the same rows and numbers as the JSON.
TEST_F(BatchOfTen, TheCsvIndexHoldsTheSameRows) {
  const json index = ReadJson(Out() / "index.json");
  const std::vector<std::string> lines = Lines(ReadText(Out() / "index.csv"));
  ASSERT_EQ(lines.size(), 11u);
  EXPECT_THAT(lines[0], HasSubstr("scan,result,status,exit_code,message,seconds,mean_arc_radius_mm,"
                                  "mean_arc_radius_sigma_mm,"));
  for (size_t i = 0; i < 10; ++i) {
    const json& row = index["scans"][i];
    EXPECT_THAT(lines[i + 1],
                HasSubstr(row["scan"].get<std::string>() + "," + row["result"].get<std::string>() + "," +
                          row["status"].get<std::string>()));
    if (row["status"] == "done") {
      std::ostringstream radius;
      radius.precision(17);
      radius << row["mean_arc_radius_mm"].get<double>();
      EXPECT_THAT(lines[i + 1], HasSubstr(radius.str().substr(0, 10)));
    }
  }
}

// Runs after the others in this file (gtest keeps the order of definition): it reruns the batch.
TEST_F(BatchOfTen, ASecondRunReusesTheEightAndRetriesTheTwo) {
  std::map<std::string, fs::file_time_type> written;
  for (int i = 0; i < 8; ++i) {
    const fs::path folder = Out() / ("wheel_" + std::to_string(i));
    for (const char* file : {"summary.json", "wheel_map.h5", "step_inputs.json"})
      written[(folder / file).string()] = fs::last_write_time(folder / file);
  }
  const auto second = RunArcwheel("batch " + (*dir_ / "scans").string() + " -o " + Out().string() + " -j 2");
  EXPECT_EQ(second.exit_status, 6) << second.output;
  for (const auto& [file, time] : written) EXPECT_EQ(fs::last_write_time(file), time) << file;
  size_t reused = 0;
  for (const std::string& line : Lines(second.output))
    reused += line.find("] reused wheel_") != std::string::npos;
  EXPECT_EQ(reused, 8u) << second.output;
  EXPECT_THAT(second.output, HasSubstr("0 done, 8 reused, 2 failed"));
  const json index = ReadJson(Out() / "index.json");
  EXPECT_EQ(index["counts"]["reused"], 8);
  EXPECT_EQ(index["counts"]["failed"], 2);
  EXPECT_TRUE(RowOf(index, "wheel_3.h5")["mean_arc_radius_mm"].is_number());

  // Other process options are other results: nothing is reused.
  const auto index_only = RunArcwheel("batch " + (*dir_ / "scans").string() + " -o " + Out().string() +
                                      " --index-only -- --phases 180");
  EXPECT_EQ(index_only.exit_status, 6);
  EXPECT_EQ(ReadJson(Out() / "index.json")["counts"]["not run"], 10) << index_only.output;
}

TEST(Batch, RefusesTwoScansOfOneNameAndWritesNothing) {
  TempDir dir;
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  Simulate(dir / "a" / "scan.h5", 1, 55.0);
  fs::copy_file(dir / "a" / "scan.h5", dir / "b" / "scan.h5");
  const auto run = RunArcwheel("batch " + (dir / "a").string() + " " + (dir / "b").string() + " -o " +
                               (dir / "out").string());
  EXPECT_EQ(run.exit_status, 2);
  EXPECT_THAT(run.output, HasSubstr("would both be written to OUTDIR/scan"));
  EXPECT_THAT(run.output, HasSubstr((dir / "b" / "scan.h5").string()));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(Batch, RefusesAProcessOptionTypoBeforeRunningAnything) {
  TempDir dir;
  Simulate(dir / "scan.h5", 1, 55.0);
  const auto run =
      RunArcwheel("batch " + (dir / "scan.h5").string() + " -o " + (dir / "out").string() + " -- --phase 90");
  EXPECT_EQ(run.exit_status, 2);
  EXPECT_THAT(run.output, HasSubstr("--phase"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

// A folder's scans are the files of every extension `process` reads, in any case: the record of
// each names the format its reader used; a file of another type is left out.
TEST(Batch, TakesEveryExtensionProcessReadsInAnyCase) {
  TempDir dir;
  fs::create_directories(dir / "scans");
  const std::map<std::string, std::string> format_of = {
      {"a.h5", "hdf5"}, {"b.HDF5", "hdf5"}, {"c.Csv", "csv"}, {"d.txt", "csv"}, {"e.TXT", "csv"}};
  int seed = 1;
  for (const auto& [name, format] : format_of) Simulate(dir / "scans" / name, seed++, 55.0);
  WriteText(dir / "scans" / "notes.md", "not a scan\n");
  const auto run = RunArcwheel("batch " + (dir / "scans").string() + " -o " + (dir / "out").string() +
                               " -- --no-model --no-uncertainty");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(ReadJson(dir / "out" / "index.json")["scans"].size(), format_of.size());
  for (const auto& [name, format] : format_of) {
    const json summary = ReadJson(dir / "out" / fs::path(name).stem() / "summary.json");
    EXPECT_EQ(summary["input"]["format"], format) << name;
  }
}

// A list file names scans relative to itself; the process options reach every child (the
// summaries record the phases used).
TEST(Batch, TakesAListFileAndPassesTheProcessOptionsThrough) {
  TempDir dir;
  fs::create_directories(dir / "lists" / "scans");
  Simulate(dir / "lists" / "scans" / "one.h5", 1, 55.0);
  Simulate(dir / "lists" / "scans" / "two.csv", 2, 56.0);
  WriteText(dir / "lists" / "batch.txt", "# two scans\nscans/one.h5\n\nscans/two.csv\n");
  const auto run = RunArcwheel("batch @" + (dir / "lists" / "batch.txt").string() + " -o " +
                               (dir / "out").string() + " -- --phases 120 --no-model");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  for (const char* name : {"one", "two"}) {
    const json summary = ReadJson(dir / "out" / name / "summary.json");
    EXPECT_EQ(summary["processing"]["phases"], 120) << name;
    EXPECT_EQ(summary["phases"]["phase_deg"].size(), 120u) << name;
    EXPECT_FALSE(summary.contains("model")) << name;
  }
}

// The emitted array script, run task by task as Slurm would run it (SLURM_ARRAY_TASK_ID set, no
// Slurm needed: tests/slurm/run_slurm_test.sh runs it under a real one), then --index-only.
TEST(Batch, TheSlurmScriptRunsOneScanPerTaskAndTheIndexFollows) {
  TempDir dir;
  fs::create_directories(dir / "scans");
  Simulate(dir / "scans" / "one.h5", 1, 54.0);
  Simulate(dir / "scans" / "two.csv", 2, 56.0);
  const std::string batch = "batch " + (dir / "scans").string() + " -o " + (dir / "out").string();
  const auto emit = RunArcwheel(batch + " --emit-slurm " + (dir / "job.sh").string() +
                                " --sbatch=--time=5 -- --phases 90 --no-model");
  ASSERT_EQ(emit.exit_status, 0) << emit.output;
  const std::string script = ReadText(dir / "job.sh");
  EXPECT_THAT(script, HasSubstr("#SBATCH --array=0-1\n"));
  EXPECT_THAT(script, HasSubstr("#SBATCH --time=5\n"));
  EXPECT_THAT(script,
              HasSubstr("#SBATCH --output=\"" + (dir / "out").string() + "/logs/slurm-%A_%a.out\"\n"));
  EXPECT_FALSE(fs::exists(dir / "out" / "one")) << "emitting runs nothing";
  for (int task = 0; task < 2; ++task) {
    EXPECT_EQ(
        testing::Shell("SLURM_ARRAY_TASK_ID=" + std::to_string(task) + " bash " + (dir / "job.sh").string() +
                       " > " + (dir / ("task" + std::to_string(task) + ".txt")).string() + " 2>&1"),
        0)
        << ReadText(dir / ("task" + std::to_string(task) + ".txt"));
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "index.json")) << "the tasks write no index";
  EXPECT_EQ(ReadJson(dir / "out" / "one" / "summary.json")["processing"]["phases"], 90);
  const auto index = RunArcwheel(batch + " --index-only -- --phases 90 --no-model");
  EXPECT_EQ(index.exit_status, 0) << index.output;
  const json rows = ReadJson(dir / "out" / "index.json")["scans"];
  ASSERT_EQ(rows.size(), 2u);
  for (const json& row : rows) {
    EXPECT_EQ(row["status"], "done") << row.dump();
    const Truth truth = ReadTruth(row["scan"].get<std::string>() + ".truth.json");
    EXPECT_NEAR(row["mean_arc_radius_mm"].get<double>(), truth.mean_arc_radius_mm,
                3 * row["mean_arc_radius_sigma_mm"].get<double>());
  }
}

// On a terminal (a pseudo-terminal from util-linux's `script`), one refreshed bar with the counts,
// the rate and the time left; in a file, one plain line per scan and no escape codes.
TEST(Batch, ShowsABarOnATerminalAndPlainLinesOtherwise) {
  TempDir dir;
  fs::create_directories(dir / "scans");
  Simulate(dir / "scans" / "one.h5", 1, 55.0);
  Simulate(dir / "scans" / "two.h5", 2, 56.0);
  const std::string batch = std::string(std::getenv("ARCWHEEL_BINARY")) + " batch " +
                            (dir / "scans").string() + " -j 2 -o " + (dir / "tty").string() +
                            " -- --no-model";
  ASSERT_EQ(testing::Shell("script -qec '" + batch + "' /dev/null > " + (dir / "tty.txt").string() + " 2>&1"),
            0)
      << ReadText(dir / "tty.txt");
  const std::string on_terminal = ReadText(dir / "tty.txt");
  EXPECT_THAT(on_terminal, HasSubstr("\r\033[Kbatch ["));
  EXPECT_THAT(on_terminal, HasSubstr("2/2 scans, 0 failed, "));
  EXPECT_THAT(on_terminal, HasSubstr(" scans/s, about "));
  EXPECT_THAT(on_terminal, ::testing::Not(HasSubstr("] done one")));

  const auto plain = RunArcwheel("batch " + (dir / "scans").string() + " -j 2 -o " + (dir / "file").string() +
                                 " -- --no-model");
  ASSERT_EQ(plain.exit_status, 0) << plain.output;
  EXPECT_THAT(plain.output, HasSubstr("] done one in "));
  EXPECT_THAT(plain.output, HasSubstr("] done two in "));
  EXPECT_THAT(plain.output, ::testing::Not(HasSubstr("\033")));
}

// The pid of the running `arcwheel process` of `scan`, 0 when there is none (yet).
pid_t ProcessChildOf(const fs::path& scan) {
  for (const fs::directory_entry& entry : fs::directory_iterator("/proc")) {
    const std::string name = entry.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    const std::string cmdline = ReadText(entry.path() / "cmdline");
    if (cmdline.find(std::string("process") + '\0' + scan.string()) != std::string::npos) {
      return static_cast<pid_t>(std::stoi(name));
    }
  }
  return 0;
}

// A child that dies (SIGKILL stands in for a crash) costs only its own scan: the batch records
// the signal, removes what the child left in its folder and goes on.
TEST(Batch, AChildKilledPartWayIsRecordedAndLeavesNoFolder) {
  TempDir dir;
  fs::create_directories(dir / "scans");
  Simulate(dir / "scans" / "a_long.h5", 1, 55.0, "", "--sample-period-s 4e-5");
  Simulate(dir / "scans" / "b_short.h5", 2, 56.0);
  const std::string command = "batch " + (dir / "scans").string() + " -o " + (dir / "out").string();
  // The batch runs in the background of a shell; this test kills its first child.
  ASSERT_EQ(
      testing::Shell("(" + std::string(std::getenv("ARCWHEEL_BINARY")) + " " + command + " > " +
                     (dir / "batch.txt").string() + " 2>&1; echo $? > " + (dir / "status").string() + ") &"),
      0);
  pid_t child = 0;
  for (int i = 0; i < 1000 && child == 0; ++i) {
    child = ProcessChildOf(dir / "scans" / "a_long.h5");
    if (child == 0) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_NE(child, 0) << "the first child did not start within 10 s";
  ::kill(child, SIGKILL);
  for (int i = 0; i < 3000 && !fs::exists(dir / "status"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(fs::exists(dir / "status")) << "the batch did not end within 30 s";
  EXPECT_EQ(ReadText(dir / "status"), "6\n") << ReadText(dir / "batch.txt");
  const json index = ReadJson(dir / "out" / "index.json");
  const json& killed = index["scans"][0];
  EXPECT_EQ(killed["status"], "failed");
  EXPECT_EQ(killed["exit_code"], 128 + SIGKILL);
  EXPECT_THAT(killed["message"].get<std::string>(), HasSubstr("killed by signal 9"));
  EXPECT_FALSE(fs::exists(dir / "out" / "a_long"));
  EXPECT_EQ(index["scans"][1]["status"], "done");
  EXPECT_EQ(testing::ListFolder(dir / "out" / "b_short"), "step_inputs.json\nsummary.json\nwheel_map.h5\n");
}

// SIGINT to the batch while its children run: they are stopped, no partial result folder is left,
// the index lists what finished, the exit status is 130; the next run finishes the rest.
TEST(Batch, AnInterruptedBatchLeavesNoPartialResultAndTheNextRunFinishes) {
  TempDir dir;
  fs::create_directories(dir / "scans");
  // 1.3e6 samples: about 0.2 s each to process in the Release build, where this case runs.
  for (int i = 0; i < 4; ++i) {
    Simulate(dir / "scans" / ("long_" + std::to_string(i) + ".h5"), 10 + i, 55.0, "",
             "--sample-period-s 1e-5");
  }
  const pid_t pid = testing::SpawnArcwheel(
      {"batch", (dir / "scans").string(), "-o", (dir / "out").string(), "-j", "2"}, dir / "stderr.txt");
  // The first child's log appears when it starts.
  for (int i = 0; i < 1000 && !fs::exists(dir / "out" / "logs" / "long_0.log"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  EXPECT_TRUE(fs::exists(dir / "out" / "logs" / "long_0.log")) << "no child started within 10 s";
  std::this_thread::sleep_for(std::chrono::milliseconds(30));
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status)) << ReadText(dir / "stderr.txt");
  EXPECT_EQ(WEXITSTATUS(status), 130) << ReadText(dir / "stderr.txt");

  ASSERT_TRUE(fs::exists(dir / "out" / "index.json"));
  const json index = ReadJson(dir / "out" / "index.json");
  ASSERT_EQ(index["scans"].size(), 4u);
  EXPECT_GE(index["counts"].value("interrupted", 0), 1) << index.dump(2);
  size_t finished = 0;
  for (const json& row : index["scans"]) {
    const fs::path folder = row["result"].get<std::string>();
    if (row["status"] == "done") {
      ++finished;
      EXPECT_EQ(testing::ListFolder(folder), "step_inputs.json\nsummary.json\nwheel_map.h5\n");
    } else {
      EXPECT_FALSE(fs::exists(folder)) << folder << " is left after " << row["status"];
    }
  }

  const auto next =
      RunArcwheel("batch " + (dir / "scans").string() + " -o " + (dir / "out").string() + " -j 2");
  EXPECT_EQ(next.exit_status, 0) << next.output;
  EXPECT_THAT(next.output, HasSubstr(std::to_string(4 - finished) + " done, " + std::to_string(finished) +
                                     " reused, 0 failed"));
  EXPECT_EQ(ReadJson(dir / "out" / "index.json")["counts"]["done"], 4 - finished);
}

}  // namespace
}  // namespace arcwheel
