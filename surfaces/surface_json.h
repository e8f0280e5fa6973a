#pragma once
// The "surface" and "aperture" sections of a job file, read the same way by the grinding and the
// polishing job (docs/grinding.md and docs/polishing.md describe the keys).

#include <memory>
#include <string>
#include <vector>

#include "core/json_job.h"
#include "surfaces/surface.h"

namespace arcwheel::surfaces {

// Reads a surface of one of `types` ("even_asphere", "xy_polynomial", "height_grid"; the first is
// the default). Throws Error{kBadInput} (the section's stage) naming the key and the value.
[[nodiscard]] std::shared_ptr<const Surface> ReadSurface(JsonSection& section,
                                                         const std::vector<std::string>& types);

// Reads an aperture. `shape` ("circle" or "rectangle") may be left out: `diameter_mm` makes a
// circle and `size_mm` ([x, y]) a rectangle. Neither or both of those keys is refused, and so is a
// `shape` that contradicts them. The sizes must be > 0.
[[nodiscard]] Aperture ReadAperture(JsonSection& section);

}  // namespace arcwheel::surfaces
