#pragma once
// Wall time per stage of a run, and the process's peak memory when it ended (`arcwheel process
// --timings`): where the next slowdown or the next copy of the samples is.

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
  }
  // Ends the stage that is running, if any.
  void Stop() {
    if (running_.empty()) return;
    const std::chrono::duration<double> took = std::chrono::steady_clock::now() - started_;
    rusage usage{};
    getrusage(RUSAGE_SELF, &usage);
    stages_.push_back({std::move(running_), took.count(), static_cast<double>(usage.ru_maxrss) / 1024.0});
    running_.clear();
  }
  struct Stage {
    std::string name;
    double seconds = 0.0;
    double peak_memory_mib = 0.0;  // of this process (not its children) when the stage ended
  };
  // Stages in the order they ran.
  [[nodiscard]] const std::vector<Stage>& stages() const { return stages_; }
  void Append(const StageClock& other) {
    stages_.insert(stages_.end(), other.stages_.begin(), other.stages_.end());
  }

 private:
  std::string running_;
  std::chrono::steady_clock::time_point started_;
  std::vector<Stage> stages_;
};

}  // namespace arcwheel
