#include "polishing/job.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <numbers>
#include <optional>
#include <sstream>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_job.h"
#include "core/json_text.h"
#include "core/memory_budget.h"
#include "core/version.h"
#include "schema/polish_outputs.h"
#include "surfaces/surface_json.h"

namespace arcwheel::polishing {
namespace {

using nlohmann::json;
constexpr const char* kJobStage = "polishing.job";

AbbQuaternion ReadQuaternion(JsonSection& s, const std::string& key) {
  const std::vector<double> q = s.Numbers(key, {1.0, 0.0, 0.0, 0.0});
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-6)
    s.Fail(key, fmt::format("must be a unit quaternion (q1 scalar first), has norm {}", norm));
  return {q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm};
}

void ReadMachine(JsonSection& s, PolishJob& job) {
  job.dwell.max_speed_mm_s = s.RequiredNumber("max_speed_mm_s");
  job.dwell.min_speed_mm_s = s.Number("min_speed_mm_s", 0.0);
  job.dwell.min_dwell_s = s.Number("min_dwell_s", 0.0);
  job.dwell.max_acceleration_mm_s2 = s.Number("max_acceleration_mm_s2", 0.0);
  job.robot_side = s.Choice("robot_side", {"+x", "-x"}) == "+x" ? RobotSide::kPlusX : RobotSide::kMinusX;
}

// The range checks of DwellOptions and RasterOptions (polishing/dwell.h), by job key.
void ReadTool(JsonSection& s, PolishJob& job) {
  const std::vector<double> tcp = s.Numbers("tcp_mm", {0.0, 0.0, 150.0});
  job.tool.tcp_mm = {tcp[0], tcp[1], tcp[2]};
  job.tool.orientation = ReadQuaternion(s, "quaternion");
  const std::vector<double> offset = s.Numbers("removal_centre_offset_mm", {0.0, 0.0});
  job.tool.removal_centre_offset_mm = {offset[0], offset[1]};
  job.tool.mass_kg = s.Number("mass_kg", 5.0);
  const std::vector<double> cog = s.Numbers("centre_of_gravity_mm", {0.0, 0.0, 75.0});
  job.tool.centre_of_gravity_mm = {cog[0], cog[1], cog[2]};
}

// A Gaussian footprint, or a measured table from a file beside the job.
// A Gaussian's range problems are added to `problems`.
RemovalFunction ReadRemovalFunctionSection(JsonSection& s, const std::filesystem::path& job_path,
                                           std::vector<std::string>& problems) {
  if (s.Has("file")) {
    if (s.Has("peak_rate_um_per_s") || s.Has("fwhm_mm")) {
      s.Fail("file", "is an alternative to peak_rate_um_per_s and fwhm_mm: give one or the other");
    }
    const std::filesystem::path file = s.String("file", "");
    return ReadRemovalFunction(file.is_absolute() ? file : job_path.parent_path() / file);
  }
  GaussianRemovalFunction gaussian;
  gaussian.peak_rate_um_per_s = s.RequiredNumber("peak_rate_um_per_s");
  gaussian.fwhm_mm = s.RequiredNumber("fwhm_mm");
  for (std::string& p : gaussian.Problems()) problems.push_back(std::move(p));
  return gaussian;
}

void ReadPath(JsonSection& s, PolishJob& job) {
  job.path_pattern =
      s.Choice("type", {"raster", "spiral"}) == "spiral" ? PathPattern::kSpiral : PathPattern::kRaster;
  // Defaults from the removal function's (equivalent) width: see removal_function.h.
  job.path.line_spacing_mm = s.Number("line_spacing_mm", job.removal.EquivalentFwhmMm() / 5.0);
  job.path.point_spacing_mm = s.Number("point_spacing_mm", job.path.line_spacing_mm);
  job.path.extension_mm = s.Number("extension_mm", 1.75 * job.removal.EquivalentSigmaMm());
}

void ReadPrecession(JsonSection& s, PolishJob& job) {
  job.precession.enabled = true;
  job.precession.tilt_deg = s.RequiredNumber("tilt_deg");
  job.precession.precession_rate_rpm = s.RequiredNumber("precession_rate_rpm");
  job.precession.bonnet_radius_mm = s.Number("bonnet_radius_mm", 0.0);
  job.precession.max_step_deg = s.Number("max_step_deg", PathPrecession{}.max_step_deg);
}

// The error_map section: the file, its format and, for interferometer maps, the placement in the
// part frame (docs/polishing.md, "Error-map formats").
ErrorMap ReadErrorMapSection(JsonSection& s, const std::filesystem::path& file) {
  std::vector<std::string> formats = {"csv", "dat", "datx", "h5"};
  if (!s.Has("format")) {
    try {
      const ErrorMapFormat implied = FormatFromExtension(file);
      std::rotate(formats.begin(), formats.begin() + static_cast<int>(implied),
                  formats.begin() + static_cast<int>(implied) + 1);
    } catch (const Error&) {
      s.Fail("format", fmt::format("is required: the extension of '{}' names no format (csv, dat, datx, h5)",
                                   file.string()));
    }
  }
  const std::string format = s.Choice("format", formats);
  ErrorMapOptions options;
  options.format = format == "csv"    ? ErrorMapFormat::kCsv
                   : format == "dat"  ? ErrorMapFormat::kDat
                   : format == "datx" ? ErrorMapFormat::kDatx
                                      : ErrorMapFormat::kHdf5;
  options.placement.scale = s.Number("scale", 1.0);
  if (options.placement.scale == 0.0)
    s.Fail("scale", "must be non-zero (+1: height = material to remove, -1: depth)");
  const bool pixels = options.format == ErrorMapFormat::kDat || options.format == ErrorMapFormat::kDatx;
  for (const char* key : {"pixel_mm", "centre_px", "centre_mm", "rotation_deg", "flip"}) {
    if (!pixels && s.Has(key))
      s.Fail(key, "applies only to interferometer maps (format \"dat\" or \"datx\")");
  }
  if (options.format != ErrorMapFormat::kCsv && s.Has("layout"))
    s.Fail("layout", "applies only to format \"csv\"");
  if (options.format == ErrorMapFormat::kCsv) {
    const bool scattered = s.Choice("layout", {"grid", "scattered"}) == "scattered";
    options.layout = scattered ? ErrorMapLayout::kScattered : ErrorMapLayout::kGrid;
    if (!scattered && s.Has("grid_spacing_mm"))
      s.Fail("grid_spacing_mm", "applies only to layout \"scattered\"");
    if (scattered && s.Has("grid_spacing_mm")) {
      options.grid_spacing_mm = s.Number("grid_spacing_mm", 0.0);
      if (!(options.grid_spacing_mm > 0.0)) s.Fail("grid_spacing_mm", "must be > 0");
    }
  } else if (s.Has("grid_spacing_mm")) {
    s.Fail("grid_spacing_mm", "applies only to format \"csv\" with layout \"scattered\"");
  }
  if (!pixels) {
    ErrorMap map = ReadErrorMap(file, options);
    if (options.layout == ErrorMapLayout::kScattered) s.SetResolved("grid_spacing_mm", map.grid.dx_mm);
    return map;
  }
  const PixelMap raw = options.format == ErrorMapFormat::kDat ? ReadMetroProDat(file) : ReadZygoDatx(file);
  MapPlacement& p = options.placement;
  if (s.Has("pixel_mm")) {
    p.pixel_mm = s.Number("pixel_mm", 0.0);
    if (!(p.pixel_mm > 0.0)) s.Fail("pixel_mm", "must be > 0");
  } else if (raw.pixel_x_mm == raw.pixel_y_mm) {
    s.SetResolved("pixel_mm", raw.pixel_x_mm);  // the file's square pixels (none: PlaceInPartFrame refuses)
  }
  const std::array<double, 2> centre = ValidDataCentrePx(raw, file.string());
  const std::vector<double> centre_px = s.Numbers("centre_px", {centre[0], centre[1]});
  p.centre_column = centre_px[0];
  p.centre_row = centre_px[1];
  const std::vector<double> centre_mm = s.Numbers("centre_mm", {0.0, 0.0});
  p.centre_x_mm = centre_mm[0];
  p.centre_y_mm = centre_mm[1];
  const double rotation = s.Number("rotation_deg", 0.0);
  if (rotation != 0.0 && rotation != 90.0 && rotation != 180.0 && rotation != 270.0) {
    s.Fail("rotation_deg", fmt::format("= {} is not 0, 90, 180 or 270 (counter-clockwise)", rotation));
  }
  p.rotation_deg = static_cast<int>(rotation);
  const std::string flip = s.Choice("flip", {"none", "x", "y"});
  p.flip = flip == "x"   ? MapPlacement::Flip::kX
           : flip == "y" ? MapPlacement::Flip::kY
                         : MapPlacement::Flip::kNone;
  return PlaceInPartFrame(raw, p, file.string());
}

// The robot section: a known model (or a URDF of it), its base frame in the world, the margins.
// Range problems, an unknown model, a base frame that is not rigid and a URDF that does not parse
// are added to `problems`, so that all of them are named together.
void ReadRobot(JsonSection& s, const std::filesystem::path& job_path, PolishJob& job,
               std::vector<std::string>& problems) {
  std::vector<std::string> known;
  for (const RobotModel& m : RobotModels()) known.emplace_back(m.name);
  const std::string model = s.String("model", "");
  job.robot.model = FindRobotModel(model);
  if (!job.robot.model) {
    problems.push_back(fmt::format("robot.model = '{}' is not a robot arcwheel knows (known: {})", model,
                                   fmt::join(known, ", ")));
  }
  s.Section("base", false, [&](JsonSection& b) {
    Eigen::Matrix4d m = Eigen::Matrix4d::Identity();
    if (b.Has("matrix")) {
      if (b.Has("origin_mm") || b.Has("quaternion"))
        b.Fail("matrix", "is an alternative to origin_mm and quaternion: give one or the other");
      const std::vector<double> v = b.RequiredNumbers("matrix", 16);
      for (int r = 0; r < 4; ++r)
        for (int c = 0; c < 4; ++c) m(r, c) = v[static_cast<std::size_t>(4 * r + c)];
    } else {
      const std::vector<double> origin = b.Numbers("origin_mm", {0.0, 0.0, 0.0});
      const std::vector<double> q = b.Numbers("quaternion", {1.0, 0.0, 0.0, 0.0});
      const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
      if (std::abs(norm - 1.0) > 1e-6) {
        problems.push_back(
            fmt::format("robot.base.quaternion = [{}] is not a rigid transform: a rotation is a "
                        "unit quaternion (q1 scalar first), this one has norm {}",
                        fmt::join(q, ", "), norm));
      } else {
        m.topLeftCorner<3, 3>() =
            Eigen::Quaterniond(q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm).toRotationMatrix();
      }
      m.topRightCorner<3, 1>() = Eigen::Vector3d(origin[0], origin[1], origin[2]);
    }
    if (std::optional<std::string> problem = RigidTransformProblem(m)) {
      problems.push_back(fmt::format("robot.base.matrix is not a rigid transform: it {}", *problem));
    } else {
      job.robot.world_from_base.matrix() = m;
    }
  });
  if (s.Has("urdf")) {
    const std::filesystem::path file = s.String("urdf", "");
    const std::filesystem::path resolved = file.is_absolute() ? file : job_path.parent_path() / file;
    std::ifstream in(resolved, std::ios::binary);
    if (!in)
      throw Error(ErrorCode::kIo, kJobStage, fmt::format("cannot open robot.urdf '{}'", resolved.string()));
    std::ostringstream text;
    text << in.rdbuf();
    job.robot.urdf_override = text.str();
    job.robot.urdf_source = resolved.string();
  }
  job.robot.margins.min_joint_margin_deg =
      s.Number("min_joint_margin_deg", RobotMargins{}.min_joint_margin_deg);
  job.robot.margins.min_wrist_margin_deg =
      s.Number("min_wrist_margin_deg", RobotMargins{}.min_wrist_margin_deg);
  job.robot.margins.max_joint_speed_ratio =
      s.Number("max_joint_speed_ratio", RobotMargins{}.max_joint_speed_ratio);
  job.robot.margins.max_added_residual_nm =
      s.Number("max_added_residual_nm", RobotMargins{}.max_added_residual_nm);
  for (std::string& p : job.robot.margins.Problems()) problems.push_back(std::move(p));
  if (!job.robot.model) return;
  if (job.robot.urdf_override.empty())
    job.robot.urdf_source = fmt::format("{} (built in)", job.robot.model->name);
  try {
    job.robot_kinematics = std::make_shared<const RobotKinematics>(
        *job.robot.model,
        job.robot.urdf_override.empty() ? std::string(job.robot.model->urdf) : job.robot.urdf_override,
        job.robot.urdf_source);
  } catch (const Error& e) {
    problems.push_back(fmt::format("robot.urdf: {}", e.what()));
  }
}

}  // namespace

