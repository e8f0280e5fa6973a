#include "processing/stuck_readings.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/parallel.h"

namespace arcwheel::processing {

namespace {

// The runs of z_mm[begin, end), which starts a run.
template <typename T>
StuckReadingsResult DropStuckIn(std::span<T> z_mm, std::size_t begin, std::size_t end, std::size_t min_run) {
  StuckReadingsResult result;
  while (begin < end) {
    std::size_t next = begin + 1;
    const bool valid = std::isfinite(z_mm[begin]);
    if (valid) {
      while (next < end && z_mm[next] == z_mm[begin]) ++next;
    }
    const std::size_t length = next - begin;
    if (valid) result.valid += length;
    if (valid && min_run >= 2 && length >= min_run) {
      std::fill(z_mm.begin() + static_cast<std::ptrdiff_t>(begin),
                z_mm.begin() + static_cast<std::ptrdiff_t>(next), std::numeric_limits<T>::quiet_NaN());
      result.dropped += length;
      ++result.runs;
      result.longest_run = std::max(result.longest_run, length);
    }
    begin = next;
  }
  return result;
}

template <typename T>
StuckReadingsResult DropStuck(std::span<T> z_mm, std::size_t min_run) {
  // A run ends where a reading differs from the one before (or either is invalid: NaN equals
  // nothing), so the second half starts at the first such place from the middle on and no run is
  // cut: the runs, and every count, are those of one pass from the start.
  std::size_t split = z_mm.size() / 2;
  while (split > 0 && split < z_mm.size() && z_mm[split] == z_mm[split - 1]) ++split;
  StuckReadingsResult halves[2];
  RunOnWorkers(2, [&](int half) {
    halves[half] =
        half == 0 ? DropStuckIn(z_mm, 0, split, min_run) : DropStuckIn(z_mm, split, z_mm.size(), min_run);
  });
  StuckReadingsResult result;
  result.min_run = min_run;
  result.dropped = halves[0].dropped + halves[1].dropped;
  result.runs = halves[0].runs + halves[1].runs;
  result.longest_run = std::max(halves[0].longest_run, halves[1].longest_run);
  result.valid = halves[0].valid + halves[1].valid;
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
