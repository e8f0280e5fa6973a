// Faults that must lose nothing: a signal in the middle of processing, and a write that fails part
// way (the file-size limit stands in for a full disk). Earlier outputs stay intact and no partial
// or temporary file is left.

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <thread>

#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using testing::ReadText;
using testing::RunArcwheel;
using testing::TempDir;

// A scan of the paper's settings and a finished run of it in `out`.
void PrepareEarlierOutputs(const TempDir& dir) {
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "short.h5").string() + " --noise-um 0.3").exit_status, 0);
  ASSERT_EQ(
      RunArcwheel("process -q " + (dir / "short.h5").string() + " -o " + (dir / "out").string()).exit_status,
      0);
}

// Runs arcwheel with `arguments` under a file-size limit of `limit_kib`, with SIGXFSZ ignored so
// that a write beyond it fails with EFBIG, as on a full disk.
testing::CommandResult RunWithFileSizeLimit(const std::string& arguments, int limit_kib) {
  const std::string command = "bash -c 'trap \"\" XFSZ; ulimit -f " + std::to_string(limit_kib) +
                              "; exec \"" + std::string(std::getenv("ARCWHEEL_BINARY")) + "\" " + arguments +
                              "' 2>&1";
  testing::CommandResult result;
  FILE* pipe = ::popen(command.c_str(), "r");
  if (pipe == nullptr) return result;
  char buffer[512];
  while (std::fgets(buffer, sizeof buffer, pipe) != nullptr) result.output += buffer;
  const int status = ::pclose(pipe);
  result.exit_status = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  return result;
}

// The CPU seconds the running process `pid` has used (all its threads), from /proc; nothing once
// it has ended.
std::optional<double> CpuSecondsOf(pid_t pid) {
  std::ifstream in(fmt::format("/proc/{}/stat", pid));
  std::string stat;
  std::getline(in, stat);
  const std::size_t name_end = stat.rfind(')');
  if (name_end == std::string::npos) return std::nullopt;
  std::istringstream fields(stat.substr(name_end + 2));
  std::string state;
  fields >> state;
  if (state == "Z" || state == "X") return std::nullopt;
  std::string skipped;
  for (int field = 4; field < 14; ++field) fields >> skipped;  // ppid .. cmajflt
  long user_ticks = 0, system_ticks = 0;
  fields >> user_ticks >> system_ticks;
  return static_cast<double>(user_ticks + system_ticks) / static_cast<double>(::sysconf(_SC_CLK_TCK));
}

TEST(Faults, InterruptDuringProcessingLeavesEarlierOutputsIntact) {
  TempDir dir;
  PrepareEarlierOutputs(dir);
  // 4e6 samples: about 0.2 s of CPU in the Release build, several times that with sanitizers.
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "long.h5").string() +
                        " --sample-period-s 1e-5 --feed-mm-per-min 33 --noise-um 0.3 --radial-harmonic 1:3")
                .exit_status,
            0);
  const std::string summary_before = ReadText(dir / "out" / "summary.json");
  const std::string map_before = ReadText(dir / "out" / "wheel_map.h5");

  const pid_t pid =
      testing::SpawnArcwheel({"process", "-q", (dir / "long.h5").string(), "-o", (dir / "out").string()});
  // Interrupted once it has spent 50 ms of CPU, past start-up and into the processing: measured in
  // CPU rather than wall time, so that neither a faster build nor a loaded machine moves the moment.
  std::optional<double> cpu_s;
  while ((cpu_s = CpuSecondsOf(pid)) && *cpu_s < 0.05)
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  EXPECT_TRUE(cpu_s.has_value()) << "the run ended before it had spent 50 ms of CPU";
  ::kill(pid, SIGINT);
  int status = 0;
  ASSERT_EQ(::waitpid(pid, &status, 0), pid);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 130) << "the run should have been interrupted, not finished";
  EXPECT_EQ(testing::ListFolder(dir / "out"), "summary.json\nwheel_map.h5\n");
  EXPECT_EQ(ReadText(dir / "out" / "summary.json"), summary_before);
  EXPECT_EQ(ReadText(dir / "out" / "wheel_map.h5"), map_before);
}

TEST(Faults, WriteFailingPartWayLeavesEarlierOutputsIntact) {
  TempDir dir;
  PrepareEarlierOutputs(dir);
  const std::string summary_before = ReadText(dir / "out" / "summary.json");
  // A 512 KiB limit: the summary fits, the new map (~0.9 MB) does not.
  const auto run = RunWithFileSizeLimit(
      "process -q " + (dir / "short.h5").string() + " -o " + (dir / "out").string(), 512);
  EXPECT_EQ(run.exit_status, 4) << run.output;
  EXPECT_NE(run.output.find("wheel_map.h5"), std::string::npos) << run.output;
  EXPECT_EQ(testing::ListFolder(dir / "out"), "summary.json\nwheel_map.h5\n");
  EXPECT_EQ(ReadText(dir / "out" / "summary.json"), summary_before);
}

// Every stage that writes several files commits them together: a full disk part way through the
// second run leaves the first run's files exactly as they were, and no new file.
struct StageRun {
  const char* name;
  const char* arguments;    // with {src} for the source folder and {out} for the output folder
  int file_size_limit_kib;  // above the smallest output, below the largest
};

class StageOutputs : public ::testing::TestWithParam<StageRun> {};

std::map<std::string, std::string> FolderContents(const std::filesystem::path& folder) {
  std::map<std::string, std::string> contents;
  for (const auto& entry : std::filesystem::directory_iterator(folder)) {
    contents[entry.path().filename().string()] = ReadText(entry.path());
  }
  return contents;
}

TEST_P(StageOutputs, AFullDiskLeavesTheEarlierRunIntact) {
  const StageRun& run = GetParam();
  TempDir dir;
  const std::string arguments =
      fmt::format(fmt::runtime(run.arguments), fmt::arg("src", testing::SourceDir().string()),
                  fmt::arg("out", (dir / "out").string()));
  ASSERT_EQ(RunArcwheel(arguments).exit_status, 0) << arguments;
  const auto before = FolderContents(dir / "out");
  ASSERT_GE(before.size(), 2U);

  const auto second = RunWithFileSizeLimit(arguments, run.file_size_limit_kib);
  EXPECT_EQ(second.exit_status, 4) << second.output;
  EXPECT_EQ(FolderContents(dir / "out"), before) << second.output;
}

INSTANTIATE_TEST_SUITE_P(
    EveryWritingStage, StageOutputs,
    ::testing::Values(StageRun{"Toolpath", "toolpath {src}/grinding/examples/trial_part.json -o {out}", 1024},
                      StageRun{"Polish",
                               "polish {src}/polishing/examples/disc_job.json -o {out} --report pdf", 100}),
    [](const ::testing::TestParamInfo<StageRun>& test) { return std::string(test.param.name); });

}  // namespace
}  // namespace arcwheel