PolishJob ReadPolishJob(const std::filesystem::path& path,
                        const std::optional<std::filesystem::path>& error_map_override) {
  const json document = ReadJsonFile(path, kJobStage);
  PolishJob job;
  job.source = path;
  JsonSection s(document, {.file = path.string(), .stage = kJobStage, .docs_page = "docs/polishing.md"});
  std::vector<std::string> problems;  // every range problem, reported together at the end
  job.name = s.String("name", path.stem().string());
  s.Section("surface", true, [&](JsonSection& c) {
    job.surface = surfaces::ReadSurface(c, {"even_asphere", "xy_polynomial"});
  });
  s.Section("aperture", true, [&](JsonSection& c) { job.aperture = surfaces::ReadAperture(c); });
  s.Section("error_map", true, [&](JsonSection& c) {
    const std::string file = c.String("file", "");
    if (error_map_override) {
      job.error_map_file = *error_map_override;
      c.SetResolved("file", job.error_map_file.string());
    } else {
      if (file.empty()) c.Expected("file", "the error map's file name (.csv, .dat, .datx or .h5)");
      job.error_map_file =
          std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : path.parent_path() / file;
    }
    job.error_map = ReadErrorMapSection(c, job.error_map_file);
  });
  s.Section("removal_target", false,
            [&](JsonSection& c) { job.target.uniform_layer_um = c.Number("uniform_layer_um", 0.0); });
  s.Section("removal_function", true,
            [&](JsonSection& c) { job.removal = ReadRemovalFunctionSection(c, path, problems); });
  s.Section("path", false, [&](JsonSection& c) { ReadPath(c, job); });
  s.Section("machine", true, [&](JsonSection& c) { ReadMachine(c, job); });
  s.Section("solver", false, [&](JsonSection& c) {
    const DwellOptions defaults;
    job.dwell.max_iterations = c.WholeNumber("max_iterations", defaults.max_iterations, 1, 10'000'000);
    job.dwell.relative_tolerance = c.Number("relative_tolerance", defaults.relative_tolerance);
  });
  s.Section("tool", false, [&](JsonSection& c) { ReadTool(c, job); });
  if (s.Has("precession")) s.Section("precession", false, [&](JsonSection& c) { ReadPrecession(c, job); });
  s.Section("workobject", false, [&](JsonSection& c) {
    const std::vector<double> origin = c.Numbers("origin_mm", {0.0, 0.0, 0.0});
    job.work_object.origin_mm = {origin[0], origin[1], origin[2]};
    job.work_object.orientation = ReadQuaternion(c, "quaternion");
  });
  std::vector<std::string> robot_problems;
  if (s.Has("robot"))
    s.Section("robot", false, [&](JsonSection& c) { ReadRobot(c, path, job, robot_problems); });
  s.Finish();
  // The path's defaults come from the removal function's width: with a bad width (already in
  // `problems`) they would only repeat it.
  const bool removal_usable = problems.empty();
  for (std::vector<std::string> more :
       {job.target.Problems(), removal_usable ? job.path.Problems() : std::vector<std::string>{},
        job.dwell.Problems(), job.tool.Problems(), job.precession.Problems(), robot_problems}) {
    problems.insert(problems.end(), more.begin(), more.end());
  }
  s.ThrowIfProblems(problems);
  s.ThrowIfProblems(SizeProblems(job));
  job.resolved_json = JsonText(s.resolved());
  return job;
}

