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
  // The job with every default filled in, as used: JSON text (parse it where it is written out),
  // so that this header does not pull nlohmann/json into every includer.
  std::string resolved_json;
};

// Reads and validates a job. `wheel_summary_override` (the CLI's --wheel) replaces the job's
// `wheel.summary`; a relative `wheel.summary` is taken relative to the job file's folder.
// Throws Error{kIo} if a file cannot be read, Error{kBadInput, "grinding.job"} naming the file
// and the dotted key for anything malformed, unknown or inconsistent.
[[nodiscard]] Job ReadJob(const std::filesystem::path& path,
                          const std::optional<std::filesystem::path>& wheel_summary_override);

// The same from JSON text already in memory (`source` names it in messages).
[[nodiscard]] Job ParseJob(const std::string& text, const std::filesystem::path& source,
                           const std::optional<std::filesystem::path>& wheel_summary_override);

}  // namespace arcwheel::grinding
