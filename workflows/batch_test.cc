// The batch workflow as library code: which scans a batch plans, and how it schedules, records
// and resumes them. The scans run through a stand-in for `arcwheel process` (a shell script that
// writes the two result files), so that what is tested is the scheduling, not the processing; the
// real binary is run end to end by tests/batch_test.cc.

#include "workflows/batch.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/testing/testing.h"
#include "workflows/batch_internal.h"

namespace arcwheel::workflows {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ErrorMessageOf;
using ::testing::HasSubstr;
using testing::ReadText;
using testing::TempDir;
using testing::WriteText;

std::vector<std::string> Names(const std::vector<batch::Scan>& scans) {
  std::vector<std::string> names;
  for (const batch::Scan& scan : scans) names.push_back(scan.name);
  return names;
}

TEST(BatchPlan, TakesAFoldersScansInOrderAndEachFileOnce) {
  TempDir dir;
  // Every extension `process` reads, in any case (a CSV scan may end in .txt); other files are not scans.
  for (const char* name : {"b.h5", "a.csv", "c.HDF5", "d.TXT", "notes.md"}) WriteText(dir / name, "x");
  const std::vector<batch::Scan> scans =
      batch::PlanScans({dir.path().string(), (dir / "a.csv").string(), (dir / "b.h5").string()});
  EXPECT_THAT(Names(scans), ::testing::ElementsAre("a", "b", "c", "d"));
}

TEST(BatchPlan, ReadsAListFileWithCommentsAndPathsRelativeToIt) {
  TempDir dir;
  fs::create_directory(dir / "scans");
  WriteText(dir / "scans/w1.h5", "x");
  WriteText(dir / "scans/w2.h5", "x");
  WriteText(dir / "scans/list.txt", "# dressing 7\nw2.h5\n\n" + (dir / "scans/w1.h5").string() + "  \n");
  EXPECT_THAT(Names(batch::PlanScans({"@" + (dir / "scans/list.txt").string()})),
              ::testing::ElementsAre("w2", "w1"));
  WriteText(dir / "scans/bad.txt", "w1.h5\nw9.h5\n");
  EXPECT_THAT(ErrorMessageOf([&] { (void)batch::PlanScans({"@" + (dir / "scans/bad.txt").string()}); }),
              HasSubstr("line 2: 'w9.h5' is not a file"));
}

TEST(BatchPlan, RefusesTwoScansOfOneNameNamingBoth) {
  TempDir dir;
  fs::create_directories(dir / "x");
  fs::create_directories(dir / "y");
  WriteText(dir / "x/w.h5", "1");
  WriteText(dir / "y/w.csv", "2");
  const std::string message = ErrorMessageOf(
      [&] {
        (void)batch::PlanScans({(dir / "x/w.h5").string(), (dir / "y/w.csv").string()});
      },
      ErrorCode::kInvalidOption);
  EXPECT_THAT(message, HasSubstr("x/w.h5"));
  EXPECT_THAT(message, HasSubstr("y/w.csv"));
}

// A stand-in for `arcwheel process SCAN -o OUT`: a scan whose text is a number gets a result
// with that number as its mean arc radius; a scan that says "bad" fails with exit status 3.
fs::path WriteFakeArcwheel(const fs::path& dir) {
  const fs::path script = dir / "fake_arcwheel";
  WriteText(script,
            "#!/bin/sh\n"
            "scan=$2; out=$4\n"
            "value=$(cat \"$scan\")\n"
            "if [ \"$value\" = bad ]; then echo 'arcwheel: bad input: not a scan' >&2; exit 3; fi\n"
            "mkdir -p \"$out\"\n"
            "echo \"{\\\"mean_arc_radius_mm\\\": $value}\" > \"$out/summary.json\"\n"
            "echo map > \"$out/wheel_map.h5\"\n"
            "echo \"$scan\" >> \"$(dirname \"$0\")/runs.log\"\n");
  fs::permissions(script, fs::perms::owner_all);
  return script;
}

class BatchRun : public ::testing::Test {
 protected:
  void SetUp() override {
    fs::create_directory(dir_ / "scans");
    WriteText(dir_ / "scans/w1.csv", "55.1");
    WriteText(dir_ / "scans/w2.csv", "55.2");
    options_.inputs = {(dir_ / "scans").string()};
    options_.outdir = (dir_ / "out").string();
    options_.jobs = 2;
    options_.arcwheel_binary = WriteFakeArcwheel(dir_.path());
  }
  [[nodiscard]] int Runs() const {
    const std::string log = ReadText(dir_ / "runs.log");
    return static_cast<int>(std::count(log.begin(), log.end(), '\n'));
  }
  TempDir dir_;
  BatchOptions options_;
};

TEST_F(BatchRun, RunsEveryScanAndIndexesItsHeadlineNumbers) {
  const BatchReport report = RunBatch(options_);
  EXPECT_EQ(report.scans, 2u);
  EXPECT_EQ(report.done, 2u);
  EXPECT_EQ(report.Unfinished(), 0u);
  const json index = json::parse(ReadText(dir_ / "out/index.json"));
  ASSERT_EQ(index.at("scans").size(), 2u);
  EXPECT_EQ(index["scans"][0]["status"], "done");
  EXPECT_DOUBLE_EQ(index["scans"][0]["mean_arc_radius_mm"].get<double>(), 55.1);
  EXPECT_DOUBLE_EQ(index["scans"][1]["mean_arc_radius_mm"].get<double>(), 55.2);
  EXPECT_THAT(ReadText(dir_ / "out/index.csv"), HasSubstr("w2.csv,"));
}

TEST_F(BatchRun, ResumesOnlyWhatChanged) {
  (void)RunBatch(options_);
  ASSERT_EQ(Runs(), 2);
  const BatchReport again = RunBatch(options_);
  EXPECT_EQ(again.reused, 2u);
  EXPECT_EQ(Runs(), 2);
  WriteText(dir_ / "scans/w2.csv", "55.3");
  const BatchReport changed = RunBatch(options_);
  EXPECT_EQ(changed.reused, 1u);
  EXPECT_EQ(changed.done, 1u);
  EXPECT_EQ(Runs(), 3);
  options_.process_options = {"--phases", "180"};  // other options: every scan again
  EXPECT_EQ(RunBatch(options_).done, 2u);
}

TEST_F(BatchRun, RecordsAFailedScanWithItsMessageAndGoesOn) {
  WriteText(dir_ / "scans/w0.csv", "bad");
  const BatchReport report = RunBatch(options_);
  EXPECT_EQ(report.failed, 1u);
  EXPECT_EQ(report.done, 2u);
  const json index = json::parse(ReadText(dir_ / "out/index.json"));
  EXPECT_EQ(index["scans"][0]["status"], "failed");
  EXPECT_EQ(index["scans"][0]["exit_code"], 3);
  EXPECT_THAT(index["scans"][0]["message"].get<std::string>(), HasSubstr("not a scan"));
  EXPECT_FALSE(fs::exists(dir_ / "out/w0"));
}

TEST_F(BatchRun, RefusesBadOptionsBeforeAnyScanRuns) {
  options_.jobs = 0;
  EXPECT_THAT(ErrorMessageOf([&] { (void)RunBatch(options_); }, ErrorCode::kInvalidOption),
              HasSubstr("-j 0 violates >= 1"));
  options_.jobs = 1;
  options_.process_options = {"-o", "elsewhere"};
  EXPECT_THAT(ErrorMessageOf([&] { (void)RunBatch(options_); }, ErrorCode::kInvalidOption),
              HasSubstr("must not set the output folder"));
  options_.process_options = {"--phases", "-1"};
  options_.check_process_options = [](const std::vector<std::string>&, const fs::path&) {
    throw Error(ErrorCode::kInvalidOption, "batch", "the process options after --: --phases -1");
  };
  EXPECT_THAT(ErrorMessageOf([&] { (void)RunBatch(options_); }, ErrorCode::kInvalidOption),
              HasSubstr("--phases -1"));
  EXPECT_EQ(Runs(), 0);
}

}  // namespace
}  // namespace arcwheel::workflows
