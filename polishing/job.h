#pragma once
// The polishing job file (JSON, documented in docs/polishing.md) and the run that turns it into a
// robot program. Unknown keys are refused by their dotted name.

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "polishing/dwell.h"
#include "polishing/error_map_io.h"
#include "polishing/reachability.h"
#include "polishing/removal_target.h"
#include "polishing/robot_kinematics.h"
#include "polishing/robot_model.h"
#include "polishing/robot_program.h"
#include "polishing/time_scaling.h"
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
  // The robot that runs the program (the "robot" section); without one nothing is checked and
  // polish.mod leaves the configuration to the controller (ConfL \Off).
  RobotCell robot;
  std::shared_ptr<const RobotKinematics> robot_kinematics;  // of robot.model (or robot.urdf)
  // The job with every default filled in, as JSON text (keeps nlohmann/json out of this header).
  std::string resolved_json;
};

// Reads and validates a job; the error map's "file" is relative to the job's folder.
// `error_map_override` replaces the job's `error_map.file` (then the job may leave it out), as
// `arcwheel regenerate` does with the predicted form error.
// Throws Error{kIo} or Error{kBadInput, "polishing.job"} naming the file and the dotted key.
[[nodiscard]] PolishJob ReadPolishJob(const std::filesystem::path& path,
                                      const std::optional<std::filesystem::path>& error_map_override = {});

// Bytes a polish run holds per item, measured as the peak resident memory of `arcwheel polish`
// over jobs of 845 to 1.3e6 dwell points and 4e3 to 1.6e6 map nodes (docs/polishing.md, "Sizes"):
// a dwell point with its bounds, solver vectors, tool frame, CSV and RAPID text (525 B at most);
// an entry the removal matrix reserves for it (a footprint box of map nodes per point, 16.5 - 17.8
// B each); a map node with its copies (target, prediction, residual, residual CSV: 155 B).
inline constexpr double kBytesPerDwellPoint = 550.0;
inline constexpr double kBytesPerRemovalMatrixEntry = 18.0;

// The dwell points a path of `pattern` over the aperture will hold: exact for a spiral and a
// rectangle's raster, an upper bound for a circle's raster. Computed in doubles: a spacing far too
// small gives a huge (or infinite) count, never an overflow.
[[nodiscard]] double PathPointCount(const surfaces::Aperture& aperture, const RasterOptions& options,
                                    PathPattern pattern);

// The sizes a valid job implies against the memory budget (core/memory_budget.h), one line per
// problem in the "key = value violates rule" form; empty when it fits.
[[nodiscard]] std::vector<std::string> SizeProblems(const PolishJob& job);

struct PolishRunReport {
  // The dwell as the robot runs it: where the targets are not the dwell points (a precession's
  // steps, slowed segments) its dwell_s, prediction, residual and total time are the targets'.
  DwellSolution dwell;
  std::size_t points = 0;  // robot targets: rows of polishing_path.csv
  double max_speed_mm_s = 0.0;
  double min_speed_mm_s = 0.0;
  std::optional<RobotPath> robot;  // the robot's solution, when the job names a robot
  TimeScaling slowing;             // the segments slowed for the robot's joints (none: empty)
};

// Solves the dwell and writes OUTDIR/polishing_path.csv, polish.mod (RAPID), residual_map.csv and
// polish_summary.json (and robot_joints.csv with a robot), all or none. With a robot the path is
// solved for it first (SolveRobotPath: reach, joint limits, wrist singularity, one configuration),
// the segments where a joint would be too fast are slowed (SlowDownToJointSpeeds, their removal
// added to the prediction), the joint speeds checked, and the path refused before anything is
// written when it fails. Throws Error{kBadInput, "polishing.job"}
// for a map node or a path point off the surface, Error{kBadInput, "polishing.robot"} for a path
// the robot cannot run, and whatever SolveDwell throws.
PolishRunReport RunPolishJob(const PolishJob& job, const std::filesystem::path& output_folder);

// `arcwheel polish --place-workobject`: solves the dwell and the path as RunPolishJob does, then
// proposes a work-object origin (the job's orientation kept) at which the job's robot runs the
// path with every margin above the job's thresholds (ProposeWorkObjectOrigin). Writes nothing.
// Throws Error{kInvalidOption, "polishing.job"} when the job names no robot.
[[nodiscard]] WorkObjectProposal ProposeWorkObject(const PolishJob& job);
// The proposal as the command prints it: the origin, the job key to set and every margin.
[[nodiscard]] std::string DescribeProposal(const WorkObjectProposal& proposal, const PolishJob& job);

}  // namespace arcwheel::polishing
