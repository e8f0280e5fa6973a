#include "core/parallel.h"

#include <algorithm>
#include <exception>
#include <system_error>
#include <thread>
#include <vector>

namespace arcwheel {

int WorkerCount(int requested) {
  if (requested > 0) return requested;
  return std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
}

void RunOnWorkers(int workers, const std::function<void(int worker)>& work) {
  workers = std::max(1, workers);
  std::vector<std::exception_ptr> errors(static_cast<std::size_t>(workers));
  const auto guarded = [&](int worker) {
    try {
      work(worker);
    } catch (...) {
      errors[static_cast<std::size_t>(worker)] = std::current_exception();
    }
  };
  std::vector<std::thread> pool;
  pool.reserve(static_cast<std::size_t>(workers - 1));
  int started = 1;
  try {
    for (; started < workers; ++started) pool.emplace_back(guarded, started);
  } catch (const std::system_error&) {
    // No thread to be had: the workers that did not get one run here, after worker 0.
  }
  guarded(0);
  for (int worker = started; worker < workers; ++worker) guarded(worker);
  for (std::thread& thread : pool) thread.join();
  for (const std::exception_ptr& error : errors) {
    if (error) std::rethrow_exception(error);
  }
}

namespace {

// Polls of a spin before a worker or the caller goes to sleep: some 0.1 ms.
constexpr int kSpins = 4000;

void Pause() {
#if defined(__x86_64__) || defined(__i386__)
  __builtin_ia32_pause();
#endif
}

}  // namespace

WorkerPool::WorkerPool(int workers) : workers_(WorkerCount(workers)) {
  errors_.resize(static_cast<std::size_t>(workers_));
  threads_.reserve(static_cast<std::size_t>(workers_ - 1));
  try {
    for (int worker = 1; worker < workers_; ++worker) threads_.emplace_back(&WorkerPool::Serve, this, worker);
  } catch (const std::system_error&) {
    // No thread to be had: the workers without one run on the caller (Run).
  }
}

WorkerPool::~WorkerPool() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  start_.notify_all();
  for (std::thread& thread : threads_) thread.join();
}

void WorkerPool::Serve(int worker) {
  std::uint64_t seen = 0;
  for (;;) {
    for (int spin = 0; spin < kSpins && run_.load(std::memory_order_acquire) == seen && !stop_; ++spin)
      Pause();
    const std::function<void(int)>* work = nullptr;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      start_.wait(lock, [&] { return stop_ || run_ != seen; });
      if (stop_) return;
      seen = run_;
      work = work_;
    }
    try {
      (*work)(worker);
    } catch (...) {
      errors_[static_cast<std::size_t>(worker)] = std::current_exception();
    }
    if (pending_.fetch_sub(1, std::memory_order_acq_rel) == 1) {
      const std::lock_guard<std::mutex> lock(mutex_);  // the caller waits under it: no lost wake-up
      done_.notify_one();
    }
  }
}

void WorkerPool::Run(const std::function<void(int worker)>& work) {
  std::fill(errors_.begin(), errors_.end(), nullptr);
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    work_ = &work;
    pending_ = static_cast<int>(threads_.size());
    ++run_;
  }
  start_.notify_all();
  const auto guarded = [&](int worker) {
    try {
      work(worker);
    } catch (...) {
      errors_[static_cast<std::size_t>(worker)] = std::current_exception();
    }
  };
  guarded(0);
  for (int worker = static_cast<int>(threads_.size()) + 1; worker < workers_; ++worker) guarded(worker);
  for (int spin = 0; spin < kSpins && pending_.load(std::memory_order_acquire) > 0; ++spin) Pause();
  {
    std::unique_lock<std::mutex> lock(mutex_);
    done_.wait(lock, [&] { return pending_.load(std::memory_order_acquire) == 0; });
    work_ = nullptr;
  }
  for (const std::exception_ptr& error : errors_) {
    if (error) std::rethrow_exception(error);
  }
}

}  // namespace arcwheel
