#pragma once
// Helpers shared by the test binaries: temporary folders, source paths and running the CLI.

#include <filesystem>
#include <functional>
#include <string>

#include "core/error.h"

namespace arcwheel::testing {

// A fresh empty folder, removed with its contents when the object dies.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

// The repository root (ARCWHEEL_SOURCE_DIR, set by CTest; else the working folder).
[[nodiscard]] std::filesystem::path SourceDir();

struct CommandResult {
  int exit_status = -1;
  std::string output;  // stdout and stderr together
};
// Runs the arcwheel binary (ARCWHEEL_BINARY, set by CTest) with `arguments` through the shell.
[[nodiscard]] CommandResult RunArcwheel(const std::string& arguments);

// The message of the Error that `run` throws, checking (as a test failure) that its code is
// `code`; "accepted" if it throws nothing.
[[nodiscard]] std::string ErrorOf(const std::function<void()>& run, ErrorCode code = ErrorCode::kBadInput);

// Names of the entries of a folder, sorted.
[[nodiscard]] std::string ListFolder(const std::filesystem::path& folder);

}  // namespace arcwheel::testing
