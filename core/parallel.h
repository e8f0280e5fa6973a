#pragma once
// The one way arcwheel splits work across threads: a fixed number of workers, worker 0 on the
// calling thread, each taking its share by index (worker, worker + workers, ...).

#include <functional>

namespace arcwheel {

// `requested` when > 0, else the number of hardware threads (at least 1).
[[nodiscard]] int WorkerCount(int requested);

// Calls work(w) for w = 0 .. workers - 1, w = 0 on the calling thread and the others on threads of
// their own, and returns when all have finished. An exception thrown by a worker is rethrown then
// (the lowest worker's, when several threw), so no thread outlives a failure.
void RunOnWorkers(int workers, const std::function<void(int worker)>& work);

}  // namespace arcwheel
