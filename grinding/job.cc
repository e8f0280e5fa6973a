#include "grinding/job.h"

#include <fmt/core.h>

#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel::grinding {

using surfaces::Aperture;
using surfaces::CheckApertureInDomain;
using surfaces::EvenAsphere;
using surfaces::EvenAsphereParameters;
using surfaces::HeightGrid;
using surfaces::HeightGridParameters;
using surfaces::Surface;
using surfaces::XyPolynomial;
using surfaces::XyPolynomialTerm;

namespace {

constexpr const char* kStage = "grinding.job";
using nlohmann::json;

// One JSON object of the job: typed reads by key, a record of the values used (defaults filled
// in) and a refusal of any key nobody read.
class Section {
 public:
  Section(const json* object, std::string prefix, const std::filesystem::path& source)
      : object_(object), prefix_(std::move(prefix)), source_(source) {
    if (object_ != nullptr && !object_->is_object()) Fail("", "must be a JSON object");
  }

  [[noreturn]] void Fail(const std::string& key, const std::string& what) const {
    const std::string name = key.empty() ? (prefix_.empty() ? "(root)" : prefix_) : Dotted(key);
    throw Error(ErrorCode::kBadInput, kStage, fmt::format("'{}': key '{}' {}", source_.string(), name, what));
  }
  [[nodiscard]] std::string Dotted(const std::string& key) const {
    return prefix_.empty() ? key : prefix_ + "." + key;
  }
  [[nodiscard]] bool Has(const std::string& key) const {
    return object_ != nullptr && object_->contains(key) && !object_->at(key).is_null();
  }
  const json& Raw(const std::string& key) {
    used_.insert(key);
    return object_->at(key);
  }

  double Number(const std::string& key, double fallback) {
    used_.insert(key);
    const double value = Has(key) ? FiniteNumber(key) : fallback;
    resolved_[key] = value;
    return value;
  }
  std::optional<double> OptionalNumber(const std::string& key) {
    used_.insert(key);
    if (!Has(key)) return std::nullopt;
    const double value = FiniteNumber(key);
    resolved_[key] = value;
    return value;
  }
  double RequiredNumber(const std::string& key, const std::string& why = "is missing") {
    if (!Has(key)) Fail(key, why);
    return Number(key, 0.0);
  }
  int Integer(const std::string& key, int fallback) {
    used_.insert(key);
    int value = fallback;
    if (Has(key)) {
      const json& v = object_->at(key);
      if (!v.is_number_integer()) Fail(key, "must be an integer");
      value = v.get<int>();
    }
    resolved_[key] = value;
    return value;
  }
  bool Boolean(const std::string& key, bool fallback) {
    used_.insert(key);
    bool value = fallback;
    if (Has(key)) {
      if (!object_->at(key).is_boolean()) Fail(key, "must be true or false");
      value = object_->at(key).get<bool>();
    }
    resolved_[key] = value;
    return value;
  }
  std::string Choice(const std::string& key, const std::vector<std::string>& choices) {
    used_.insert(key);
    std::string value = choices.front();
    if (Has(key)) {
      if (!object_->at(key).is_string()) Fail(key, "must be a string");
      value = object_->at(key).get<std::string>();
      bool known = false;
      for (const std::string& c : choices) known = known || c == value;
      if (!known) {
        std::string list;
        for (const std::string& c : choices) list += (list.empty() ? "'" : ", '") + c + "'";
        Fail(key, fmt::format("= '{}' is not one of {}", value, list));
      }
    }
    resolved_[key] = value;
    return value;
  }
  std::optional<std::string> OptionalString(const std::string& key) {
    used_.insert(key);
    if (!Has(key)) return std::nullopt;
    if (!object_->at(key).is_string()) Fail(key, "must be a string");
    resolved_[key] = object_->at(key).get<std::string>();
    return object_->at(key).get<std::string>();
  }
  std::vector<double> Numbers(const std::string& key, size_t count) {
    used_.insert(key);
    if (!Has(key) || !object_->at(key).is_array())
      Fail(key, fmt::format("must be an array of {} numbers", count));
    std::vector<double> values;
    for (const json& v : object_->at(key)) {
      if (!v.is_number() || !std::isfinite(v.get<double>())) Fail(key, "must hold finite numbers only");
      values.push_back(v.get<double>());
    }
    if (count != 0 && values.size() != count) {
      Fail(key, fmt::format("must be an array of {} numbers, has {}", count, values.size()));
    }
    resolved_[key] = values;
    return values;
  }
  // A nested section (empty if absent); its resolved values are merged in when it finishes.
  Section Child(const std::string& key) {
    used_.insert(key);
    return Section(Has(key) ? &object_->at(key) : nullptr, Dotted(key), source_);
  }
  // Element `index` of the array at `key`, as a section of its own.
  Section Element(const std::string& key, size_t index) const {
    return Section(&object_->at(key).at(index), fmt::format("{}[{}]", Dotted(key), index), source_);
  }
  void Adopt(const std::string& key, const Section& child) { resolved_[key] = child.resolved_; }
  void SetResolved(const std::string& key, const json& value) { resolved_[key] = value; }

