#pragma once
// A displacement sensor that loses its target, saturates or hangs repeats its last reading. A
// turning wheel never gives that: its readings carry the sensor's noise and the wheel's runout,
// and the helix moves the spot along the arc. So a long run of exactly equal consecutive readings
// is not data; left in, it bends every section it crosses and the fits print a plausible radius
// that is wrong by far more than their sigma (a stuck sensor for two turns of a simulated 0.5 um
// noise scan moved the mean arc radius by 0.7 mm with nothing flagged).

#include <cstddef>
#include <span>

namespace arcwheel::processing {

struct StuckReadingsResult {
  std::size_t min_run = 0;      // the run length (samples) from which readings were dropped
  std::size_t dropped = 0;      // samples set to NaN
  std::size_t runs = 0;         // how many runs
  std::size_t longest_run = 0;  // samples in the longest run dropped
  std::size_t valid = 0;        // valid samples before any was dropped (counted in the same pass)
};

// Sets to NaN every run of `min_run` or more consecutive valid samples with exactly equal values
// (bitwise, as the sensor wrote them); an invalid sample ends a run. `min_run` < 2 drops nothing.
// Two workers take the two halves of the scan, split where a run starts.
StuckReadingsResult DropStuckReadings(std::span<double> z_mm, std::size_t min_run);
StuckReadingsResult DropStuckReadings(std::span<float> z_mm, std::size_t min_run);

}  // namespace arcwheel::processing
