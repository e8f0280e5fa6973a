#include "core/atomic_file.h"

#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel {
namespace {

std::string Slurp(const std::filesystem::path& path) {
  std::ifstream in(path);
  std::stringstream contents;
  contents << in.rdbuf();
  return contents.str();
}

TEST(OutputSet, LeavesEarlierFileIntactWhenNotCommitted) {
  testing::TempDir dir;
  WriteFileAtomically(dir / "summary.json", "old");
  {
    OutputSet outputs;
    std::ofstream(outputs.Stage(dir / "summary.json")) << "new, but the run fails before commit";
  }
  EXPECT_EQ(Slurp(dir / "summary.json"), "old");
  EXPECT_EQ(testing::ListFolder(dir.path()), "summary.json\n");
}

TEST(OutputSet, RemovesTheFoldersItCreatedWhenNotCommitted) {
  testing::TempDir dir;
  std::filesystem::create_directory(dir / "kept");
  {
    OutputSet outputs;
    outputs.CreateFolder(dir / "kept");
    outputs.CreateFolder(dir / "new" / "deeper");
    ASSERT_TRUE(std::filesystem::is_directory(dir / "new" / "deeper"));
    std::ofstream(outputs.Stage(dir / "new" / "deeper" / "a.txt")) << "the run fails before commit";
  }
  // The folder that was there stays; the two made for the run go with their temporary file.
  EXPECT_EQ(testing::ListFolder(dir.path()), "kept\n");
}

TEST(OutputSet, KeepsTheFoldersItCreatedOnCommit) {
  testing::TempDir dir;
  OutputSet outputs;
  outputs.CreateFolder(dir / "out");
  std::ofstream(outputs.Stage(dir / "out" / "a.txt")) << "A";
  outputs.Commit();
  EXPECT_EQ(Slurp(dir / "out" / "a.txt"), "A");
}

TEST(OutputSet, CommitReplacesEveryStagedFile) {
  testing::TempDir dir;
  OutputSet outputs;
  std::ofstream(outputs.Stage(dir / "a.txt")) << "A";
  std::ofstream(outputs.Stage(dir / "b.txt")) << "B";
  outputs.Commit();
  EXPECT_EQ(Slurp(dir / "a.txt"), "A");
  EXPECT_EQ(Slurp(dir / "b.txt"), "B");
  EXPECT_EQ(testing::ListFolder(dir.path()), "a.txt\nb.txt\n");
}

TEST(WriteFileAtomically, RefusesAnUnwritableFolderWithItsName) {
  try {
    WriteFileAtomically("/nonexistent-folder/summary.json", "x");
    FAIL() << "expected an Error";
  } catch (const Error& error) {
    EXPECT_EQ(error.code(), ErrorCode::kIo);
    EXPECT_NE(std::string(error.what()).find("/nonexistent-folder/summary.json"), std::string::npos);
  }
}

}  // namespace
}  // namespace arcwheel
