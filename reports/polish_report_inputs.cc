#include "reports/polish_report_inputs.h"

#include <fmt/format.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <map>
#include <optional>
#include <set>
#include <span>
#include <sstream>

#include "core/error.h"
#include "core/json_text.h"
#include "core/nan.h"
#include "core/sha256.h"
#include "core/text_lines.h"
#include "schema/polish_outputs.h"

namespace arcwheel::reports {
namespace {

using nlohmann::json;
constexpr const char* kPolishReportInputsStage = "reports.polish";
// A residual map is an aperture's nodes; a grid larger than this is a broken file, not a map.
constexpr double kMaxGridNodes = 1e7;

[[noreturn]] void Bad(const std::string& what) {
  throw Error(ErrorCode::kBadInput, kPolishReportInputsStage, what);
}

[[noreturn]] void BadLine(const std::string& source, std::size_t line, const std::string& what) {
  Bad(fmt::format("'{}' line {}: {}", source, line, what));
}

std::vector<std::string_view> SplitCells(std::string_view line) {
  std::vector<std::string_view> cells;
  std::size_t start = 0;
  for (;;) {
    const std::size_t comma = line.find(',', start);
    cells.push_back(
        line.substr(start, comma == std::string_view::npos ? std::string_view::npos : comma - start));
    if (comma == std::string_view::npos) return cells;
    start = comma + 1;
  }
}

// A whole cell as a double (from_chars: no locale, no leading space or '+'); "nan" is accepted.
bool ParseDouble(std::string_view cell, double& value) {
  const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  return error == std::errc() && end == cell.data() + cell.size() && !cell.empty();
}

// Header cells to column indices; every name of `required` must be present.
std::vector<std::size_t> Columns(std::string_view header, std::span<const std::string_view> required,
                                 const std::string& source, std::size_t line) {
  std::map<std::string, std::size_t, std::less<>> index;
  const std::vector<std::string_view> cells = SplitCells(header);
  for (std::size_t c = 0; c < cells.size(); ++c) index.emplace(std::string(cells[c]), c);
  std::vector<std::size_t> columns;
  for (const std::string_view name : required) {
    const auto it = index.find(name);
    if (it == index.end()) {
      BadLine(
          source, line,
          fmt::format("header '{}' has no column '{}' (needs {})", header, name, fmt::join(required, ",")));
    }
    columns.push_back(it->second);
  }
  return columns;
}

// Reads the data rows of a CSV with the named columns: `row(values, line)` gets the values in
// the order of `required`. Lines starting with '#' are passed to `comment`.
template <typename Row, typename Comment>
void ReadCsv(std::string_view text, const std::string& source, std::span<const std::string_view> required,
             const Row& row, const Comment& comment) {
  TextLines lines(text);
  std::string_view line;
  std::vector<std::size_t> columns;
  std::size_t width = 0;
  std::vector<double> values(required.size());
  while (lines.Next(line)) {
    if (line.empty()) continue;
    if (line.front() == '#') {
      comment(line);
      continue;
    }
    if (columns.empty()) {
      columns = Columns(line, required, source, lines.number());
      width = SplitCells(line).size();
      continue;
    }
    const std::vector<std::string_view> cells = SplitCells(line);
    if (cells.size() != width)
      BadLine(source, lines.number(), fmt::format("has {} values, the header names {}", cells.size(), width));
    for (std::size_t k = 0; k < required.size(); ++k) {
      if (!ParseDouble(cells[columns[k]], values[k])) {
        BadLine(source, lines.number(),
                fmt::format("{} '{}' is not a number", required[k], cells[columns[k]]));
      }
    }
    row(values, lines.number());
  }
  if (columns.empty())
    BadLine(source, lines.number(), fmt::format("has no header line ({})", fmt::join(required, ",")));
}

// Grid nodes of one axis from the distinct coordinates: spacing = the median gap (a stray value
// is then reported as off the grid rather than taken for the spacing).
std::vector<double> GridNodes(const std::set<double>& values, const std::string& source, const char* axis) {
  if (values.size() == 1) return {*values.begin()};
  std::vector<double> gaps;
  for (auto it = std::next(values.begin()); it != values.end(); ++it) gaps.push_back(*it - *std::prev(it));
  std::nth_element(gaps.begin(), gaps.begin() + static_cast<std::ptrdiff_t>(gaps.size() / 2), gaps.end());
  const double step = gaps[gaps.size() / 2];
  const double count = std::round((*values.rbegin() - *values.begin()) / step) + 1.0;
  if (!(count <= kMaxGridNodes))
    Bad(fmt::format("'{}': the {} nodes would need a grid of {} nodes", source, axis, count));
  std::vector<double> nodes(static_cast<std::size_t>(count));
  for (std::size_t i = 0; i < nodes.size(); ++i) nodes[i] = *values.begin() + static_cast<double>(i) * step;
  return nodes;
}

// Index of `v` among regular `nodes`, or -1 when it is not within 1e-6 spacing of one.
std::ptrdiff_t NodeIndex(const std::vector<double>& nodes, double v) {
  if (nodes.size() == 1) return v == nodes.front() ? 0 : -1;
  const double u = (v - nodes.front()) / (nodes[1] - nodes[0]);
  const double r = std::round(u);
  return std::abs(u - r) <= 1e-6 && r >= 0.0 && r < static_cast<double>(nodes.size())
             ? static_cast<std::ptrdiff_t>(r)
             : -1;
}

// Locates a value in the summary for messages: "'OUTDIR/polish_summary.json' key 'before.pv_um'".
class JsonReader {
 public:
  JsonReader(const json& root, std::string source) : root_(root), source_(std::move(source)) {}

