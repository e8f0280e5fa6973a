#include "processing/stuck_readings.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/nan.h"
#include "core/parallel.h"

namespace arcwheel::processing {

namespace {

// Readings checked at once for the common case, each valid and unlike the next.
constexpr std::size_t kAtOnce = 64;

// True when every one of z[0, kAtOnce) is valid and differs from the reading after it: each is
// then a run of one. Branch-free, so that GCC vectorises it.
template <typename T>
bool AllRunsOfOne(const T* z) {
  int stuck_or_invalid = 0;
  for (std::size_t k = 0; k < kAtOnce; ++k) {
    stuck_or_invalid |= static_cast<int>(!(FiniteWithoutBranch(z[k]) & (z[k] != z[k + 1])));
  }
  return stuck_or_invalid == 0;
}

// The run that starts at `begin` (< end), added to `result` (and dropped when stuck); where the
// next one starts.
template <typename T>
std::size_t TakeRun(std::span<T> z_mm, std::size_t begin, std::size_t end, std::size_t min_run,
                    StuckReadingsResult& result) {
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
  return next;
}

// The runs of z_mm[begin, end), which starts a run: kAtOnce readings at a time where each is a
// run of one, else run by run to the end of those readings.
template <typename T>
StuckReadingsResult DropStuckIn(std::span<T> z_mm, std::size_t begin, std::size_t end, std::size_t min_run) {
  StuckReadingsResult result;
  while (begin < end) {
    if (end - begin > kAtOnce && AllRunsOfOne(z_mm.data() + begin)) {
      result.valid += kAtOnce;
      begin += kAtOnce;
      continue;
    }
    const std::size_t checked_to = std::min(end, begin + kAtOnce);
    while (begin < checked_to) begin = TakeRun(z_mm, begin, end, min_run, result);
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
