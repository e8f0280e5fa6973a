#pragma once
// Errors and exit codes shared by every stage.
//
// Three tiers, never mixed (see ARCHITECTURE.md):
//  1. bad data, I/O or options: throw Error with the stage id as prefix and the offending value;
//  2. our own bugs: ARCWHEEL_CHECK (core/check.h) throws ErrorCode::kInternal;
//  3. numerical outcomes (a fit that did not converge) are data in the stage's result struct.
// Only cli/ catches, mapping code() to the process exit status below.

#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace arcwheel {

enum class ErrorCode {
  kInvalidOption,  // a command-line option or option struct field is out of range
  kBadInput,       // an input file is malformed or cannot support the requested computation
  kIo,             // a file cannot be opened, read, written or renamed
  kFitFailed,      // no usable result could be computed from otherwise valid input
  kInterrupted,    // SIGINT / SIGTERM arrived while working
  kInternal,       // a broken invariant: a bug in arcwheel
};

// Process exit status for each code; documented in `arcwheel help` and the README.
[[nodiscard]] int ExitStatus(ErrorCode code) noexcept;
[[nodiscard]] std::string_view ErrorCodeName(ErrorCode code) noexcept;

class Error : public std::runtime_error {
 public:
  Error(ErrorCode code, std::string_view stage, const std::string& detail)
      : std::runtime_error(std::string(stage) + ": " + detail), code_(code), stage_(stage) {}
  [[nodiscard]] ErrorCode code() const noexcept { return code_; }
  // The stage id that prefixes what(), e.g. "acquisition.validate".
  [[nodiscard]] const std::string& stage() const noexcept { return stage_; }

 private:
  ErrorCode code_;
  std::string stage_;
};

// Every problem of an options struct's Problems(), in the order found, on one line:
// "a = -1 violates > 0; b = 7 violates <= 5".
[[nodiscard]] std::string JoinProblems(const std::vector<std::string>& problems);

// Throws one Error{code, stage} listing every problem (JoinProblems), if there are any, so that a
// user fixes them all in one go rather than one per run.
void ThrowIfProblems(ErrorCode code, std::string_view stage, const std::vector<std::string>& problems);

}  // namespace arcwheel