  [[nodiscard]] const std::string& source() const { return source_; }
  [[noreturn]] void Fail(const std::string& key, const std::string& problem) const {
    Bad(fmt::format("'{}' key '{}' {}", source_, key, problem));
  }
  // The value at a dotted key, or nullptr when a part of it is absent.
  [[nodiscard]] const json* Find(const std::string& key) const {
    const json* node = &root_;
    std::size_t start = 0;
    for (;;) {
      const std::size_t dot = key.find('.', start);
      const std::string part = key.substr(start, dot == std::string::npos ? std::string::npos : dot - start);
      if (!node->is_object()) Fail(key.substr(0, start == 0 ? 0 : start - 1), "is not a JSON object");
      const auto it = node->find(part);
      if (it == node->end()) return nullptr;
      node = &*it;
      if (dot == std::string::npos) return node;
      start = dot + 1;
    }
  }
  [[nodiscard]] const json& Require(const std::string& key) const {
    const json* value = Find(key);
    if (value == nullptr) Fail(key, "is missing");
    return *value;
  }
  [[nodiscard]] double Number(const std::string& key) const {
    const json& value = Require(key);
    if (!value.is_number() || !std::isfinite(value.get<double>()))
      Fail(key, "is not a finite number (found " + JsonText(value) + ")");
    return value.get<double>();
  }
  [[nodiscard]] double OptionalNumber(const std::string& key, double fallback) const {
    return Find(key) == nullptr ? fallback : Number(key);
  }
  [[nodiscard]] std::int64_t Count(const std::string& key) const {
    const json& value = Require(key);
    if (!value.is_number_integer() || value.get<std::int64_t>() < 0) {
      Fail(key, "is not a non-negative integer (found " + JsonText(value) + ")");
    }
    return value.get<std::int64_t>();
  }
  [[nodiscard]] std::string String(const std::string& key) const {
    const json& value = Require(key);
    if (!value.is_string()) Fail(key, "is not a string (found " + JsonText(value) + ")");
    return value.get<std::string>();
  }
  [[nodiscard]] bool Boolean(const std::string& key) const {
    const json& value = Require(key);
    if (!value.is_boolean()) Fail(key, "is not true or false (found " + JsonText(value) + ")");
    return value.get<bool>();
  }
  // The number as the file writes it (nlohmann's shortest round-trip form, as the writer used).
  [[nodiscard]] std::string NumberText(const std::string& key) const {
    (void)Number(key);
    return JsonText(Require(key));
  }