  // Refuses keys nobody read, naming them all.
  void Finish() const {
    if (object_ == nullptr) return;
    std::string unknown;
    for (const auto& [key, value] : object_->items()) {
      if (!used_.count(key)) unknown += (unknown.empty() ? "'" : ", '") + Dotted(key) + "'";
    }
    if (!unknown.empty()) {
      throw Error(ErrorCode::kBadInput, kStage,
                  fmt::format("'{}': unknown key {} (see docs/grinding.md for the job keys)",
                              source_.string(), unknown));
    }
  }
  [[nodiscard]] const json& resolved() const { return resolved_; }

 private:
  double FiniteNumber(const std::string& key) const {
    const json& v = object_->at(key);
    if (!v.is_number() || !std::isfinite(v.get<double>())) Fail(key, "must be a finite number");
    return v.get<double>();
  }

  const json* object_;
  std::string prefix_;
  const std::filesystem::path& source_;
  std::set<std::string> used_;
  json resolved_ = json::object();
};

std::shared_ptr<const Surface> ReadEvenAsphere(Section& s) {
  EvenAsphereParameters p;
  p.vertex_radius_mm = s.RequiredNumber("vertex_radius_mm");
  if (!(p.vertex_radius_mm > 0.0)) s.Fail("vertex_radius_mm", "must be > 0 (use \"form\" for the side)");
  p.conic = s.Number("conic", 0.0);
  if (s.Has("coefficients")) {
    Section c = s.Child("coefficients");
    for (int order = 4; order <= 20; order += 2) {
      const double a = c.Number(fmt::format("A{}", order), 0.0);
      p.even_coefficients.push_back(a);
    }
    while (!p.even_coefficients.empty() && p.even_coefficients.back() == 0.0) p.even_coefficients.pop_back();
    c.Finish();
    s.Adopt("coefficients", c);
  }
  std::vector<double> off{0.0, 0.0};
  if (s.Has("off_axis_mm")) off = s.Numbers("off_axis_mm", 2);
  s.SetResolved("off_axis_mm", off);
  p.off_axis_x_mm = off[0];
  p.off_axis_y_mm = off[1];
  p.concave = s.Choice("form", {"concave", "convex"}) == "concave";
  try {
    return std::make_shared<EvenAsphere>(p);
  } catch (const Error& e) {
    s.Fail("off_axis_mm", fmt::format("is not usable: {}", e.what()));
  }
}

std::shared_ptr<const Surface> ReadXyPolynomial(Section& s) {
  if (!s.Has("terms") || !s.Raw("terms").is_array()) {
    s.Fail("terms", "must be an array of {\"x_power\", \"y_power\", \"coefficient\"} objects");
  }
  std::vector<XyPolynomialTerm> terms;
  json resolved = json::array();
  for (size_t k = 0; k < s.Raw("terms").size(); ++k) {
    Section t = s.Element("terms", k);
    XyPolynomialTerm term;
    term.x_power = t.Integer("x_power", 0);
    term.y_power = t.Integer("y_power", 0);
    term.coefficient = t.RequiredNumber("coefficient");
    if (term.x_power < 0 || term.y_power < 0 || term.x_power > 20 || term.y_power > 20) {
      t.Fail("x_power", "and y_power must be within 0 .. 20");
    }
    t.Finish();
    terms.push_back(term);
    resolved.push_back(t.resolved());
  }
  s.SetResolved("terms", resolved);
  return std::make_shared<XyPolynomial>(std::move(terms));
}

std::shared_ptr<const Surface> ReadHeightGrid(Section& s) {
  HeightGridParameters g;
  g.x0_mm = s.RequiredNumber("x0_mm");
  g.y0_mm = s.RequiredNumber("y0_mm");
  g.dx_mm = s.RequiredNumber("dx_mm");
  g.dy_mm = s.RequiredNumber("dy_mm");
  if (!(g.dx_mm > 0.0) || !(g.dy_mm > 0.0)) s.Fail("dx_mm", "and dy_mm must be > 0");
  if (!s.Has("heights_mm") || !s.Raw("heights_mm").is_array()) {
    s.Fail("heights_mm", "must be an array of rows (one per y, each along x)");
  }
  const json& rows = s.Raw("heights_mm");
  g.ny = static_cast<int>(rows.size());
  for (size_t j = 0; j < rows.size(); ++j) {
    const std::string key = fmt::format("heights_mm[{}]", j);
    if (!rows[j].is_array()) s.Fail(key, "must be an array of heights");
    if (j == 0) g.nx = static_cast<int>(rows[j].size());
    if (static_cast<int>(rows[j].size()) != g.nx) {
      s.Fail(key, fmt::format("has {} heights, row 0 has {}", rows[j].size(), g.nx));
    }
    for (const json& h : rows[j]) {
      if (!h.is_number() || !std::isfinite(h.get<double>())) s.Fail(key, "must hold finite numbers only");
      g.heights_mm.push_back(h.get<double>());
    }
  }
  s.SetResolved("heights_mm", rows);
  try {
    return std::make_shared<HeightGrid>(std::move(g));
  } catch (const Error& e) {
    s.Fail("heights_mm", fmt::format("is not usable: {}", e.what()));
  }
}

std::shared_ptr<const Surface> ReadSurface(Section& s) {
  const std::string type = s.Choice("type", {"even_asphere", "xy_polynomial", "height_grid"});
  if (type == "even_asphere") return ReadEvenAsphere(s);
  if (type == "xy_polynomial") return ReadXyPolynomial(s);
  return ReadHeightGrid(s);
}

Aperture ReadAperture(Section& s) {
  Aperture a;
  if (s.Choice("shape", {"rectangle", "circle"}) == "circle") {
    a.shape = Aperture::Shape::kCircle;
    a.diameter_mm = s.RequiredNumber("diameter_mm");
    if (!(a.diameter_mm > 0.0)) s.Fail("diameter_mm", "must be > 0");
  } else {
    const std::vector<double> size = s.Numbers("size_mm", 2);
    if (!(size[0] > 0.0) || !(size[1] > 0.0)) s.Fail("size_mm", "must be two sizes > 0");
    a.width_x_mm = size[0];
    a.width_y_mm = size[1];
  }
  return a;
}

// Wheel from the job's own numbers or from a summary.json.
struct WheelSource {
  Wheel wheel;
  std::optional<WheelSummary> summary;
};

WheelSource ReadWheel(Section& s, const std::filesystem::path& job_path,
                      const std::optional<std::filesystem::path>& override_summary,
                      std::optional<std::filesystem::path>& summary_path) {
  WheelSource out;
  std::optional<std::string> summary_key = s.OptionalString("summary");
  if (override_summary) {
    summary_path = *override_summary;
  } else if (summary_key) {
    const std::filesystem::path given(*summary_key);
    summary_path = given.is_absolute() ? given : job_path.parent_path() / given;
  }
  Wheel& w = out.wheel;
  if (summary_path) {
    if (s.Has("arc_radius_mm")) {
      s.Fail("arc_radius_mm", fmt::format("conflicts with the measured wheel '{}': the arc radius "
                                          "comes from its mean_arc_radius_mm",
                                          summary_path->string()));
    }
    out.summary = ReadWheelSummary(*summary_path);
    const WheelSummary& m = *out.summary;
    w.arc_radius_mm = m.mean_arc_radius_mm;
    s.SetResolved("summary", summary_path->string());
    s.SetResolved("arc_radius_mm", w.arc_radius_mm);
    std::optional<double> total = s.OptionalNumber("total_radius_mm");
    if (!total) {
      if (!(m.wheel_diameter_mm > 0.0)) {
        s.Fail("total_radius_mm", fmt::format("is missing and the summary '{}' has no "
                                              "scan.wheel_diameter_mm (null): give the wheel's "
                                              "total radius in the job",
                                              summary_path->string()));
      }
      total = 0.5 * m.wheel_diameter_mm;
      s.SetResolved("total_radius_mm", *total);
    }
    w.base_radius_mm = *total - w.arc_radius_mm;
    if (s.Boolean("use_profile", true)) {
      for (size_t k = 0; k < m.profile_u_mm.size(); ++k) {
        if (std::isfinite(m.profile_u_mm[k]) && std::isfinite(m.profile_error_um[k])) {
          w.profile_u_mm.push_back(m.profile_u_mm[k]);
          w.profile_error_um.push_back(m.profile_error_um[k]);
        }
      }
    }
    w.description = fmt::format("measured wheel '{}' ({}): Ra = {} +- {} mm, Rb = {} mm{}",
                                summary_path->filename().string(), m.wheel_id.empty() ? "no id" : m.wheel_id,
                                w.arc_radius_mm, m.mean_arc_radius_sigma_mm, w.base_radius_mm,
                                w.HasProfile() ? ", with its mean arc profile" : "");
  } else {
    w.arc_radius_mm = s.RequiredNumber("arc_radius_mm", "is missing (or give wheel.summary / --wheel)");
    const double total = s.RequiredNumber("total_radius_mm");
    w.base_radius_mm = total - w.arc_radius_mm;
    s.Boolean("use_profile", false);
    w.description = fmt::format("wheel Ra = {} mm, Rb = {} mm", w.arc_radius_mm, w.base_radius_mm);
  }
  const double width = s.RequiredNumber("width_mm");
  w.half_width_mm = 0.5 * width;
  if (const std::optional<std::string> name = s.OptionalString("name"))
    w.description = *name + ": " + w.description;
  if (const auto problems = w.Problems(); !problems.empty()) s.Fail("", "is not usable: " + problems.front());
  return out;
}

ToolpathOptions ReadPath(Section& s) {
  ToolpathOptions o;
  o.step_over_mm = s.Number("step_over_mm", o.step_over_mm);
  o.point_spacing_mm = s.Number("point_spacing_mm", o.point_spacing_mm);
  o.chordal_tolerance_um = s.Number("chordal_tolerance_um", o.chordal_tolerance_um);
  o.feed_mm_per_min = s.RequiredNumber("feed_mm_per_min");
  o.depth_per_pass_um = s.Number("depth_per_pass_um", o.depth_per_pass_um);
  o.passes = s.Integer("passes", o.passes);
  o.lead_in_mm = s.Number("lead_in_mm", o.lead_in_mm);
  o.lead_out_mm = s.Number("lead_out_mm", o.lead_out_mm);
  o.zigzag = s.Choice("direction", {"zigzag", "one_way"}) == "zigzag";
  return o;
}

void ReadGougeCheck(Section& s, ToolpathOptions& o) {
  o.gouge_check_spacing_mm = s.Number("spacing_mm", o.gouge_check_spacing_mm);
  o.gouge_samples = s.Integer("samples", o.gouge_samples);
  o.gouge_tolerance_mm = 1e-3 * s.Number("tolerance_um", o.gouge_tolerance_mm * 1e3);
}

void ReadPrediction(Section& s, const std::optional<WheelSummary>& summary, double feed, Job& job) {
  job.predict = s.Boolean("enabled", true);
  PredictionOptions& p = job.prediction;
  p.feed_mm_per_min = feed;
  p.arc_radius_error_mm = s.Number("arc_radius_error_mm", summary ? summary->mean_arc_radius_sigma_mm : 0.0);
  p.keep_total_radius = s.Boolean("keep_total_radius", true);
  const std::optional<double> rpm = s.OptionalNumber("spindle_rpm");
  std::optional<double> tir = s.OptionalNumber("runout_um");
  if (tir) {
    SetEccentricRunout(*tir, p);
  } else if (summary && summary->phase_deg.size() >= 3) {
    // The measured rim: eps(phi) = b(phi) - mean b, from the per-phase arc centres.
    double mean = 0.0;
    for (double b : summary->center_radial_mm) mean += b;
    mean /= static_cast<double>(summary->center_radial_mm.size());
    for (size_t k = 0; k < summary->phase_deg.size(); ++k) {
      p.runout_phase_deg.push_back(summary->phase_deg[k]);
      p.runout_radial_um.push_back(1e3 * (summary->center_radial_mm[k] - mean));
    }
    s.SetResolved("runout_source", "summary phases.center_radial_mm");
  } else if (summary && summary->max_runout_um > 0.0) {
    SetEccentricRunout(summary->max_runout_um, p);
    s.SetResolved("runout_um", summary->max_runout_um);
  }
  bool any_runout = false;
  for (double e : p.runout_radial_um) any_runout = any_runout || e != 0.0;
  if (!any_runout) {
    p.runout_phase_deg.clear();
    p.runout_radial_um.clear();
  }
  if (any_runout && job.predict && !rpm) {
    s.Fail("spindle_rpm", "is missing: the grinding spindle speed places the runout ripple");
  }
  p.spindle_rpm = rpm.value_or(0.0);
  std::vector<double> nodes{201, 201};
  if (s.Has("map_nodes")) nodes = s.Numbers("map_nodes", 2);
  s.SetResolved("map_nodes", nodes);
  p.nodes_x = static_cast<int>(nodes[0]);
  p.nodes_y = static_cast<int>(nodes[1]);
}

void Validate(const Section& root, Job& job) {
  if (const auto problems = job.path.Problems(); !problems.empty()) {
    const std::string& first = problems.front();
    root.Fail(first.substr(0, first.find(' ')), first.substr(first.find(' ') + 1));
  }
  if (job.machine.pmac_program < 1) root.Fail("machine.pmac_program", "must be >= 1");
  if (job.machine.decimals < 1 || job.machine.decimals > 9)
    root.Fail("machine.decimals", "must be within 1 .. 9");
  if (!(job.machine.retract_mm >= 0.0)) root.Fail("machine.retract_mm", "must be >= 0");
  if (job.predict) {
    if (const auto problems = job.prediction.Problems(); !problems.empty()) {
      root.Fail("prediction", "is not usable: " + problems.front());
    }
  }
  // Contacts run lead_in / lead_out past the aperture and up to Ra |fy| / N3 < half width
  // across it; the surface must exist there.
  try {
    CheckApertureInDomain(*job.surface, job.aperture, std::max(job.path.lead_in_mm, job.path.lead_out_mm),
                          job.wheel.half_width_mm);
  } catch (const Error& e) {
    root.Fail("aperture", fmt::format("does not fit the surface: {}", e.what()));
  }
}

}  // namespace

