#pragma once
// FFTW's planner, and the thread count it gives the plans it makes (fftw_plan_with_nthreads), are
// process-wide state that only one thread at a time may touch: every source that makes or
// destroys a plan does so under this one lock, and states its thread count each time, so that a
// plan never picks up the count some other source set last. Executing a plan needs no lock.
// Header-only (the inline function's static is one object per program), for the libraries that
// link FFTW; not installed.

#include <fftw3.h>

#include <mutex>

namespace arcwheel {

class FftwPlanner {
 public:
  // Holds the planner until destroyed; plans made meanwhile run on `threads` threads (>= 1).
  explicit FftwPlanner(int threads) : lock_(Mutex()) {
    static const bool threads_ready = fftw_init_threads() != 0;
    fftw_plan_with_nthreads(threads_ready && threads > 1 ? threads : 1);
  }
  // Holds the planner to destroy plans.
  FftwPlanner() : lock_(Mutex()) {}

 private:
  static std::mutex& Mutex() {
    static std::mutex mutex;
    return mutex;
  }
  std::lock_guard<std::mutex> lock_;
};

}  // namespace arcwheel