 private:
  const json& root_;
  std::string source_;
};

// "before.pv_um": the reader's dotted form of a nested key.
std::string Dotted(std::string_view object, std::string_view name) {
  return fmt::format("{}.{}", object, name);
}

// A file without schema_version was written before versions were recorded: read it as 1.0.
// robot.slowed_segments, added_time_s and added_removal, when the summary has them.
void ReadSlowedSegments(const JsonReader& r, PolishSummary& s) {
  namespace key = schema::polish::summary::robot;
  const std::string robot(schema::polish::summary::kRobot);
  const std::string list = Dotted(robot, key::kSlowedSegments);
  if (r.Find(list) == nullptr) return;
  const json& segments = r.Require(list);
  if (!segments.is_array()) r.Fail(list, "is not an array");
  for (std::size_t n = 0; n < segments.size(); ++n) {
    const JsonReader segment(segments[n], r.source());
    const std::string at = fmt::format("{}[{}]", list, n);
    if (!segments[n].is_object()) r.Fail(at, "is not a JSON object");
    const double planned_s = segment.Number(std::string(key::slowed_segments::kPlannedS));
    const double slowed_s = segment.Number(std::string(key::slowed_segments::kSlowedS));
    if (!(planned_s > 0.0)) r.Fail(at + "." + std::string(key::slowed_segments::kPlannedS), "is not > 0");
    s.robot_slowed_targets.push_back(segment.Count(std::string(key::slowed_segments::kTarget)));
    s.robot_slowed_factor.push_back(slowed_s / planned_s);
  }
  s.robot_added_time_s = r.Number(Dotted(robot, key::kAddedTimeS));
  const std::string added = Dotted(robot, key::kAddedRemoval);
  s.robot_added_max_nm = r.Number(Dotted(added, key::added_removal::kMaxNm));
  s.robot_added_rms_nm = r.Number(Dotted(added, key::added_removal::kRmsNm));
  const json& at = r.Require(Dotted(added, key::added_removal::kMaxAtMm));
  if (!at.is_array() || at.size() != 2 || !at[0].is_number() || !at[1].is_number())
    r.Fail(Dotted(added, key::added_removal::kMaxAtMm), "is not [x, y]");
  s.robot_added_max_at_mm = {at[0].get<double>(), at[1].get<double>()};
}

void CheckPolishSummaryVersion(const JsonReader& r) {
  const std::string name(schema::polish::summary::kSchemaVersion);
  const std::optional<std::string> version =
      r.Find(name) == nullptr ? std::nullopt : std::optional<std::string>(r.String(name));
  schema::CheckVersion(version, schema::polish::kVersion, r.source(), fmt::format("key '{}'", name),
                       kPolishReportInputsStage);
}

std::string ReadWhole(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) {
    const std::string why = std::filesystem::exists(path) ? "cannot be read" : "does not exist";
    throw Error(ErrorCode::kIo, kPolishReportInputsStage,
                fmt::format("'{}' {} (is this a folder written by `arcwheel polish`?)", path.string(), why));
  }
  std::ostringstream text;
  text << in.rdbuf();
  return text.str();
}

}  // namespace

