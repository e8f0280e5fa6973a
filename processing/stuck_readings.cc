#include "processing/stuck_readings.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace arcwheel::processing {

namespace {

template <typename T>
StuckReadingsResult DropStuck(std::span<T> z_mm, std::size_t min_run) {
  StuckReadingsResult result;
  result.min_run = min_run;
  if (min_run < 2) return result;
  std::size_t begin = 0;
  while (begin < z_mm.size()) {
    std::size_t end = begin + 1;
    if (std::isfinite(z_mm[begin])) {
      while (end < z_mm.size() && z_mm[end] == z_mm[begin]) ++end;
    }
    const std::size_t length = end - begin;
    if (std::isfinite(z_mm[begin]) && length >= min_run) {
      std::fill(z_mm.begin() + static_cast<std::ptrdiff_t>(begin),
                z_mm.begin() + static_cast<std::ptrdiff_t>(end), std::numeric_limits<T>::quiet_NaN());
      result.dropped += length;
      ++result.runs;
      result.longest_run = std::max(result.longest_run, length);
    }
    begin = end;
  }
  return result;
}

}  // namespace

StuckReadingsResult DropStuckReadings(std::span<double> z_mm, std::size_t min_run) {
  return DropStuck(z_mm, min_run);
}

StuckReadingsResult DropStuckReadings(std::span<float> z_mm, std::size_t min_run) {
  return DropStuck(z_mm, min_run);
}

}  // namespace arcwheel::processing
