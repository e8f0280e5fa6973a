#pragma once
// Helpers shared by the test binaries: temporary folders, source paths, running the CLI and
// other commands, reading files back and catching the Error a call throws.

#include <gtest/gtest.h>
#include <sys/types.h>

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

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

// Starts the arcwheel binary with `arguments` (no shell) and returns its process id without
// waiting. SIGINT starts blocked, so that a signal sent before the program has installed its
// handler (a loaded machine) waits for it instead of killing it: an interrupt test's outcome then
// does not depend on timing. Its stderr goes to `stderr_path` when one is given.
[[nodiscard]] pid_t SpawnArcwheel(const std::vector<std::string>& arguments,
                                  const std::filesystem::path& stderr_path = {});

// The message of the Error that `run` throws, checking (as a test failure) that its code is
// `code`; "accepted" if it throws nothing.
[[nodiscard]] std::string ErrorMessageOf(const std::function<void()>& run,
                                         ErrorCode code = ErrorCode::kBadInput);

// Names of the entries of a folder, sorted.
[[nodiscard]] std::string ListFolder(const std::filesystem::path& folder);

// The bytes of a file; "" when it cannot be read.
[[nodiscard]] std::string ReadText(const std::filesystem::path& path);

// Writes `text` as the whole of a file; a test failure when it cannot be written.
void WriteText(const std::filesystem::path& path, const std::string& text);

// Runs a shell command, returning its exit status (-1 if it did not exit); output goes where the
// command redirects it.
int Shell(const std::string& command);

// The text of a PDF as poppler's pdftotext gives it (UTF-8); a test failure when pdftotext fails.
[[nodiscard]] std::string PdfText(const std::filesystem::path& pdf);

// Runs `call` and returns the Error it throws; fails the test if it throws nothing.
template <typename Call>
Error ErrorOf(const Call& call) {
  try {
    call();
  } catch (const Error& error) {
    return error;
  }
  ADD_FAILURE() << "no Error thrown";
  return Error(ErrorCode::kInternal, "test", "no error");
}

}  // namespace arcwheel::testing