double PathPointCount(const surfaces::Aperture& aperture, const RasterOptions& o, PathPattern pattern) {
  const bool circle = aperture.shape == surfaces::Aperture::Shape::kCircle;
  const double half_x = aperture.HalfX() + o.extension_mm, half_y = aperture.HalfY() + o.extension_mm;
  if (pattern == PathPattern::kSpiral) {
    // As SpiralPath: the arc length of r = b theta out to the grown aperture's radius, in steps.
    const double radius = circle ? half_y : std::hypot(half_x, half_y);
    const double b = o.line_spacing_mm / (2.0 * std::numbers::pi), theta = radius / b;
    const double length = 0.5 * b * (theta * std::sqrt(1.0 + theta * theta) + std::asinh(theta));
    return std::max(1.0, std::ceil(length / o.point_spacing_mm - 1e-9)) + 1.0;
  }
  // As RasterPath: lines across the grown height, each at most the grown width long.
  const double lines = std::ceil(2.0 * half_y / o.line_spacing_mm - 1e-9) + 1.0;
  const double widest = circle ? half_y : half_x;
  return lines * (std::max(1.0, std::ceil(2.0 * widest / o.point_spacing_mm - 1e-9)) + 1.0);
}

std::vector<std::string> SizeProblems(const PolishJob& job) {
  // Each dwell point holds a column of the removal matrix, reserved as the removal function's
  // footprint box on the map's grid.
  const FootprintBox box = job.removal.Footprint();
  const surfaces::GridSpec& grid = job.error_map.grid;
  const double box_x_mm = box.max_x_mm - box.min_x_mm, box_y_mm = box.max_y_mm - box.min_y_mm;
  const double entries = std::ceil(box_x_mm / grid.dx_mm + 1.0) * std::ceil(box_y_mm / grid.dy_mm + 1.0);
  const double points = PathPointCount(job.aperture, job.path, job.path_pattern);
  std::optional<std::string> problem = MemoryBudgetProblem(
      fmt::format("path.line_spacing_mm = {}, path.point_spacing_mm = {}", job.path.line_spacing_mm,
                  job.path.point_spacing_mm),
      points, "dwell points", kBytesPerDwellPoint + kBytesPerRemovalMatrixEntry * entries);
  if (!problem) return {};
  return {*problem +
          fmt::format(" (a dwell point holds {:.3g} B and {:.3g} removal-matrix entries of {:g} B: the "
                      "removal function's {:g} x {:g} mm footprint on the map's {:g} x {:g} mm grid)",
                      kBytesPerDwellPoint, entries, kBytesPerRemovalMatrixEntry, box_x_mm, box_y_mm,
                      grid.dx_mm, grid.dy_mm)};
}

