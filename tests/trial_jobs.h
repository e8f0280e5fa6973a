#pragma once
// The shipped trial part (grinding/examples/trial_part.json, method.md A.9) made small enough for a
// test to run the grinding and polishing chain in seconds, and a polishing job for it.

#include <nlohmann/json.hpp>

#include "core/testing/testing.h"

namespace arcwheel::testing {

// The trial part with coarser rows, points and map; the surface, the aperture and the wheel
// (nominal radius included) are the shipped ones.
inline nlohmann::json SmallTrialPart() {
  nlohmann::json job = nlohmann::json::parse(ReadText(SourceDir() / "grinding/examples/trial_part.json"));
  job["path"]["step_over_mm"] = 10.0;
  job["path"]["point_spacing_mm"] = 10.0;
  job["gouge_check"] = {{"spacing_mm", 50.0}, {"samples", 9}};
  job["prediction"]["map_nodes"] = {44, 44};  // a 10 mm grid over 430 mm
  return job;
}

// A polishing job for the trial part: a wide Gaussian tool on a raster whose points lie on the
// map's 10 mm grid. Its error map comes from the chain.
inline nlohmann::json TrialPolishJob() {
  const nlohmann::json part =
      nlohmann::json::parse(ReadText(SourceDir() / "grinding/examples/trial_part.json"));
  return {{"name", "trial part after grinding"},
          {"surface", part["surface"]},
          {"aperture", part["aperture"]},
          {"error_map", nlohmann::json::object()},
          {"removal_target", {{"uniform_layer_um", 0.2}}},
          {"removal_function", {{"peak_rate_um_per_s", 0.1}, {"fwhm_mm", 60.0}}},
          {"path", {{"line_spacing_mm", 10.0}, {"point_spacing_mm", 10.0}, {"extension_mm", 40.0}}},
          {"machine", {{"max_speed_mm_s", 500.0}}}};
}

}  // namespace arcwheel::testing
