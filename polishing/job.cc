#include "polishing/job.h"

#include <fmt/core.h>
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <utility>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/version.h"

namespace arcwheel::polishing {
namespace {

using nlohmann::json;
constexpr const char* kStage = "polishing.job";

// One JSON object of the job: typed reads by key, remembered for the unknown-key check.
class Section {
 public:
  Section(const json* object, std::string prefix, const std::filesystem::path& source)
      : object_(object), prefix_(std::move(prefix)), source_(source) {
    if (object_ != nullptr && !object_->is_object()) Fail("", "must be an object");
  }
  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    throw Error(ErrorCode::kBadInput, kStage,
                fmt::format("'{}': '{}' {}", source_.string(), Dotted(key), what));
  }
  [[nodiscard]] bool Has(const std::string& key) const {
    return object_ != nullptr && object_->contains(key);
  }
  double Number(const std::string& key, double fallback) {
    used_.insert(key);
    double v = fallback;
    if (Has(key)) {
      if (!object_->at(key).is_number() || !std::isfinite(object_->at(key).get<double>()))
        Fail(key, "must be a finite number");
      v = object_->at(key).get<double>();
    }
    resolved_[key] = v;
    return v;
  }
  // A count or power: checked as a double first, so 2.5 is refused rather than used as 2 and a
  // value beyond int's range is never cast (undefined behaviour).
  int WholeNumber(const std::string& key, int fallback, int low, int high) {
    const double v = Number(key, fallback);
    if (!(v >= low && v <= high) || v != std::floor(v)) {
      Fail(key, fmt::format("must be a whole number within {} .. {}, got {}", low, high, v));
    }
    return static_cast<int>(v);
  }
  double RequiredNumber(const std::string& key) {
    if (!Has(key)) Fail(key, "is required");
    return Number(key, 0.0);
  }
  std::vector<double> Numbers(const std::string& key, std::vector<double> fallback) {
    used_.insert(key);
    if (Has(key)) {
      const json& v = object_->at(key);
      if (!v.is_array() || (!fallback.empty() && v.size() != fallback.size())) {
        Fail(key, fmt::format("must be an array of {} numbers", fallback.size()));
      }
      fallback.clear();
      for (const json& e : v) {
        if (!e.is_number() || !std::isfinite(e.get<double>())) Fail(key, "must hold finite numbers only");
        fallback.push_back(e.get<double>());
      }
    }
    resolved_[key] = fallback;
    return fallback;
  }
  std::string String(const std::string& key, const std::string& fallback) {
    used_.insert(key);
    std::string v = fallback;
    if (Has(key)) {
      if (!object_->at(key).is_string()) Fail(key, "must be a string");
      v = object_->at(key).get<std::string>();
    }
    resolved_[key] = v;
    return v;
  }
  std::string Choice(const std::string& key, const std::vector<std::string>& allowed) {
    const std::string v = String(key, allowed.front());
    if (std::find(allowed.begin(), allowed.end(), v) == allowed.end()) {
      Fail(key, fmt::format("= \"{}\" is not one of \"{}\"", v, fmt::join(allowed, "\", \"")));
    }
    return v;
  }
  Section Child(const std::string& key) {
    used_.insert(key);
    return Section(Has(key) ? &object_->at(key) : nullptr, Dotted(key), source_);
  }
  void Adopt(const std::string& key, const Section& child) { resolved_[key] = child.resolved_; }
  void SetResolved(const std::string& key, const json& value) { resolved_[key] = value; }
  [[nodiscard]] const json& Raw(const std::string& key) {
    used_.insert(key);
    return object_->at(key);
  }
  [[nodiscard]] const std::filesystem::path& source() const { return source_; }
  void Finish() const {
    if (object_ == nullptr) return;
    for (const auto& [key, value] : object_->items()) {
      if (!used_.count(key)) Fail(key, "is an unknown key (see docs/polishing.md for the job keys)");
    }
  }
  [[nodiscard]] const json& resolved() const { return resolved_; }
  [[nodiscard]] std::string Dotted(const std::string& key) const {
    return prefix_.empty() ? key : (key.empty() ? prefix_ : prefix_ + "." + key);
  }