ResidualMap ParseResidualMapCsv(std::string_view text, const std::string& source_name) {
  struct Node {
    double x, y, target, removal, residual;
    std::size_t line;
  };
  std::vector<Node> nodes;
  ReadCsv(
      text, source_name, schema::polish::residual_map::kColumns,
      [&](const std::vector<double>& v, std::size_t line) {
        if (!std::isfinite(v[0]) || !std::isfinite(v[1]))
          BadLine(source_name, line,
                  fmt::format("{} and {} must be finite", schema::polish::residual_map::kXMm,
                              schema::polish::residual_map::kYMm));
        nodes.push_back({v[0], v[1], v[2], v[3], v[4], line});
      },
      [](std::string_view) {});
  if (nodes.empty()) Bad(fmt::format("'{}' has no aperture node", source_name));
  std::set<double> xs, ys;
  for (const Node& n : nodes) xs.insert(n.x), ys.insert(n.y);
  ResidualMap map;
  map.x_mm = GridNodes(xs, source_name, "x_mm");
  map.y_mm = GridNodes(ys, source_name, "y_mm");
  const double grid_nodes = static_cast<double>(map.n_x()) * static_cast<double>(map.n_y());
  if (grid_nodes > kMaxGridNodes) {
    Bad(fmt::format("'{}': a grid of {} x {} nodes is too large for a residual map", source_name, map.n_x(),
                    map.n_y()));
  }
  // Aperture nodes fill most of their grid; a few nodes spanning a vast grid are not a map.
  if (grid_nodes > 64.0 * static_cast<double>(nodes.size()) + 4096.0) {
    Bad(fmt::format("'{}': {} nodes spread over a grid of {} x {}: not the nodes of one regular grid",
                    source_name, nodes.size(), map.n_x(), map.n_y()));
  }
  const std::size_t cells = map.n_x() * map.n_y();
  map.target_um.assign(cells, kNaN);
  map.removal_um.assign(cells, kNaN);
  map.residual_um.assign(cells, kNaN);
  std::vector<bool> seen(cells, false);
  for (const Node& n : nodes) {
    const std::ptrdiff_t i = NodeIndex(map.x_mm, n.x), j = NodeIndex(map.y_mm, n.y);
    if (i < 0 || j < 0)
      BadLine(source_name, n.line,
              fmt::format("node ({}, {}) mm is not on the grid of the other nodes", n.x, n.y));
    const std::size_t k = static_cast<std::size_t>(i) * map.n_y() + static_cast<std::size_t>(j);
    if (seen[k]) BadLine(source_name, n.line, fmt::format("node ({}, {}) mm appears twice", n.x, n.y));
    seen[k] = true;
    map.target_um[k] = n.target;
    map.removal_um[k] = n.removal;
    map.residual_um[k] = n.residual;
  }
  map.nodes = nodes.size();
  return map;
}

PolishingPathTable ParsePolishingPathCsv(std::string_view text, const std::string& source_name) {
  namespace column = schema::polish::path;
  // The lambda below takes the values by their position in kColumns.
  static_assert(column::kColumns[7] == column::kSpeedMmS && column::kColumns[8] == column::kDwellS);
  PolishingPathTable path;
  ReadCsv(
      text, source_name, column::kColumns,
      [&](const std::vector<double>& v, std::size_t line) {
        for (double value : v) {
          if (!std::isfinite(value)) BadLine(source_name, line, "every value must be finite");
        }
        if (!(v[7] > 0.0))
          BadLine(source_name, line, fmt::format("{} = {} is not > 0", column::kSpeedMmS, v[7]));
        if (!(v[8] >= 0.0))
          BadLine(source_name, line, fmt::format("{} = {} is negative", column::kDwellS, v[8]));
        double length = 0.0;
        if (!path.x_mm.empty()) {
          length = path.path_length_mm.back() +
                   std::hypot(v[0] - path.x_mm.back(), v[1] - path.y_mm.back(), v[2] - path.z_mm.back());
        }
        path.x_mm.push_back(v[0]);
        path.y_mm.push_back(v[1]);
        path.z_mm.push_back(v[2]);
        path.speed_mm_s.push_back(v[7]);
        path.dwell_s.push_back(v[8]);
        path.path_length_mm.push_back(length);
      },
      [&](std::string_view comment) {
        comment.remove_prefix(1);
        if (!comment.empty() && comment.front() == ' ') comment.remove_prefix(1);
        path.comments.emplace_back(comment);
      });
  if (path.size() == 0) Bad(fmt::format("'{}' has no path point", source_name));
  return path;
}

