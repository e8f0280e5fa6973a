#pragma once
// Wall and CPU time per stage of a run, and the process's peak memory when it ended (`arcwheel
// process --timings`): where the next slowdown or the next copy of the samples is, and whether a
// stage kept both cores busy.

#include <sys/resource.h>

#include <chrono>
#include <string>
#include <vector>

namespace arcwheel {

class StageClock {
 public:
  // Ends the stage that is running, if any, and starts `name`.
  void Start(std::string name) {
    Stop();
    running_ = std::move(name);
    started_ = std::chrono::steady_clock::now();
    cpu_started_s_ = Usage().cpu_s;
  }
  // Ends the stage that is running, if any.
  void Stop() {
    if (running_.empty()) return;
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - started_;
    const ProcessUsage usage = Usage();
    stages_.push_back(
        {std::move(running_), took.count(), usage.cpu_s - cpu_started_s_, usage.peak_memory_mib});
    running_.clear();
  }
  struct Stage {
    std::string name;
    double seconds = 0.0;
    double cpu_seconds = 0.0;      // of all this process's threads (not its children)
    double peak_memory_mib = 0.0;  // of this process (not its children) when the stage ended
  };
  // Stages in the order they ran.
  [[nodiscard]] const std::vector<Stage>& stages() const { return stages_; }
  void Append(const StageClock& other) {
    stages_.insert(stages_.end(), other.stages_.begin(), other.stages_.end());
  }

 private:
  struct ProcessUsage {
    double cpu_s = 0.0;
    double peak_memory_mib = 0.0;
  };
  static ProcessUsage Usage() {
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    const auto seconds = [](const timeval& t) {
      return static_cast<double>(t.tv_sec) + 1e-6 * static_cast<double>(t.tv_usec);
    };
    return {seconds(usage.ru_utime) + seconds(usage.ru_stime), static_cast<double>(usage.ru_maxrss) / 1024.0};
  }
  std::string running_;
  std::chrono::steady_clock::time_point started_;
  double cpu_started_s_ = 0.0;
  std::vector<Stage> stages_;
};

}  // namespace arcwheel
