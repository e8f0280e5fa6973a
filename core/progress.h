#pragma once
// Progress lines on a terminal (stderr), silent when stderr is not a terminal or when disabled.

#include <string_view>

namespace arcwheel {

class Progress {
 public:
  explicit Progress(bool enabled);
  ~Progress();
  Progress(const Progress&) = delete;
  Progress& operator=(const Progress&) = delete;
  // Shows "step: fraction%" on one refreshed line.
  void Update(std::string_view step, double fraction);
  void Done();

 private:
  bool enabled_;
  bool line_open_ = false;
};

}  // namespace arcwheel
