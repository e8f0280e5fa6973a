#pragma once
// The report stage's reader of what `arcwheel polish` writes (docs/polishing.md, formats.md
// section 7): OUTDIR/polish_summary.json, OUTDIR/residual_map.csv and OUTDIR/polishing_path.csv.
//
// The polish report is drawn from these three files alone, so that every number and map in it
// can be traced to them. A file that cannot be opened throws Error{kIo}; anything malformed
// (invalid JSON, a missing key, a wrong type, a bad CSV line, files that disagree) throws
// Error{kBadInput, "reports.polish"} naming the file and the key or line.

#include <array>
#include <cstdint>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <string>
#include <string_view>
#include <vector>

namespace arcwheel::reports {

// residual_map.csv (x_mm,y_mm,target_um,removal_um,residual_um), one aperture node per row, put
// back on its regular grid. Grids are row-major [n_x, n_y]: node (i, j) at index i * n_y + j,
// at x_mm[i], y_mm[j]; NaN where the file has no node.
struct ResidualMap {
  std::vector<double> x_mm;  // grid nodes, increasing
  std::vector<double> y_mm;  // grid nodes, increasing
  std::vector<double> target_um;
  std::vector<double> removal_um;
  std::vector<double> residual_um;
  std::size_t nodes = 0;  // rows in the file
  [[nodiscard]] std::size_t n_x() const { return x_mm.size(); }
  [[nodiscard]] std::size_t n_y() const { return y_mm.size(); }
};

// polishing_path.csv: the points in path order. Columns are found by header name; extra columns
// are ignored.
struct PolishingPathTable {
  std::vector<std::string> comments;  // "# " lines, without the "# "
  std::vector<double> x_mm;
  std::vector<double> y_mm;
  std::vector<double> z_mm;
  std::vector<double> speed_mm_s;
  std::vector<double> dwell_s;
  // Length of the path up to each point (3-D, in the part frame); 0 at the first point.
  std::vector<double> path_length_mm;
  [[nodiscard]] std::size_t size() const { return x_mm.size(); }
};

// polish_summary.json. The *_text fields hold numbers exactly as the file writes them (JSON's
// shortest round-trip form), which is how the report prints them.
struct PolishSummary {
  std::string arcwheel_version;
  std::string job_name;
  std::string error_map_file;  // job.error_map.file as recorded, "" when absent
  std::int64_t points = 0;
  std::int64_t aperture_nodes = 0;
  double total_time_s = 0.0;
  double before_pv_um = 0.0;
  double before_rms_um = 0.0;
  double after_pv_um = 0.0;
  double after_rms_um = 0.0;
  double min_speed_mm_s = 0.0;
  double max_speed_mm_s = 0.0;
  double max_acceleration_mm_s2 = 0.0;
  std::int64_t solver_iterations = 0;
  bool solver_converged = false;
  // Machine limits from job.machine (0 when the job does not set them: no limit).
  double limit_max_speed_mm_s = 0.0;
  double limit_min_speed_mm_s = 0.0;
  double limit_max_acceleration_mm_s2 = 0.0;
  std::string total_time_text;
  std::string before_pv_text;
  std::string before_rms_text;
  std::string after_pv_text;
  std::string after_rms_text;
  nlohmann::json job = nlohmann::json::object();  // the job as used
  // The robot's solution (summary key "robot"), when the job named a robot: model, the arm
  // configuration (cfx), per joint the limits [lower, upper] (deg), the smallest margin to them
  // (deg) and the largest speed ratio; the smallest |joint 5| (deg).
  bool has_robot = false;
  std::string robot_model;
  std::int64_t robot_cfx = 0;
  std::array<std::array<double, 2>, 6> robot_limits_deg{};
  std::array<double, 6> robot_min_limit_margin_deg{};
  std::array<double, 6> robot_max_speed_ratio{};
  double robot_wrist_margin_deg = 0.0;
  // Segments slowed for the joints (summaries before they were reported: none): the target each
  // runs into (a row of polishing_path.csv, 1 = first) and its slowed / planned time; their
  // added time and the largest removal it adds, where, and its RMS.
  std::vector<std::int64_t> robot_slowed_targets;
  std::vector<double> robot_slowed_factor;
  double robot_added_time_s = 0.0;
  double robot_added_max_nm = 0.0;
  double robot_added_rms_nm = 0.0;
  std::array<double, 2> robot_added_max_at_mm{};
};

// robot_joints.csv: joints 1 - 6 (deg) at each target, in path order.
struct RobotJointsTable {
  std::vector<double> target;                    // 1-based target number
  std::array<std::vector<double>, 6> joint_deg;  // joint i + 1 at each target
  [[nodiscard]] std::size_t size() const { return target.size(); }
};

// Parsers from text; `source_name` stands for the file in messages. These are the in-memory
// entry points of the readers (and what a fuzzer calls).
[[nodiscard]] ResidualMap ParseResidualMapCsv(std::string_view text, const std::string& source_name);
[[nodiscard]] PolishingPathTable ParsePolishingPathCsv(std::string_view text, const std::string& source_name);
[[nodiscard]] PolishSummary ParsePolishSummary(const std::string& text, const std::string& source_name);
[[nodiscard]] RobotJointsTable ParseRobotJointsCsv(std::string_view text, const std::string& source_name);

struct SourceFile {
  std::filesystem::path path;
  std::string sha256;  // lower-case hex SHA-256 of the file
};

// The three inputs of a polish report, checked against each other: the path has
// polish_summary.json's "points" rows and the residual map its "aperture_nodes" rows.
struct PolishReportInputs {
  PolishSummary summary;
  ResidualMap residual;
  PolishingPathTable path;
  std::vector<SourceFile> sources;  // summary, residual map, path (and robot joints), in that order
  RobotJointsTable robot_joints;    // empty unless the summary has a robot
};

// Reads the three files of a polish output folder. Throws as described at the top.
[[nodiscard]] PolishReportInputs ReadPolishReportInputs(const std::filesystem::path& outdir);

}  // namespace arcwheel::reports
