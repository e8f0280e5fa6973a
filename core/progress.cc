#include "core/progress.h"

#include <unistd.h>

#include <cstdio>

namespace arcwheel {

Progress::Progress(bool enabled) : enabled_(enabled && ::isatty(STDERR_FILENO) == 1) {}

Progress::~Progress() { Done(); }

void Progress::Update(std::string_view step, double fraction) {
  if (!enabled_) return;
  std::fprintf(stderr, "\r\033[K%.*s %3.0f%%", static_cast<int>(step.size()), step.data(), 100.0 * fraction);
  std::fflush(stderr);
  line_open_ = true;
}

void Progress::Done() {
  if (line_open_) std::fprintf(stderr, "\r\033[K");
  line_open_ = false;
}

}  // namespace arcwheel
