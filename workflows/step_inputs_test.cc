// The record of a step's inputs, and when it says a result can be reused.

#include "workflows/step_inputs.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <nlohmann/json.hpp>

#include "core/testing/testing.h"
#include "core/version.h"

namespace arcwheel::workflows {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::TempDir;
using testing::WriteText;

// FIPS 180-2, appendix B.1: SHA-256("abc").
constexpr const char* kSha256OfAbc = "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad";

TEST(StepInputs, RecordsTheVersionTheOptionsAndEachFilesSha256) {
  TempDir dir;
  WriteText(dir / "scan.csv", "abc");
  const json inputs = StepInputs({{"scan", dir / "scan.csv"}}, {{"phases", 360}});
  EXPECT_EQ(inputs.at("arcwheel_version"), kVersion);
  EXPECT_EQ(inputs.at("options"), json({{"phases", 360}}));
  EXPECT_EQ(inputs.at("sha256").at("scan"), kSha256OfAbc);
  EXPECT_EQ(inputs.at("paths").at("scan"), fs::absolute(dir / "scan.csv").string());
}

TEST(StepInputs, AnUnreadableFileIsAnIoError) {
  TempDir dir;
  const Error error = testing::ErrorOf([&] {
    (void)StepInputs({{"scan", dir / "missing.h5"}}, json::object());
  });
  EXPECT_EQ(error.code(), ErrorCode::kIo);
}

class UpToDateResult : public ::testing::Test {
 protected:
  void SetUp() override {
    WriteText(dir_ / "scan.csv", "abc");
    fs::create_directory(dir_ / "result");
    WriteText(dir_ / "result/summary.json", "{}");
    WriteText(dir_ / "result" / kStepInputsFileName, Inputs().dump());
  }
  [[nodiscard]] json Inputs(const std::string& file = "scan.csv", int phases = 360) const {
    return StepInputs({{"scan", dir_ / file}}, {{"phases", phases}});
  }
  TempDir dir_;
};

TEST_F(UpToDateResult, WhenEveryOutputIsThereAndTheInputsAreEqual) {
  EXPECT_TRUE(UpToDate(dir_ / "result", {"summary.json"}, Inputs()));
}

TEST_F(UpToDateResult, NotWhenAnInputFileChanged) {
  WriteText(dir_ / "scan.csv", "abd");
  EXPECT_FALSE(UpToDate(dir_ / "result", {"summary.json"}, Inputs()));
}

TEST_F(UpToDateResult, StillWhenTheSameFileWasMoved) {
  fs::rename(dir_ / "scan.csv", dir_ / "moved.csv");
  EXPECT_TRUE(UpToDate(dir_ / "result", {"summary.json"}, Inputs("moved.csv")));
}

TEST_F(UpToDateResult, NotWhenAnOptionOrTheVersionDiffers) {
  EXPECT_FALSE(UpToDate(dir_ / "result", {"summary.json"}, Inputs("scan.csv", 180)));
  json other_version = Inputs();
  other_version["arcwheel_version"] = "0.0.1";
  EXPECT_FALSE(UpToDate(dir_ / "result", {"summary.json"}, other_version));
}

TEST_F(UpToDateResult, NotWhenAnOutputOrTheRecordIsMissingOrUnreadable) {
  EXPECT_FALSE(UpToDate(dir_ / "result", {"summary.json", "wheel_map.h5"}, Inputs()));
  WriteText(dir_ / "result" / kStepInputsFileName, "{ not json");
  EXPECT_FALSE(UpToDate(dir_ / "result", {"summary.json"}, Inputs()));
  fs::remove(dir_ / "result" / kStepInputsFileName);
  EXPECT_FALSE(UpToDate(dir_ / "result", {"summary.json"}, Inputs()));
}

}  // namespace
}  // namespace arcwheel::workflows
