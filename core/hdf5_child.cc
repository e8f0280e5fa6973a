#include <fmt/format.h>
#include <signal.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <optional>
#include <string>
#include <system_error>
#include <thread>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/interrupt.h"

namespace arcwheel::hdf5 {
namespace {

constexpr const char* kStage = "hdf5";

bool g_in_child = false;

double DefaultTimeoutS(const std::filesystem::path& path) {
  std::error_code error;
  const auto bytes = std::filesystem::file_size(path, error);
  return 60.0 + (error ? 0.0 : static_cast<double>(bytes) / 10e6);
}

// Waits for `child`; its wait status, or nothing once `timeout_s` has passed or a signal asks us
// to stop (the child is then killed and reaped).
std::optional<int> WaitFor(pid_t child, double timeout_s) {
  const auto start = std::chrono::steady_clock::now();
  auto pause = std::chrono::microseconds(200);
  for (;;) {
    int status = 0;
    const pid_t done = waitpid(child, &status, WNOHANG);
    if (done == child) return status;
    if (done < 0 && errno != EINTR) return 0;  // reaped elsewhere: nothing to report
    const std::chrono::duration<double> waited = std::chrono::steady_clock::now() - start;
    if (InterruptRequested() || waited.count() > timeout_s) {
      kill(child, SIGKILL);
      while (waitpid(child, &status, 0) < 0 && errno == EINTR) {
      }
      return std::nullopt;
    }
    std::this_thread::sleep_for(pause);
    pause = std::min(pause * 2, std::chrono::microseconds(20000));
  }
}

}  // namespace

void ReadFirstInChildProcess(const std::filesystem::path& path, const std::function<void()>& read,
                             double timeout_s) {
  if (g_in_child) return;
  if (timeout_s <= 0.0) timeout_s = DefaultTimeoutS(path);
  std::fflush(nullptr);  // nothing buffered twice
  const pid_t child = fork();
  if (child < 0) return;  // no child to be had: read here, unguarded, as before
  if (child == 0) {
    g_in_child = true;
    try {
      read();
    } catch (...) {
      // Refused: the parent reads again and gives the reader's own message.
    }
    _exit(0);
  }
  const std::optional<int> status = WaitFor(child, timeout_s);
  ThrowIfInterrupted();
  const std::string name = fmt::format("'{}'", path.string());
  if (!status) {
    throw Error(ErrorCode::kBadInput, kStage,
                fmt::format("{}: libhdf5 had not finished reading it after {:g} s (a damaged file?)", name,
                            timeout_s));
  }
  if (WIFSIGNALED(*status)) {
    const int signal = WTERMSIG(*status);
    throw Error(ErrorCode::kBadInput, kStage,
                name + ": reading it crashed libhdf5 (signal " + std::to_string(signal) + ", " +
                    strsignal(signal) + "); the file is damaged");
  }
  if (!WIFEXITED(*status) || WEXITSTATUS(*status) != 0) {
    throw Error(ErrorCode::kBadInput, kStage,
                name + ": reading it crashed libhdf5 (exit status " +
                    std::to_string(WIFEXITED(*status) ? WEXITSTATUS(*status) : -1) +
                    "); the file is damaged");
  }
}

}  // namespace arcwheel::hdf5
