#include "cli/output.h"

#include <fmt/core.h>
#include <unistd.h>

#include "core/atomic_file.h"

namespace arcwheel::cli {

void EmitText(const std::string& text, const std::string& output) {
  if (output.empty()) {
    fmt::print("{}", text);
  } else {
    WriteFileAtomically(output, text);
  }
}

void SummariseOnTerminal(const std::string& text) {
  if (::isatty(STDERR_FILENO)) fmt::print(stderr, "{}", text);
}

}  // namespace arcwheel::cli
