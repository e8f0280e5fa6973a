#pragma once
// The toolpath job file (JSON, documented in docs/grinding.md): surface, aperture, wheel, path,
// gouge check, machine, prediction and outputs. Unknown keys are refused by their dotted name.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "grinding/prediction.h"
#include "grinding/toolpath.h"
#include "grinding/wheel.h"
#include "surfaces/surface.h"

namespace arcwheel::grinding {

struct MachineOptions {
  int pmac_program = 1;     // PMAC motion program number, >= 1
  int decimals = 4;         // decimals of mm in G-code and PMAC moves (4 = 0.1 um), 1 .. 9
  double retract_mm = 5.0;  // lift between rows (one-way) and between passes, >= 0
  // Empty when valid, else one line per violation naming the job key and the value.
  [[nodiscard]] std::vector<std::string> Problems() const;
};

struct OutputChoice {
  bool csv = true;
  bool gcode = true;
  bool pmac = true;
};

// A measured wheel (a summary.json) that replaces the job's nominal arc radius. A job names the
// nominal wheel it was written for; after each dressing the scan measures the real one, which is
// then used, and the two are recorded side by side.
struct WheelChange {
  std::optional<double> nominal_arc_radius_mm;  // the job's wheel.arc_radius_mm, if it gives one
  double measured_arc_radius_mm = 0.0;          // the summary's mean_arc_radius_mm
  double measured_sigma_mm = 0.0;               // its 1-sigma, mean_arc_radius_sigma_mm
  double max_change_mm = 0.0;                   // the limit the difference was checked against
  // measured - nominal; 0 without a nominal radius.
  [[nodiscard]] double DifferenceMm() const {
    return nominal_arc_radius_mm ? measured_arc_radius_mm - *nominal_arc_radius_mm : 0.0;
  }
};

// Default of --max-wheel-change-mm (docs/grinding.md): a dressing takes tens of micrometres off
// the arc radius, a wrong wheel differs by millimetres (arc wheels come in radii millimetres
// apart); half a millimetre lets many dressings through and stops a wrong wheel.
inline constexpr double kDefaultMaxWheelChangeMm = 0.5;

// Which measured wheel a summary gives the path (--wheel-profile, docs/grinding.md):
//   kMeanProfile: the per-phase fits' mean arc radius and, with wheel.use_profile, their mean profile;
//   kModel: the wheel model's mean arc radius and, with wheel.use_profile, its profile error p(u)
//           (from wheel_map.h5 beside the summary); without use_profile the path is a pure arc and
//           the prediction includes the error p(u) prints.
enum class WheelProfileSource { kMeanProfile, kModel };

struct Job {
  std::string name;  // "name" key, or the job file's stem
  std::filesystem::path source;
  std::shared_ptr<const surfaces::Surface> surface;
  surfaces::Aperture aperture;
  Wheel wheel;
  ToolpathOptions path;
  MachineOptions machine;
  OutputChoice outputs;
  bool predict = true;
  PredictionOptions prediction;
  std::optional<std::filesystem::path> wheel_summary;  // where the wheel came from, if a summary
  std::optional<WheelChange> wheel_change;             // set whenever the wheel comes from a summary
  // Where prediction.arc_radius_error_mm came from: "prediction.arc_radius_error_mm" (the job),
  // "the measured radius's 1-sigma" (the summary) or "none" (0 by default).
  std::string arc_radius_error_source = "none";
  WheelProfileSource wheel_profile = WheelProfileSource::kMeanProfile;
  // The job with every default filled in, as used: JSON text (parse it where it is written out),
  // so that this header does not pull nlohmann/json into every includer.
  std::string resolved_json;
};

// Reads and validates a job. `wheel_summary_override` (the CLI's --wheel) replaces the job's
// `wheel.summary`; a relative `wheel.summary` is taken relative to the job file's folder. With a
// summary, its measured mean arc radius replaces the job's nominal `wheel.arc_radius_mm`, unless
// the two differ by more than `max_wheel_change_mm` (> 0): then the job is refused, naming both.
// Throws Error{kIo} if a file cannot be read, Error{kBadInput, "grinding.job"} naming the file
// and the dotted key for anything malformed, unknown or inconsistent, Error{kInvalidOption} for
// a limit that is not > 0.
[[nodiscard]] Job ReadJob(const std::filesystem::path& path,
                          const std::optional<std::filesystem::path>& wheel_summary_override,
                          double max_wheel_change_mm = kDefaultMaxWheelChangeMm,
                          WheelProfileSource wheel_profile = WheelProfileSource::kMeanProfile);

// The same from JSON text already in memory (`source` names it in messages).
[[nodiscard]] Job ParseJob(const std::string& text, const std::filesystem::path& source,
                           const std::optional<std::filesystem::path>& wheel_summary_override,
                           double max_wheel_change_mm = kDefaultMaxWheelChangeMm,
                           WheelProfileSource wheel_profile = WheelProfileSource::kMeanProfile);

}  // namespace arcwheel::grinding