namespace {

void CheckOnSurface(const PolishJob& job, std::span<const Eigen::Vector2d> path) {
  const ErrorMap& m = job.error_map;
  for (int j = 0; j < m.grid.ny; ++j) {
    for (int i = 0; i < m.grid.nx; ++i) {
      if (!std::isfinite(m.At(i, j)) || !job.aperture.Contains(m.grid.X(i), m.grid.Y(j))) continue;
      if (!job.surface->InDomain(m.grid.X(i), m.grid.Y(j))) {
        throw Error(
            ErrorCode::kBadInput, kJobStage,
            fmt::format("map off the surface: '{}' node ({}, {}) mm lies outside {}",
                        job.error_map_file.string(), m.grid.X(i), m.grid.Y(j), job.surface->Describe()));
      }
    }
  }
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (!job.surface->InDomain(path[k].x(), path[k].y())) {
      throw Error(ErrorCode::kBadInput, kJobStage,
                  fmt::format("'{}': path point {} ({}, {}) mm (aperture grown by path.extension_mm = {}) "
                              "is off the surface {}",
                              job.source.string(), k, path[k].x(), path[k].y(), job.path.extension_mm,
                              job.surface->Describe()));
    }
  }
}

std::string ResidualCsv(const ErrorMap& target, const DwellSolution& d) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "{}\n", fmt::join(schema::polish::residual_map::kColumns, ","));
  for (int j = 0; j < target.grid.ny; ++j) {
    for (int i = 0; i < target.grid.nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * target.grid.nx + i;
      if (!std::isfinite(d.residual_um.error_um[k])) continue;
      fmt::format_to(std::back_inserter(out), "{},{},{},{},{}\n", target.grid.X(i), target.grid.Y(j),
                     target.error_um[k], d.predicted_removal_um.error_um[k], d.residual_um.error_um[k]);
    }
  }
  return fmt::to_string(out);
}

}  // namespace

