#include <fmt/core.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>

#include "core/number_format.h"
#include "workflows/batch_internal.h"

namespace arcwheel::workflows::batch {

namespace {

std::string Duration(double seconds) {
  const long s = std::lround(seconds);
  if (s >= 3600) return fmt::format("{}h{:02}m", s / 3600, (s % 3600) / 60);
  if (s >= 60) return fmt::format("{}m{:02}s", s / 60, s % 60);
  return fmt::format("{}s", s);
}

}  // namespace

BatchProgress::BatchProgress(size_t total) : total_(total), terminal_(::isatty(STDERR_FILENO) == 1) {}
BatchProgress::~BatchProgress() { ClearLine(); }

void BatchProgress::Report(const Scan& scan, const Outcome& outcome) {
  ++finished_;
  if (outcome.status == Status::kDone || outcome.status == Status::kFailed) ++ran_;
  if (outcome.status == Status::kFailed) ++failed_;
  std::string line;
  switch (outcome.status) {
    case Status::kDone:
      line = fmt::format("done {} in {:.1f} s", scan.name, Shown(outcome.seconds));
      break;
    case Status::kReused:
      line = fmt::format("reused {}: finished earlier with the same input and options", scan.name);
      break;
    case Status::kFailed:
      line = fmt::format("FAILED {} ({}, exit status {}): {}", scan.name, scan.path.string(),
                         outcome.exit_code ? std::to_string(*outcome.exit_code) : "none", outcome.message);
      break;
    case Status::kInterrupted:
      line = fmt::format("interrupted {}", scan.name);
      break;
    case Status::kNotRun:
      break;
  }
  if (terminal_ && outcome.status != Status::kFailed) {
    Refresh();
    return;
  }
  ClearLine();
  fmt::print(stderr, "batch: [{}/{}] {}\n", finished_, total_, line);
  Refresh();
}

void BatchProgress::Refresh() {
  if (!terminal_) return;
  const double elapsed_s = std::chrono::duration<double>(Clock::now() - start_).count();
  std::string rate = "";
  if (ran_ > 0 && elapsed_s > 0) {
    const double per_s = static_cast<double>(ran_) / elapsed_s;
    rate = fmt::format(", {:.2f} scans/s, about {} left", Shown(per_s),
                       Duration(static_cast<double>(total_ - finished_) / per_s));
  }
  const int width = 24;
  const int filled = total_ == 0 ? width : static_cast<int>(width * finished_ / total_);
  fmt::print(stderr, "\r\033[Kbatch [{}{}] {}/{} scans, {} failed{}", std::string(filled, '#'),
             std::string(width - filled, '.'), finished_, total_, failed_, rate);
  std::fflush(stderr);
  line_open_ = true;
}

void BatchProgress::ClearLine() {
  if (line_open_) fmt::print(stderr, "\r\033[K");
  line_open_ = false;
}

}  // namespace arcwheel::workflows::batch
