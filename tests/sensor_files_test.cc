// Scans as the sensors' software writes them (formats.md 2.4): the settings the files lack, given
// from outside (`--scan-settings`), and the refusals, through the binary as a user runs it.

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

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

// A contract CSV of a simulated wheel whose `# key: value` lines lack `drop` (one or more keys).
std::filesystem::path CsvWithout(const TempDir& dir, const std::string& name, const std::string& drop) {
  const std::filesystem::path full = dir / (name + ".full.csv");
  EXPECT_EQ(RunArcwheel("simulate " + full.string() + " --feed-mm-per-min 400").exit_status, 0);
  std::ifstream in(full);
  std::string text, line;
  while (std::getline(in, line)) {
    if (line.starts_with('#') && drop.find(line.substr(2, line.find(':') - 2)) != std::string::npos) continue;
    text += line + "\n";
  }
  const std::filesystem::path path = dir / (name + ".csv");
  WriteText(path, text);
  return path;
}

TEST(ScanSettings, FillWhatTheFileLacksAndTheSummarySaysWhereEachCameFrom) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "spindle_rpm sample_period_s");
  WriteText(dir / "settings.json",
            R"({"spindle_rpm": 500, "sample_period_s": 0.0001, "operator": "E. Abbe"})");
  const auto run = RunArcwheel("process -q --no-model " + scan.string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto s = ReadJson(dir / "out" / "summary.json");
  const auto& input = s["input"];
  EXPECT_EQ(input["scan_settings"], (dir / "settings.json").string());
  EXPECT_EQ(input["sources"]["spindle_rpm"], "settings");
  EXPECT_EQ(input["sources"]["sample_period_s"], "settings");
  EXPECT_EQ(input["sources"]["operator"], "settings");
  EXPECT_EQ(input["sources"]["feed_mm_per_min"], "file");
  EXPECT_EQ(s["scan"]["operator"], "E. Abbe");
  EXPECT_NEAR(s["mean_arc_radius_mm"].get<double>(), 55.4423, 1e-6);  // no noise: the text's 1 nm digits
}

TEST(ScanSettings, AMissingSettingIsNamedWithTheKeyThatSuppliesIt) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "spindle_rpm");
  const auto run = RunArcwheel("process -q " + scan.string() + " -o " + (dir / "out").string());
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_NE(run.output.find("lacks spindle_rpm (and has no angle column): give \"spindle_rpm\" in the file's "
                            "metadata or in --scan-settings"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ScanSettings, AValueThatContradictsTheFileIsRefusedNamingBoth) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "sample_period_s");
  WriteText(dir / "settings.json", R"({"spindle_rpm": 600, "sample_period_s": 0.0001})");
  const auto run = RunArcwheel("process -q " + scan.string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_NE(run.output.find("spindle_rpm contradicts the scan: '" + (dir / "settings.json").string() +
                            "' gives spindle_rpm = 600, '" + scan.string() + "' gives spindle_rpm = 500"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ScanSettings, TheSameValueAsTheFileIsNoContradiction) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "sample_period_s");
  WriteText(dir / "settings.json", R"({"spindle_rpm": 500.0, "sample_period_s": 1e-4})");
  const auto run = RunArcwheel("process -q --no-model " + scan.string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(ReadJson(dir / "out" / "summary.json")["input"]["sources"]["spindle_rpm"], "file");
}

TEST(ScanSettings, AnUnknownKeyOrAWrongTypeIsRefusedBeforeTheScanIsRead) {
  TempDir dir;
  WriteText(dir / "scan.csv", "never read\n");
  WriteText(dir / "settings.json", R"({"spindle_speed": 500, "feed_mm_per_min": "100"})");
  const auto run = RunArcwheel("process -q " + (dir / "scan.csv").string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_NE(run.output.find("'feed_mm_per_min' must be a number, got \"100\""), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("'spindle_speed' is not a scan setting (expected spindle_rpm, "),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace arcwheel
