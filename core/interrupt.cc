#include "core/interrupt.h"

#include <pthread.h>

#include <csignal>
#include <cstdlib>

#include "core/error.h"

namespace arcwheel {
namespace {

volatile std::sig_atomic_t g_interrupted = 0;

// The first signal asks the run to unwind at its next check, so that nothing partial is left. A
// second one stops at once: a run stuck where it never checks (inside a library) can still be
// ended; at that point only temporary files can be left, never a damaged output.
extern "C" void OnSignal(int /*signal*/) {
  if (g_interrupted != 0) std::_Exit(130);
  g_interrupted = 1;
}

}  // namespace

void InstallInterruptHandlers() {
  std::signal(SIGINT, OnSignal);
  std::signal(SIGTERM, OnSignal);
  // A parent may have started us with the signals blocked; from here on they are handled.
  sigset_t handled;
  sigemptyset(&handled);
  sigaddset(&handled, SIGINT);
  sigaddset(&handled, SIGTERM);
  pthread_sigmask(SIG_UNBLOCK, &handled, nullptr);
}

bool InterruptRequested() noexcept { return g_interrupted != 0; }

void RequestInterrupt() noexcept { g_interrupted = 1; }

void ClearInterruptRequest() noexcept { g_interrupted = 0; }

void ThrowIfInterrupted() {
  if (g_interrupted != 0) throw Error(ErrorCode::kInterrupted, "arcwheel", "interrupted by a signal");
}

}  // namespace arcwheel