RobotJointsTable ParseRobotJointsCsv(std::string_view text, const std::string& source_name) {
  RobotJointsTable table;
  ReadCsv(
      text, source_name, schema::polish::robot_joints::kColumns,
      [&](const std::vector<double>& v, std::size_t line) {
        for (double value : v) {
          if (!std::isfinite(value)) BadLine(source_name, line, "every value must be finite");
        }
        table.target.push_back(v[0]);
        for (std::size_t i = 0; i < 6; ++i) table.joint_deg[i].push_back(v[i + 1]);
      },
      [](std::string_view) {});
  if (table.size() == 0) Bad(fmt::format("'{}' has no target", source_name));
  return table;
}

PolishSummary ParsePolishSummary(const std::string& text, const std::string& source_name) {
  const json root = ParseJsonText(text, source_name, kPolishReportInputsStage);
  if (!root.is_object()) Bad(fmt::format("'{}' is not a JSON object", source_name));
  const JsonReader r(root, source_name);
  namespace key = schema::polish::summary;
  const std::string before_pv = Dotted(key::kBefore, key::figures::kPvUm);
  const std::string before_rms = Dotted(key::kBefore, key::figures::kRmsUm);
  const std::string after_pv = Dotted(key::kAfter, key::figures::kPvUm);
  const std::string after_rms = Dotted(key::kAfter, key::figures::kRmsUm);
  const std::string total_time(key::kTotalTimeS);
  const std::string job(key::kJob);
  const std::string machine = Dotted(key::kJob, key::job::kMachine);
  CheckPolishSummaryVersion(r);
  PolishSummary s;
  s.arcwheel_version = r.String(std::string(key::kArcwheelVersion));
  if (!r.Require(job).is_object()) r.Fail(job, "is not a JSON object");
  s.job = r.Require(job);
  s.job_name = r.String(Dotted(job, key::job::kName));
  const std::string error_map_file = Dotted(Dotted(job, key::job::kErrorMap), key::job::error_map::kFile);
  if (r.Find(error_map_file) != nullptr) s.error_map_file = r.String(error_map_file);
  s.points = r.Count(std::string(key::kPoints));
  s.aperture_nodes = r.Count(std::string(key::kApertureNodes));
  s.total_time_s = r.Number(total_time);
  s.before_pv_um = r.Number(before_pv);
  s.before_rms_um = r.Number(before_rms);
  s.after_pv_um = r.Number(after_pv);
  s.after_rms_um = r.Number(after_rms);
  s.min_speed_mm_s = r.Number(Dotted(key::kSpeedMmS, key::speed_mm_s::kMin));
  s.max_speed_mm_s = r.Number(Dotted(key::kSpeedMmS, key::speed_mm_s::kMax));
  s.max_acceleration_mm_s2 = r.Number(std::string(key::kMaxAccelerationMmS2));
  s.solver_iterations = r.Count(Dotted(key::kSolver, key::solver::kIterations));
  s.solver_converged = r.Boolean(Dotted(key::kSolver, key::solver::kConverged));
  s.limit_max_speed_mm_s = r.Number(Dotted(machine, key::job::machine::kMaxSpeedMmS));
  s.limit_min_speed_mm_s = r.OptionalNumber(Dotted(machine, key::job::machine::kMinSpeedMmS), 0.0);
  s.limit_max_acceleration_mm_s2 =
      r.OptionalNumber(Dotted(machine, key::job::machine::kMaxAccelerationMmS2), 0.0);
  if (r.Find(std::string(key::kRobot)) != nullptr) {
    const std::string robot(key::kRobot);
    s.has_robot = true;
    s.robot_model = r.String(Dotted(robot, key::robot::kModel));
    s.robot_cfx = r.Count(Dotted(robot, key::robot::kCfx));
    s.robot_wrist_margin_deg = r.Number(Dotted(robot, key::robot::kWristMarginDeg));
    const auto numbers = [&](std::string_view name, std::size_t count) {
      const std::string k = Dotted(robot, name);
      const json& v = r.Require(k);
      if (!v.is_array() || v.size() != count) r.Fail(k, fmt::format("is not an array of {} values", count));
      std::vector<double> out;
      for (const json& e : v) {
        if (e.is_array()) {
          for (const json& f : e) out.push_back(f.is_number() ? f.get<double>() : kNaN);
        } else {
          out.push_back(e.is_number() ? e.get<double>() : kNaN);
        }
      }
      for (double x : out) {
        if (!std::isfinite(x)) r.Fail(k, "holds a value that is not a finite number");
      }
      return out;
    };
    const std::vector<double> limits = numbers(key::robot::kLimitsDeg, 6);
    const std::vector<double> margins = numbers(key::robot::kMinLimitMarginDeg, 6);
    const std::vector<double> ratios = numbers(key::robot::kMaxJointSpeedRatio, 6);
    if (limits.size() != 12) r.Fail(Dotted(robot, key::robot::kLimitsDeg), "is not 6 pairs [lower, upper]");
    for (std::size_t i = 0; i < 6; ++i) {
      s.robot_limits_deg[i] = {limits[2 * i], limits[2 * i + 1]};
      s.robot_min_limit_margin_deg[i] = margins[i];
      s.robot_max_speed_ratio[i] = ratios[i];
    }
    ReadSlowedSegments(r, s);
  }
  s.total_time_text = r.NumberText(total_time);
  s.before_pv_text = r.NumberText(before_pv);
  s.before_rms_text = r.NumberText(before_rms);
  s.after_pv_text = r.NumberText(after_pv);
  s.after_rms_text = r.NumberText(after_rms);
  return s;
}