 private:
  const json* object_;
  std::string prefix_;
  const std::filesystem::path& source_;
  std::set<std::string> used_;
  json resolved_ = json::object();
};

std::shared_ptr<const surfaces::Surface> ReadSurface(Section& s) {
  const std::string type = s.Choice("type", {"even_asphere", "xy_polynomial"});
  if (type == "xy_polynomial") {
    // The same form as the grinding job: [{"x_power": i, "y_power": j, "coefficient": c}, ...].
    if (!s.Has("terms") || !s.Raw("terms").is_array()) {
      s.Fail("terms", "must be an array of {\"x_power\", \"y_power\", \"coefficient\"} objects");
    }
    std::vector<surfaces::XyPolynomialTerm> terms;
    json resolved = json::array();
    for (std::size_t k = 0; k < s.Raw("terms").size(); ++k) {
      Section t(&s.Raw("terms")[k], s.Dotted(fmt::format("terms[{}]", k)), s.source());
      surfaces::XyPolynomialTerm term;
      term.x_power = t.WholeNumber("x_power", 0, 0, 20);
      term.y_power = t.WholeNumber("y_power", 0, 0, 20);
      term.coefficient = t.RequiredNumber("coefficient");
      t.Finish();
      terms.push_back(term);
      resolved.push_back(t.resolved());
    }
    s.SetResolved("terms", resolved);
    return std::make_shared<surfaces::XyPolynomial>(std::move(terms));
  }
  surfaces::EvenAsphereParameters p;
  p.vertex_radius_mm = s.RequiredNumber("vertex_radius_mm");
  if (!(p.vertex_radius_mm > 0.0)) s.Fail("vertex_radius_mm", "must be > 0 (use \"form\" for the side)");
  p.conic = s.Number("conic", 0.0);
  if (s.Has("coefficients")) {
    // The same form as the grinding job: {"A4": ..., "A6": ..., ..., "A20": ...}.
    Section c = s.Child("coefficients");
    for (int order = 4; order <= 20; order += 2)
      p.even_coefficients.push_back(c.Number(fmt::format("A{}", order), 0.0));
    while (!p.even_coefficients.empty() && p.even_coefficients.back() == 0.0) p.even_coefficients.pop_back();
    c.Finish();
    s.Adopt("coefficients", c);
  }
  const std::vector<double> off = s.Numbers("off_axis_mm", {0.0, 0.0});
  p.off_axis_x_mm = off[0];
  p.off_axis_y_mm = off[1];
  p.concave = s.Choice("form", {"concave", "convex"}) == "concave";
  try {
    return std::make_shared<surfaces::EvenAsphere>(p);
  } catch (const Error& e) {
    s.Fail("", fmt::format("is not usable: {}", e.what()));
  }
}

surfaces::Aperture ReadAperture(Section& s) {
  surfaces::Aperture a;
  if (s.Choice("shape", {"circle", "rectangle"}) == "circle") {
    a.shape = surfaces::Aperture::Shape::kCircle;
    a.diameter_mm = s.RequiredNumber("diameter_mm");
    if (!(a.diameter_mm > 0.0)) s.Fail("diameter_mm", "must be > 0");
  } else {
    const std::vector<double> size = s.Numbers("size_mm", {0.0, 0.0});
    if (!(size[0] > 0.0) || !(size[1] > 0.0)) s.Fail("size_mm", "must be two sizes > 0");
    a.width_x_mm = size[0];
    a.width_y_mm = size[1];
  }
  return a;
}

AbbQuaternion ReadQuaternion(Section& s, const std::string& key) {
  const std::vector<double> q = s.Numbers(key, {1.0, 0.0, 0.0, 0.0});
  const double norm = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  if (std::abs(norm - 1.0) > 1e-6)
    s.Fail(key, fmt::format("must be a unit quaternion (q1 scalar first), has norm {}", norm));
  return {q[0] / norm, q[1] / norm, q[2] / norm, q[3] / norm};
}

void ReadMachine(Section& s, PolishJob& job) {
  job.dwell.max_speed_mm_s = s.RequiredNumber("max_speed_mm_s");
  if (!(job.dwell.max_speed_mm_s > 0.0)) s.Fail("max_speed_mm_s", "must be > 0");
  job.dwell.min_speed_mm_s = s.Number("min_speed_mm_s", 0.0);
  if (!(job.dwell.min_speed_mm_s >= 0.0 && job.dwell.min_speed_mm_s <= job.dwell.max_speed_mm_s)) {
    s.Fail("min_speed_mm_s", fmt::format("= {} is unreachable: it must lie in [0, max_speed_mm_s = {}]",
                                         job.dwell.min_speed_mm_s, job.dwell.max_speed_mm_s));
  }
  job.dwell.min_dwell_s = s.Number("min_dwell_s", 0.0);
  if (!(job.dwell.min_dwell_s >= 0.0)) s.Fail("min_dwell_s", "must be >= 0");
  if (job.dwell.min_dwell_s > 0.0 && job.dwell.min_speed_mm_s > 0.0) {
    s.Fail("min_dwell_s", "is unreachable together with min_speed_mm_s: give one of them");
  }
  job.dwell.max_acceleration_mm_s2 = s.Number("max_acceleration_mm_s2", 0.0);
  if (!(job.dwell.max_acceleration_mm_s2 >= 0.0))
    s.Fail("max_acceleration_mm_s2", "must be >= 0 (0 = no limit)");
  job.robot_side = s.Choice("robot_side", {"+x", "-x"}) == "+x" ? RobotSide::kPlusX : RobotSide::kMinusX;
}

void ReadTool(Section& s, PolishJob& job) {
  const std::vector<double> tcp = s.Numbers("tcp_mm", {0.0, 0.0, 150.0});
  job.tool.tcp_mm = {tcp[0], tcp[1], tcp[2]};
  job.tool.orientation = ReadQuaternion(s, "quaternion");
  const std::vector<double> offset = s.Numbers("removal_centre_offset_mm", {0.0, 0.0});
  job.tool.removal_centre_offset_mm = {offset[0], offset[1]};
  job.tool.mass_kg = s.Number("mass_kg", 5.0);
  if (!(job.tool.mass_kg > 0.0)) s.Fail("mass_kg", "must be > 0");
  const std::vector<double> cog = s.Numbers("centre_of_gravity_mm", {0.0, 0.0, 75.0});
  job.tool.centre_of_gravity_mm = {cog[0], cog[1], cog[2]};
}

// The error_map section: the file, its format and, for interferometer maps, the placement in the
// part frame (docs/polishing.md, "Error-map formats").
ErrorMap ReadErrorMapSection(Section& s, const std::filesystem::path& file) {
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
    if (options.layout == ErrorMapLayout::kScattered) s.SetResolved("grid_spacing_mm", map.dx_mm);
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

}  // namespace

PolishJob ReadPolishJob(const std::filesystem::path& path) {
  json root = ReadJsonFile(path, kStage);
  PolishJob job;
  job.source = path;
  Section s(&root, "", path);
  job.name = s.String("name", path.stem().string());
  auto section = [&](const std::string& key, auto&& read) {
    if (!s.Has(key) && key != "removal_target" && key != "path" && key != "solver" && key != "tool" &&
        key != "workobject" && key != "precession") {
      s.Fail(key, "is required");
    }
    Section child = s.Child(key);
    read(child);
    child.Finish();
    s.Adopt(key, child);
  };
  section("surface", [&](Section& c) { job.surface = ReadSurface(c); });
  section("aperture", [&](Section& c) { job.aperture = ReadAperture(c); });
  section("error_map", [&](Section& c) {
    const std::string file = c.String("file", "");
    if (file.empty()) c.Fail("file", "is required: the error map (.csv, .dat, .datx or .h5)");
    job.error_map_file =
        std::filesystem::path(file).is_absolute() ? std::filesystem::path(file) : path.parent_path() / file;
    job.error_map = ReadErrorMapSection(c, job.error_map_file);
  });
  section("removal_target", [&](Section& c) {
    job.target.uniform_layer_um = c.Number("uniform_layer_um", 0.0);
    if (!(job.target.uniform_layer_um >= 0.0)) c.Fail("uniform_layer_um", "must be >= 0");
  });
  section("removal_function", [&](Section& c) {
    if (c.Has("file")) {
      if (c.Has("peak_rate_um_per_s") || c.Has("fwhm_mm")) {
        c.Fail("file", "is an alternative to peak_rate_um_per_s and fwhm_mm: give one or the other");
      }
      const std::filesystem::path file = c.String("file", "");
      job.removal = ReadRemovalFunction(file.is_absolute() ? file : path.parent_path() / file);
      return;
    }
    GaussianRemovalFunction gaussian;
    gaussian.peak_rate_um_per_s = c.RequiredNumber("peak_rate_um_per_s");
    if (!(gaussian.peak_rate_um_per_s > 0.0)) c.Fail("peak_rate_um_per_s", "must be > 0");
    gaussian.fwhm_mm = c.RequiredNumber("fwhm_mm");
    if (!(gaussian.fwhm_mm > 0.0)) c.Fail("fwhm_mm", "must be > 0");
    job.removal = gaussian;
  });
  section("path", [&](Section& c) {
    job.path_pattern =
        c.Choice("type", {"raster", "spiral"}) == "spiral" ? PathPattern::kSpiral : PathPattern::kRaster;
    // Defaults from the removal function's (equivalent) width: see removal_function.h.
    job.path.line_spacing_mm = c.Number("line_spacing_mm", job.removal.EquivalentFwhmMm() / 5.0);
    if (!(job.path.line_spacing_mm > 0.0)) c.Fail("line_spacing_mm", "must be > 0");
    job.path.point_spacing_mm = c.Number("point_spacing_mm", job.path.line_spacing_mm);
    if (!(job.path.point_spacing_mm > 0.0)) c.Fail("point_spacing_mm", "must be > 0");
    job.path.extension_mm = c.Number("extension_mm", 1.75 * job.removal.EquivalentSigmaMm());
    if (!(job.path.extension_mm >= 0.0)) c.Fail("extension_mm", "must be >= 0");
  });
  section("machine", [&](Section& c) { ReadMachine(c, job); });
  section("solver", [&](Section& c) {
    const DwellOptions defaults;
    job.dwell.max_iterations = c.WholeNumber("max_iterations", defaults.max_iterations, 1, 10'000'000);
    job.dwell.relative_tolerance = c.Number("relative_tolerance", defaults.relative_tolerance);
    if (!(job.dwell.relative_tolerance > 0.0)) c.Fail("relative_tolerance", "must be > 0");
  });
  section("tool", [&](Section& c) { ReadTool(c, job); });
  if (s.Has("precession")) {
    section("precession", [&](Section& c) {
      job.precession.enabled = true;
      job.precession.tilt_deg = c.RequiredNumber("tilt_deg");
      if (!(job.precession.tilt_deg >= 0.0 && job.precession.tilt_deg < 90.0))
        c.Fail("tilt_deg", "must lie in [0, 90)");
      job.precession.precession_rate_rpm = c.RequiredNumber("precession_rate_rpm");
      job.precession.bonnet_radius_mm = c.Number("bonnet_radius_mm", 0.0);
      if (!(job.precession.bonnet_radius_mm >= 0.0)) c.Fail("bonnet_radius_mm", "must be >= 0");
    });
  }
  section("workobject", [&](Section& c) {
    const std::vector<double> origin = c.Numbers("origin_mm", {0.0, 0.0, 0.0});
    job.work_object.origin_mm = {origin[0], origin[1], origin[2]};
    job.work_object.orientation = ReadQuaternion(c, "quaternion");
  });
  s.Finish();
  job.resolved = s.resolved();
  return job;
}

namespace {

void CheckOnSurface(const PolishJob& job, std::span<const Eigen::Vector2d> path) {
  const ErrorMap& m = job.error_map;
  for (int j = 0; j < m.ny; ++j) {
    for (int i = 0; i < m.nx; ++i) {
      if (!std::isfinite(m.At(i, j)) || !job.aperture.Contains(m.X(i), m.Y(j))) continue;
      if (!job.surface->InDomain(m.X(i), m.Y(j))) {
        throw Error(ErrorCode::kBadInput, kStage,
                    fmt::format("map off the surface: '{}' node ({}, {}) mm lies outside {}",
                                job.error_map_file.string(), m.X(i), m.Y(j), job.surface->Describe()));
      }
    }
  }
  for (std::size_t k = 0; k < path.size(); ++k) {
    if (!job.surface->InDomain(path[k].x(), path[k].y())) {
      throw Error(ErrorCode::kBadInput, kStage,
                  fmt::format("'{}': path point {} ({}, {}) mm (aperture grown by path.extension_mm = {}) "
                              "is off the surface {}",
                              job.source.string(), k, path[k].x(), path[k].y(), job.path.extension_mm,
                              job.surface->Describe()));
    }
  }
}

std::string ResidualCsv(const ErrorMap& target, const DwellSolution& d) {
  fmt::memory_buffer out;
  fmt::format_to(std::back_inserter(out), "x_mm,y_mm,target_um,removal_um,residual_um\n");
  for (int j = 0; j < target.ny; ++j) {
    for (int i = 0; i < target.nx; ++i) {
      const std::size_t k = static_cast<std::size_t>(j) * target.nx + i;
      if (!std::isfinite(d.residual_um.error_um[k])) continue;
      fmt::format_to(std::back_inserter(out), "{},{},{},{},{}\n", target.X(i), target.Y(j),
                     target.error_um[k], d.predicted_removal_um.error_um[k], d.residual_um.error_um[k]);
    }
  }
  return fmt::to_string(out);
}

}  // namespace

PolishRunReport RunPolishJob(const PolishJob& job, const std::filesystem::path& output_folder) {
  const std::vector<Eigen::Vector2d> path = job.path_pattern == PathPattern::kSpiral
                                                ? SpiralPath(job.aperture, job.path)
                                                : RasterPath(job.aperture, job.path);
  CheckOnSurface(job, path);
  const ErrorMap target = RemovalTarget(job.error_map, job.aperture, job.target);
  PolishRunReport report;
  report.dwell = SolveDwell(target, job.aperture, path, job.removal, job.dwell);
  const std::vector<PolishingPoint> points =
      BuildPolishingPath(*job.surface, path, report.dwell, job.robot_side, job.precession);
  report.points = points.size();
  report.max_speed_mm_s =
      *std::max_element(report.dwell.speed_mm_s.begin() + 1, report.dwell.speed_mm_s.end());
  report.min_speed_mm_s =
      *std::min_element(report.dwell.speed_mm_s.begin() + 1, report.dwell.speed_mm_s.end());

  const std::vector<std::string> comments = {fmt::format("arcwheel {} polish, job '{}'", kVersion, job.name),
                                             fmt::format("surface: {}", job.surface->Describe()),
                                             fmt::format("aperture: {}", job.aperture.Describe()),
                                             fmt::format("removal function: {}", job.removal.Describe())};
  json summary = {{"arcwheel_version", kVersion},
                  {"job", job.resolved},
                  {"points", report.points},
                  {"total_time_s", report.dwell.total_time_s},
                  {"before", {{"pv_um", report.dwell.before.pv_um}, {"rms_um", report.dwell.before.rms_um}}},
                  {"after", {{"pv_um", report.dwell.after.pv_um}, {"rms_um", report.dwell.after.rms_um}}},
                  {"aperture_nodes", report.dwell.before.nodes},
                  {"speed_mm_s", {{"min", report.min_speed_mm_s}, {"max", report.max_speed_mm_s}}},
                  {"max_acceleration_mm_s2", report.dwell.max_acceleration_mm_s2},
                  {"solver",
                   {{"iterations", report.dwell.iterations},
                    {"converged", report.dwell.converged},
                    {"nonzeros", report.dwell.nonzeros},
                    {"shaping_rounds", report.dwell.shaping_rounds}}}};

  EnsureDirectory(output_folder);
  OutputSet outputs;
  auto write = [&](const std::string& name, const std::string& text) {
    const std::filesystem::path temporary = outputs.Stage(output_folder / name);
    std::ofstream out(temporary, std::ios::binary);
    out << text;
    out.close();
    if (!out) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot write '{}'", temporary.string()));
  };
  write("polishing_path.csv", PolishingPathCsv(points, comments));
  write("polish.mod", RapidModule(points, job.tool, job.work_object, "ArcwheelPolish", comments));
  write("residual_map.csv", ResidualCsv(target, report.dwell));
  write("polish_summary.json", summary.dump(2) + "\n");
  outputs.Commit();
  return report;
}

}  // namespace arcwheel::polishing