namespace {

// The path, its dwell and the points the robot runs, before anything is written.
struct Plan {
  ErrorMap target;
  PolishRunReport report;
  std::vector<PolishingPoint> points;
};

// The prediction, residual and times of the targets as the robot runs them: each target's dwell
// at its own contact point. Used where the targets are not the dwell points.
void PredictFromTargets(const PolishJob& job, Plan& plan) {
  std::vector<Eigen::Vector2d> contact;
  std::vector<double> dwell_s;
  DwellSolution& d = plan.report.dwell;
  std::fill(d.dwell_s.begin(), d.dwell_s.end(), 0.0);
  for (const PolishingPoint& p : plan.points) {
    contact.push_back(p.contact_xy_mm);
    dwell_s.push_back(p.dwell_s);
    d.dwell_s[p.dwell_point] += p.dwell_s;
  }
  d.predicted_removal_um = RemovalOfDwell(plan.target, job.aperture, contact, dwell_s, job.removal);
  d.residual_um = d.predicted_removal_um;
  for (std::size_t k = 0; k < d.residual_um.error_um.size(); ++k)
    d.residual_um.error_um[k] = plan.target.error_um[k] - d.predicted_removal_um.error_um[k];
  d.after = StatisticsInAperture(d.residual_um, job.aperture);
  d.total_time_s = 0.0;
  for (const double t : dwell_s) d.total_time_s += t;
}

void TargetSpeeds(Plan& plan) {
  const auto speed = [](const PolishingPoint& a, const PolishingPoint& b) {
    return a.speed_mm_s < b.speed_mm_s;
  };
  plan.report.points = plan.points.size();
  plan.report.max_speed_mm_s =
      std::max_element(plan.points.begin() + 1, plan.points.end(), speed)->speed_mm_s;
  plan.report.min_speed_mm_s =
      std::min_element(plan.points.begin() + 1, plan.points.end(), speed)->speed_mm_s;
}

Plan MakePlan(const PolishJob& job) {
  const std::vector<Eigen::Vector2d> path = job.path_pattern == PathPattern::kSpiral
                                                ? SpiralPath(job.aperture, job.path)
                                                : RasterPath(job.aperture, job.path);
  CheckOnSurface(job, path);
  Plan plan;
  plan.target = RemovalTarget(job.error_map, job.aperture, job.target);
  PolishRunReport& report = plan.report;
  // The dwell is the time the robot takes on each TCP chord, precession included.
  const std::vector<double> chord_mm = TcpChordsMm(TcpPositionsMm(*job.surface, path, job.precession));
  report.dwell = SolveDwell(plan.target, job.aperture, path, chord_mm, job.removal, job.dwell);
  plan.points = BuildPolishingPath(*job.surface, path, report.dwell, job.robot_side, job.precession);
  if (plan.points.size() != path.size()) PredictFromTargets(job, plan);
  TargetSpeeds(plan);
  return plan;
}

std::vector<double> SegmentTimes(std::span<const PolishingPoint> points) {
  std::vector<double> out;
  out.reserve(points.size());
  for (const PolishingPoint& p : points) out.push_back(p.dwell_s);
  return out;
}

std::vector<Eigen::Vector3d> TargetPositions(std::span<const PolishingPoint> points) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(points.size());
  for (const PolishingPoint& p : points) out.push_back(p.position_mm);
  return out;
}