PolishReportInputs ReadPolishReportInputs(const std::filesystem::path& outdir) {
  const std::filesystem::path summary_path = outdir / schema::polish::kSummaryFileName;
  const std::filesystem::path residual_path = outdir / schema::polish::kResidualMapFileName;
  const std::filesystem::path path_path = outdir / schema::polish::kPathFileName;
  PolishReportInputs inputs;
  inputs.summary = ParsePolishSummary(ReadWhole(summary_path), summary_path.string());
  inputs.residual = ParseResidualMapCsv(ReadWhole(residual_path), residual_path.string());
  inputs.path = ParsePolishingPathCsv(ReadWhole(path_path), path_path.string());
  if (inputs.path.size() != static_cast<std::size_t>(inputs.summary.points)) {
    Bad(fmt::format("'{}' has {} points but '{}' key '{}' says {}", path_path.string(), inputs.path.size(),
                    summary_path.string(), schema::polish::summary::kPoints, inputs.summary.points));
  }
  if (inputs.residual.nodes != static_cast<std::size_t>(inputs.summary.aperture_nodes)) {
    Bad(fmt::format("'{}' has {} nodes but '{}' key '{}' says {}", residual_path.string(),
                    inputs.residual.nodes, summary_path.string(), schema::polish::summary::kApertureNodes,
                    inputs.summary.aperture_nodes));
  }
  for (const auto& file : {summary_path, residual_path, path_path})
    inputs.sources.push_back({file, Sha256OfFile(file)});
  if (inputs.summary.has_robot) {
    const std::filesystem::path joints_path = outdir / schema::polish::kRobotJointsFileName;
    inputs.robot_joints = ParseRobotJointsCsv(ReadWhole(joints_path), joints_path.string());
    if (inputs.robot_joints.size() != inputs.path.size()) {
      Bad(fmt::format("'{}' has {} targets but '{}' has {} points", joints_path.string(),
                      inputs.robot_joints.size(), path_path.string(), inputs.path.size()));
    }
    inputs.sources.push_back({joints_path, Sha256OfFile(joints_path)});
  }
  return inputs;
}

}  // namespace arcwheel::reports