Job ParseJob(const std::string& text, const std::filesystem::path& source,
             const std::optional<std::filesystem::path>& wheel_summary_override) {
  json document = ParseJsonText(text, source.string(), kStage);
  Section root(&document, "", source);
  Job job;
  job.source = source;
  job.name = root.OptionalString("name").value_or(source.stem().string());

  Section surface = root.Child("surface");
  if (!root.Has("surface")) root.Fail("surface", "is missing");
  job.surface = ReadSurface(surface);
  surface.Finish();

  Section aperture = root.Child("aperture");
  if (!root.Has("aperture")) root.Fail("aperture", "is missing");
  job.aperture = ReadAperture(aperture);
  aperture.Finish();

  Section wheel = root.Child("wheel");
  WheelSource wheel_source = ReadWheel(wheel, source, wheel_summary_override, job.wheel_summary);
  job.wheel = wheel_source.wheel;
  wheel.Finish();

  Section path = root.Child("path");
  if (!root.Has("path")) root.Fail("path", "is missing");
  job.path = ReadPath(path);
  path.Finish();

  Section gouge = root.Child("gouge_check");
  ReadGougeCheck(gouge, job.path);
  gouge.Finish();

  Section machine = root.Child("machine");
  job.path.threads = machine.Integer("threads", 0);
  job.machine.pmac_program = machine.Integer("pmac_program", job.machine.pmac_program);
  job.machine.decimals = machine.Integer("decimals", job.machine.decimals);
  job.machine.retract_mm = machine.Number("retract_mm", job.machine.retract_mm);
  machine.Finish();

  Section prediction = root.Child("prediction");
  ReadPrediction(prediction, wheel_source.summary, job.path.feed_mm_per_min, job);
  job.prediction.threads = job.path.threads;
  prediction.Finish();

  Section outputs = root.Child("outputs");
  job.outputs.csv = outputs.Boolean("csv", true);
  job.outputs.gcode = outputs.Boolean("gcode", true);
  job.outputs.pmac = outputs.Boolean("pmac", true);
  outputs.Finish();

  root.Finish();
  Validate(root, job);

  job.resolved = root.resolved();
  for (const auto& [key, section] :
       std::vector<std::pair<std::string, const Section*>>{{"surface", &surface},
                                                           {"aperture", &aperture},
                                                           {"wheel", &wheel},
                                                           {"path", &path},
                                                           {"gouge_check", &gouge},
                                                           {"machine", &machine},
                                                           {"prediction", &prediction},
                                                           {"outputs", &outputs}}) {
    job.resolved[key] = section->resolved();
  }
  job.resolved["name"] = job.name;
  return job;
}

Job ReadJob(const std::filesystem::path& path,
            const std::optional<std::filesystem::path>& wheel_summary_override) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot open job file '{}'", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return ParseJob(text.str(), path, wheel_summary_override);
}

}  // namespace arcwheel::grinding