json SlowedJson(const TimeScaling& scaling) {
  namespace key = schema::polish::summary::robot::slowed_segments;
  json out = json::array();
  for (const SlowedSegment& s : scaling.slowed) {
    out.push_back({{key::kTarget, s.target + 1},
                   {key::kJoint, s.joint},
                   {key::kPlannedS, s.planned_s},
                   {key::kSlowedS, s.slowed_s}});
  }
  return out;
}

std::string RobotJointsCsv(const RobotPath& robot) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "{}\n", fmt::join(schema::polish::robot_joints::kColumns, ","));
  for (std::size_t k = 0; k < robot.joints_rad.size(); ++k) {
    const JointAngles& q = robot.joints_rad[k];
    constexpr double kDeg = 180.0 / std::numbers::pi;
    fmt::format_to(std::back_inserter(out), "{},{},{},{},{},{},{}\n", k + 1, q[0] * kDeg, q[1] * kDeg,
                   q[2] * kDeg, q[3] * kDeg, q[4] * kDeg, q[5] * kDeg);
  }
  return fmt::to_string(out);
}

}  // namespace

WorkObjectProposal ProposeWorkObject(const PolishJob& job) {
  if (!job.robot_kinematics) {
    throw Error(ErrorCode::kInvalidOption, kJobStage,
                fmt::format("'{}': --place-workobject needs a robot: the job has no \"robot\" section "
                            "(docs/polishing.md, \"Robot\")",
                            job.source.string()));
  }
  const Plan plan = MakePlan(job);
  return ProposeWorkObjectOrigin(*job.robot_kinematics, job.robot.margins, plan.points, job.tool,
                                 job.work_object, job.robot.world_from_base, SegmentTimes(plan.points),
                                 job.source.string());
}

