#pragma once
// A line-profile scan's frames as the wheel map's per-phase sections (docs/processing.md,
// "Line-profile scans"). Each frame is a whole axial section at one phase; the frames of every
// turn whose phase lies nearest a phase node are averaged column by column, and each column's mean
// is placed in the wheel's section plane by the sensor's calibrated tilt and offset
// (acquisition::ProfilePlacement). The result is the WheelMap the helical path's section fits take
// (fitting::FitWheel): everything downstream of the sections is the same for both kinds of scan.

#include <cstddef>

#include "acquisition/profile_scan.h"
#include "processing/wheel_map.h"

namespace arcwheel::processing {

struct ProfileSectionsResult {
  WheelMap map;
  std::size_t valid_points = 0;
  // The readings' noise: the pooled spread of a column's readings over the frames a phase node
  // averages (mm). It holds the wheel's texture between their phases too, so it bounds the noise.
  double point_spread_mm = 0.0;
  int min_frames_per_phase = 0;  // the fewest frames a phase node averaged
};

// options.phases phase nodes; map nodes every options.axial_step_mm (<= 0: 0.1 mm) over the axial
// span that every section covers. Each section point's sigma is point_spread_mm over the square
// root of its frames (fitting/profile_fit.h replaces it by the residuals' own). Throws
// Error{kBadInput, "processing.profile"} naming the file when a phase node has no frame or the
// sections share no axial span.
[[nodiscard]] ProfileSectionsResult BuildProfileSections(const acquisition::ProfileScan& scan,
                                                         const MapOptions& options);

}  // namespace arcwheel::processing
