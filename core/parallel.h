#pragma once
// The one way arcwheel splits work across threads: a fixed number of workers, worker 0 on the
// calling thread, each taking its share by index (worker, worker + workers, ...).

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>
#include <vector>

namespace arcwheel {

// `requested` when > 0, else the number of hardware threads (at least 1).
[[nodiscard]] int WorkerCount(int requested);

// Calls work(w) for w = 0 .. workers - 1, w = 0 on the calling thread and the others on threads of
// their own, and returns when all have finished. An exception thrown by a worker is rethrown then
// (the lowest worker's, when several threw), so no thread outlives a failure.
void RunOnWorkers(int workers, const std::function<void(int worker)>& work);

// The same workers kept for many runs: for a loop of passes of a few milliseconds each, where
// starting threads anew (~50 us a thread on a virtual machine) would cost a fair part of a pass.
// Run(work) does what RunOnWorkers(Workers(), work) does; one run at a time. Between runs the
// threads spin briefly (a pass often follows within microseconds), then sleep; the destructor
// joins them.
class WorkerPool {
 public:
  // `workers` when > 0, else the hardware threads (WorkerCount). A worker that gets no thread of
  // its own runs on the calling thread, after worker 0.
  explicit WorkerPool(int workers);
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  [[nodiscard]] int Workers() const { return workers_; }
  void Run(const std::function<void(int worker)>& work);

 private:
  void Serve(int worker);

  int workers_;
  std::vector<std::thread> threads_;  // workers 1 .. threads_.size()
  std::mutex mutex_;
  std::condition_variable start_, done_;
  std::atomic<std::uint64_t> run_{0};  // counts the runs started
  std::atomic<int> pending_{0};        // threads still working on the current run
  std::atomic<bool> stop_{false};
  const std::function<void(int)>* work_ = nullptr;
  std::vector<std::exception_ptr> errors_;
};

}  // namespace arcwheel