std::string DescribeProposal(const WorkObjectProposal& proposal, const PolishJob& job) {
  const RobotPath& r = proposal.path;
  const RobotMargins& m = job.robot.margins;
  std::string out = fmt::format(
      "{}: work-object origin [{:.1f}, {:.1f}, {:.1f}] mm (world frame; orientation as in the job) runs the "
      "path in arm configuration cfx {} ({} origins tried)\n"
      "set \"workobject\": {{\"origin_mm\": [{:.1f}, {:.1f}, {:.1f}]}}\n",
      job.robot.model->name, proposal.origin_mm.x(), proposal.origin_mm.y(), proposal.origin_mm.z(),
      r.branch.Cfx(), proposal.candidates, proposal.origin_mm.x(), proposal.origin_mm.y(),
      proposal.origin_mm.z());
  for (int i = 0; i < kRobotJoints; ++i) {
    const auto n = static_cast<std::size_t>(i);
    out += fmt::format(
        "joint {}: limits {:.0f} .. {:.0f} deg, smallest margin {:.2f} deg (at least {}), largest "
        "speed {:.3f} of its maximum (at most {})\n",
        i + 1, r.limits_deg[n][0], r.limits_deg[n][1], r.min_limit_margin_deg[n], m.min_joint_margin_deg,
        r.max_speed_ratio[n], m.max_joint_speed_ratio);
  }
  out += fmt::format("wrist singularity: |joint 5| >= {:.2f} deg (at least {})\n", r.wrist_margin_deg,
                     m.min_wrist_margin_deg);
  return out;
}

