#pragma once
// The polishing job file (JSON, documented in docs/polishing.md) and the run that turns it into a
// robot program. Unknown keys are refused by their dotted name.

#include <filesystem>
#include <memory>
#include <string>

#include "polishing/dwell.h"
#include "polishing/error_map_io.h"
#include "polishing/removal_target.h"
#include "polishing/robot_program.h"
#include "polishing/tool_frame.h"
#include "surfaces/surface.h"

namespace arcwheel::polishing {

struct PolishJob {
  std::string name;
  std::filesystem::path source;
  std::shared_ptr<const surfaces::Surface> surface;
  surfaces::Aperture aperture;
  std::filesystem::path error_map_file;
  ErrorMap error_map;
  RemovalTargetOptions target;
  RemovalFunction removal;                          // a Gaussian, or a measured table (removal_function.file)
  PathPattern path_pattern = PathPattern::kRaster;  // path.type
  RasterOptions path;
  DwellOptions dwell;
  RobotSide robot_side = RobotSide::kPlusX;
  PathPrecession precession;  // enabled when the job has a "precession" section
  ToolData tool;
  WorkObject work_object;
  // The job with every default filled in, as JSON text (keeps nlohmann/json out of this header).
  std::string resolved_json;
};

// Reads and validates a job; the error map's "file" is relative to the job's folder.
// Throws Error{kIo} or Error{kBadInput, "polishing.job"} naming the file and the dotted key.
[[nodiscard]] PolishJob ReadPolishJob(const std::filesystem::path& path);

struct PolishRunReport {
  DwellSolution dwell;
  std::size_t points = 0;
  double max_speed_mm_s = 0.0;
  double min_speed_mm_s = 0.0;
};

// Solves the dwell and writes OUTDIR/polishing_path.csv, polish.mod (RAPID), residual_map.csv and
// polish_summary.json, all or none. Throws Error{kBadInput, "polishing.job"} for a map node or a
// path point off the surface, and whatever SolveDwell throws.
PolishRunReport RunPolishJob(const PolishJob& job, const std::filesystem::path& output_folder);

}  // namespace arcwheel::polishing
