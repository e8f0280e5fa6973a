#include "core/parallel.h"

#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

namespace arcwheel {
namespace {

TEST(WorkerCount, TakesTheRequestedCountOrTheHardwareThreads) {
  EXPECT_EQ(WorkerCount(3), 3);
  EXPECT_EQ(WorkerCount(0), std::max(1, static_cast<int>(std::thread::hardware_concurrency())));
  EXPECT_GE(WorkerCount(-2), 1);
}

TEST(RunOnWorkers, GivesEveryIndexToExactlyOneWorkerAndWorkerZeroToTheCaller) {
  for (const int workers : {1, 2, 5}) {
    std::vector<std::atomic<int>> visits(101);
    std::thread::id worker_zero;
    RunOnWorkers(workers, [&](int worker) {
      if (worker == 0) worker_zero = std::this_thread::get_id();
      for (std::size_t i = static_cast<std::size_t>(worker); i < visits.size();
           i += static_cast<std::size_t>(workers)) {
        ++visits[i];
      }
    });
    for (std::size_t i = 0; i < visits.size(); ++i)
      EXPECT_EQ(visits[i], 1) << workers << " workers, index " << i;
    EXPECT_EQ(worker_zero, std::this_thread::get_id());
  }
}

TEST(RunOnWorkers, RethrowsTheLowestFailingWorkersErrorOnlyAfterEveryWorkerFinished) {
  std::atomic<int> finished{0};
  try {
    RunOnWorkers(4, [&](int worker) {
      if (worker == 1 || worker == 3) throw std::runtime_error("worker " + std::to_string(worker));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++finished;
    });
    FAIL() << "nothing was rethrown";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "worker 1");
  }
  EXPECT_EQ(finished, 2);
}

TEST(WorkerPool, RunsEveryWorkerOncePerRunAndWorkerZeroOnTheCaller) {
  for (const int workers : {1, 2, 5}) {
    WorkerPool pool(workers);
    EXPECT_EQ(pool.Workers(), workers);
    for (int run = 0; run < 50; ++run) {
      std::vector<std::atomic<int>> visits(static_cast<std::size_t>(workers));
      std::thread::id worker_zero;
      pool.Run([&](int worker) {
        if (worker == 0) worker_zero = std::this_thread::get_id();
        ++visits[static_cast<std::size_t>(worker)];
      });
      for (std::size_t w = 0; w < visits.size(); ++w)
        EXPECT_EQ(visits[w], 1) << workers << " workers, run " << run;
      EXPECT_EQ(worker_zero, std::this_thread::get_id());
    }
  }
}

TEST(WorkerPool, RethrowsTheLowestFailingWorkersErrorAfterEveryWorkerFinishedAndRunsAgain) {
  WorkerPool pool(4);
  std::atomic<int> finished{0};
  try {
    pool.Run([&](int worker) {
      if (worker == 1 || worker == 3) throw std::runtime_error("worker " + std::to_string(worker));
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      ++finished;
    });
    FAIL() << "nothing was rethrown";
  } catch (const std::runtime_error& e) {
    EXPECT_STREQ(e.what(), "worker 1");
  }
  EXPECT_EQ(finished, 2);
  std::atomic<int> ran{0};
  pool.Run([&](int) { ++ran; });
  EXPECT_EQ(ran, 4);
}

}  // namespace
}  // namespace arcwheel