PolishRunReport RunPolishJob(const PolishJob& job, const std::filesystem::path& output_folder) {
  Plan plan = MakePlan(job);
  const ErrorMap& target = plan.target;
  PolishRunReport& report = plan.report;
  if (job.robot_kinematics) {
    // Refused here, before anything is written, when the robot cannot run the path. First the
    // joints without their speeds (over an unbounded time no joint is too fast), then the
    // segments a joint cannot run at the dwell's speed slowed to what it can, then every check.
    const std::string name = job.source.string();
    const std::vector<Eigen::Isometry3d> poses =
        FlangePosesInBase(plan.points, job.tool, job.work_object, job.robot.world_from_base);
    const std::vector<Eigen::Vector3d> targets = TargetPositions(plan.points);
    const std::vector<double> unbounded(plan.points.size(), std::numeric_limits<double>::infinity());
    const RobotPath joints =
        SolveRobotPath(*job.robot_kinematics, job.robot.margins, poses, unbounded, name, targets);
    report.slowing = SlowDownToJointSpeeds(plan.points, *job.robot_kinematics, joints, target, job.aperture,
                                           job.removal, job.robot.margins, name);
    if (!report.slowing.slowed.empty()) {
      PredictFromTargets(job, plan);
      TargetSpeeds(plan);
    }
    report.robot = SolveRobotPath(*job.robot_kinematics, job.robot.margins, poses, SegmentTimes(plan.points),
                                  name, targets);
  }
  const std::vector<PolishingPoint>& points = plan.points;

  const std::vector<std::string> comments = {fmt::format("arcwheel {} polish, job '{}'", kVersion, job.name),
                                             fmt::format("surface: {}", job.surface->Describe()),
                                             fmt::format("aperture: {}", job.aperture.Describe()),
                                             fmt::format("removal function: {}", job.removal.Describe())};
  std::vector<std::string> program_comments = comments;
  if (report.robot) {
    program_comments.push_back(
        fmt::format("robot: {}, arm configuration cfx {} held along the path (ConfL \\On)",
                    job.robot.model->name, report.robot->branch.Cfx()));
  }
  namespace key = schema::polish::summary;
  const auto figures = [](const auto& f) {
    return json{{key::figures::kPvUm, f.pv_um}, {key::figures::kRmsUm, f.rms_um}};
  };
  json summary = {
      {key::kSchemaVersion, schema::VersionText(schema::polish::kVersion)},
      {key::kArcwheelVersion, kVersion},
      {key::kJob, ParseJsonText(job.resolved_json, "the resolved job", kJobStage)},
      {key::kPoints, report.points},
      {key::kTotalTimeS, report.dwell.total_time_s},
      {key::kBefore, figures(report.dwell.before)},
      {key::kAfter, figures(report.dwell.after)},
      {key::kApertureNodes, report.dwell.before.nodes},
      {key::kSpeedMmS,
       {{key::speed_mm_s::kMin, report.min_speed_mm_s}, {key::speed_mm_s::kMax, report.max_speed_mm_s}}},
      {key::kMaxAccelerationMmS2, report.dwell.max_acceleration_mm_s2},
      {key::kSolver,
       {{key::solver::kIterations, report.dwell.iterations},
        {key::solver::kConverged, report.dwell.converged},
        {key::solver::kNonzeros, report.dwell.nonzeros},
        {key::solver::kShapingRounds, report.dwell.shaping_rounds}}}};
  if (report.robot) {
    const RobotPath& r = *report.robot;
    summary[key::kRobot] = {{key::robot::kModel, job.robot.model->name},
                            {key::robot::kCfx, r.branch.Cfx()},
                            {key::robot::kMinLimitMarginDeg, r.min_limit_margin_deg},
                            {key::robot::kWristMarginDeg, r.wrist_margin_deg},
                            {key::robot::kMaxJointSpeedRatio, r.max_speed_ratio},
                            {key::robot::kLargestJointSpeedRatio, r.largest_speed_ratio},
                            {key::robot::kLargestJointSpeedJoint, r.largest_speed_joint},
                            {key::robot::kLimitsDeg, r.limits_deg},
                            {key::robot::kSlowedSegments, SlowedJson(report.slowing)},
                            {key::robot::kAddedTimeS, report.slowing.added_time_s},
                            {key::robot::kAddedRemoval,
                             {{key::robot::added_removal::kPvNm, report.slowing.added.pv_nm},
                              {key::robot::added_removal::kRmsNm, report.slowing.added.rms_nm},
                              {key::robot::added_removal::kMaxNm, report.slowing.added.max_nm},
                              {key::robot::added_removal::kMaxAtMm,
                               {report.slowing.added.max_at_mm.x(), report.slowing.added.max_at_mm.y()}}}}};
  }

  OutputSet outputs;
  outputs.CreateFolder(output_folder);
  auto write = [&](std::string_view name, const std::string& text) {
    const std::filesystem::path temporary = outputs.Stage(output_folder / name);
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw Error(ErrorCode::kIo, kJobStage, fmt::format("cannot write '{}'", temporary.string()));
  };
  write(schema::polish::kPathFileName, PolishingPathCsv(points, comments));
  write("polish.mod", RapidModule(points, job.tool, job.work_object, "ArcwheelPolish", program_comments,
                                  report.robot ? std::span<const std::array<int, 4>>(report.robot->confdata)
                                               : std::span<const std::array<int, 4>>()));
  if (report.robot) write(schema::polish::kRobotJointsFileName, RobotJointsCsv(*report.robot));
  write(schema::polish::kResidualMapFileName, ResidualCsv(target, report.dwell));
  {
    // The residual as a grid map (schema/grid_map.h): an error map for the next polish run.
    schema::grid_map::Content residual =
        GridMapContent(report.dwell.residual_um, schema::grid_map::kPolishResidual);
    residual.layers = {
        {std::string(schema::grid_map::kTargetUm), target.error_um},
        {std::string(schema::grid_map::kRemovalUm), report.dwell.predicted_removal_um.error_um}};
    residual.figures = {{std::string(schema::grid_map::kPvUmAttribute), report.dwell.after.pv_um},
                        {std::string(schema::grid_map::kRmsUmAttribute), report.dwell.after.rms_um}};
    schema::grid_map::WriteGridMap(residual,
                                   outputs.Stage(output_folder / schema::polish::kResidualGridFileName));
  }
  write(schema::polish::kSummaryFileName, JsonText(summary, 2) + "\n");
  outputs.Commit();
  return report;
}

}  // namespace arcwheel::polishing
