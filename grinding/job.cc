#include "grinding/job.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>

#include "core/error.h"
#include "core/json_job.h"
#include "core/json_text.h"
#include "core/memory_budget.h"
#include "core/parallel.h"
#include "schema/wheel_map.h"
#include "surfaces/surface_json.h"

namespace arcwheel::grinding {

namespace {

constexpr const char* kJobStage = "grinding.job";

// Peak resident memory of `arcwheel toolpath` per item, measured on the trial part (docs/grinding.md
// "Sizes"): a control point of a row in flight, with its CSV, G-code and PMAC text (360 B); a
// planned row; a node of the predicted form-error map (30 B).
constexpr double kBytesPerControlPoint = 400.0;
constexpr double kBytesPerRow = 8.0;
constexpr double kBytesPerPredictionNode = 40.0;

// Wheel from the job's own numbers or from a summary.json.
struct WheelSource {
  Wheel wheel;
  std::optional<WheelSummary> summary;
  std::optional<WheelChange> change;
  ProfileError unfollowed_profile;  // the model's p(u) under a pure-arc path (for the prediction)
};

// With --wheel-profile model, the summary's radius and profile are the wheel model's: its mean
// arc radius with 1-sigma, and p(u) from the wheel_map.h5 written beside the summary.
WheelSummary WithModel(WheelSummary m, const std::filesystem::path& summary_path, JsonSection& s) {
  if (!std::isfinite(m.model_mean_arc_radius_mm)) {
    s.Fail("summary", fmt::format("'{}' has no wheel model (model.mean_arc_radius_mm), which "
                                  "--wheel-profile model needs: process the scan without --no-model",
                                  summary_path.string()));
  }
  m.mean_arc_radius_mm = m.model_mean_arc_radius_mm;
  m.mean_arc_radius_sigma_mm = m.model_mean_arc_radius_sigma_mm;
  const ProfileError p = ReadModelProfile(summary_path.parent_path() / schema::wheel_map::kFileName);
  m.profile_u_mm = p.u_mm;
  m.profile_error_um = p.error_um;
  return m;
}

// The measured radius replaces the nominal one within `max_change_mm`; beyond it the wheel on the
// spindle is not the one the job was written for (or the scan is of another wheel).
WheelChange CheckWheelChange(JsonSection& s, std::optional<double> nominal_mm, const WheelSummary& measured,
                             const std::filesystem::path& summary_path, double max_change_mm) {
  WheelChange change{.nominal_arc_radius_mm = nominal_mm,
                     .measured_arc_radius_mm = measured.mean_arc_radius_mm,
                     .measured_sigma_mm = measured.mean_arc_radius_sigma_mm,
                     .max_change_mm = max_change_mm};
  if (nominal_mm && !(std::abs(change.DifferenceMm()) <= max_change_mm)) {
    s.Fail(
        "arc_radius_mm",
        fmt::format("= {} mm (the nominal wheel) and the measured wheel '{}' (mean_arc_radius_mm = {} mm, "
                    "1-sigma {:.2g} mm) differ by {:+.4f} mm, more than the limit --max-wheel-change-mm = {} "
                    "mm: a dressing changes the arc radius by micrometres, so this is another wheel or "
                    "another wheel's scan; check the wheel, or raise the limit",
                    *nominal_mm, summary_path.string(), measured.mean_arc_radius_mm,
                    measured.mean_arc_radius_sigma_mm, change.DifferenceMm(), max_change_mm));
  }
  return change;
}

WheelSource ReadWheel(JsonSection& s, const std::filesystem::path& job_path,
                      const std::optional<std::filesystem::path>& override_summary,
                      std::optional<std::filesystem::path>& summary_path, double max_change_mm,
                      WheelProfileSource source) {
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
    // The job's arc radius is the nominal wheel's; the measured one wins.
    const std::optional<double> nominal = s.OptionalNumber("arc_radius_mm");
    out.summary = ReadWheelSummary(*summary_path);
    if (source == WheelProfileSource::kModel) out.summary = WithModel(*out.summary, *summary_path, s);
    const WheelSummary& m = *out.summary;
    out.change = CheckWheelChange(s, nominal, m, *summary_path, max_change_mm);
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
    const bool use_profile = s.Boolean("use_profile", true);
    if (use_profile) {
      for (size_t k = 0; k < m.profile_u_mm.size(); ++k) {
        if (std::isfinite(m.profile_u_mm[k]) && std::isfinite(m.profile_error_um[k])) {
          w.profile_u_mm.push_back(m.profile_u_mm[k]);
          w.profile_error_um.push_back(m.profile_error_um[k]);
        }
      }
    }
    const bool model = source == WheelProfileSource::kModel;
    if (model && !use_profile) out.unfollowed_profile = {m.profile_u_mm, m.profile_error_um};
    w.description = fmt::format(
        "measured wheel '{}' ({}){}: Ra = {} mm (1-sigma {:.2g} mm), Rb = {} mm{}",
        summary_path->filename().string(), m.wheel_id.empty() ? "no id" : m.wheel_id,
        model ? ", wheel model" : "", w.arc_radius_mm, m.mean_arc_radius_sigma_mm, w.base_radius_mm,
        w.HasProfile() ? (model ? ", with its profile error p(u)" : ", with its mean arc profile")
        : model        ? ", a pure arc (p(u) left to the prediction)"
                       : "");
  } else {
    if (!s.Has("arc_radius_mm"))
      s.Expected("arc_radius_mm", "the arc radius in mm (or wheel.summary / --wheel)");
    w.arc_radius_mm = s.RequiredNumber("arc_radius_mm");
    const double total = s.RequiredNumber("total_radius_mm");
    w.base_radius_mm = total - w.arc_radius_mm;
    s.Boolean("use_profile", false);
    w.description = fmt::format("wheel Ra = {} mm, Rb = {} mm", w.arc_radius_mm, w.base_radius_mm);
  }
  const double width = s.RequiredNumber("width_mm");
  w.half_width_mm = 0.5 * width;
  if (const std::optional<std::string> name = s.OptionalString("name"))
    w.description = *name + ": " + w.description;
  return out;
}

ToolpathOptions ReadPath(JsonSection& s) {
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

void ReadGougeCheck(JsonSection& s, ToolpathOptions& o) {
  o.gouge_check_spacing_mm = s.Number("spacing_mm", o.gouge_check_spacing_mm);
  o.gouge_samples = s.Integer("samples", o.gouge_samples);
  o.gouge_tolerance_mm = 1e-3 * s.Number("tolerance_um", o.gouge_tolerance_mm * 1e3);
}

void ReadPrediction(JsonSection& s, const std::optional<WheelSummary>& summary, double feed, Job& job) {
  job.predict = s.Boolean("enabled", true);
  PredictionOptions& p = job.prediction;
  p.feed_mm_per_min = feed;
  job.arc_radius_error_source = s.Has("arc_radius_error_mm") ? "prediction.arc_radius_error_mm"
                                : summary                    ? "the measured radius's 1-sigma"
                                                             : "none";
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
    s.Expected("spindle_rpm", "the grinding spindle speed in rpm (it places the runout ripple)");
  }
  p.spindle_rpm = rpm.value_or(0.0);
  // Whole numbers only: 2.5 must be refused, not used as 2, and a huge count never cast to int.
  const std::vector<double> nodes = s.Numbers("map_nodes", {201, 201});
  // Checked before the counts become ints: [1e10, 1e10] is no int, and no map that fits.
  if (const auto problem =
          MemoryBudgetProblem(fmt::format("prediction.map_nodes = [{}, {}]", nodes[0], nodes[1]),
                              nodes[0] * nodes[1], "map nodes", kBytesPerPredictionNode)) {
    s.ThrowIfProblems({*problem});
  }
  for (const double n : nodes) {
    if (n != std::floor(n) || std::abs(n) > std::numeric_limits<int>::max())
      s.Expected("map_nodes", "two whole numbers");
  }
  p.nodes_x = static_cast<int>(nodes[0]);
  p.nodes_y = static_cast<int>(nodes[1]);
}

// Sizes the toolpath implies, against the wheel and the memory budget (core/memory_budget.h),
// from the job alone: the rows are planned and the points solved only after this.
std::vector<std::string> SizeProblems(const Job& job) {
  const ToolpathOptions& o = job.path;
  const Wheel& w = job.wheel;
  std::vector<std::string> problems;
  if (o.step_over_mm > 2.0 * w.half_width_mm) {
    problems.push_back(
        fmt::format("path.step_over_mm = {} violates <= wheel.width_mm = {}: rows farther apart than "
                    "the wheel is wide leave bands it never touches",
                    o.step_over_mm, 2.0 * w.half_width_mm));
  }
  // Wheel-centre Y of the contacts lies within Ra of the contact (|Yw - Y| = Ra |fy| / N3), and
  // wheel-centre X within Ra + Rb of it: bounds of the rows and of a row's length.
  const double rows = (2.0 * job.aperture.HalfY() + 2.0 * w.arc_radius_mm) / o.step_over_mm + 2.0;
  if (const auto problem = MemoryBudgetProblem(fmt::format("path.step_over_mm = {}", o.step_over_mm), rows,
                                               "rows", kBytesPerRow)) {
    problems.push_back(*problem);
  }
  const double row_mm =
      2.0 * job.aperture.HalfX() + o.lead_in_mm + o.lead_out_mm + 2.0 * (w.arc_radius_mm + w.base_radius_mm);
  const double points_per_row = row_mm / o.point_spacing_mm + 2.0;
  const double rows_at_once =
      std::min(rows, static_cast<double>(kRowsInFlightPerWorker * WorkerCount(o.threads)));
  if (const auto problem = MemoryBudgetProblem(
          fmt::format("path.point_spacing_mm = {}", o.point_spacing_mm), rows_at_once * points_per_row,
          fmt::format("control points held at once ({:g} rows of up to {:.3g})", rows_at_once,
                      points_per_row),
          kBytesPerControlPoint)) {
    problems.push_back(*problem);
  }
  return problems;
}

// Every range problem of the options at once, then the aperture against the surface.
void Validate(const JsonSection& root, const Job& job) {
  std::vector<std::string> problems = job.wheel.Problems();
  for (std::string& p : job.path.Problems()) problems.push_back(std::move(p));
  for (std::string& p : job.machine.Problems()) problems.push_back(std::move(p));
  if (job.predict) {
    for (std::string& p : job.prediction.Problems()) problems.push_back(std::move(p));
  }
  root.ThrowIfProblems(problems);
  root.ThrowIfProblems(SizeProblems(job));
  // Contacts run lead_in / lead_out past the aperture and up to Ra |fy| / N3 < half width
  // across it; the surface must exist there.
  try {
    surfaces::CheckApertureInDomain(*job.surface, job.aperture,
                                    std::max(job.path.lead_in_mm, job.path.lead_out_mm),
                                    job.wheel.half_width_mm);
  } catch (const Error& e) {
    root.Fail("aperture", fmt::format("does not fit the surface: {}", e.what()));
  }
}

}  // namespace

std::vector<std::string> MachineOptions::Problems() const {
  std::vector<std::string> problems;
  if (pmac_program < 1)
    problems.push_back(fmt::format("machine.pmac_program = {} violates >= 1", pmac_program));
  if (decimals < 1 || decimals > 9) {
    problems.push_back(fmt::format("machine.decimals = {} violates 1 .. 9", decimals));
  }
  if (!(retract_mm >= 0.0))
    problems.push_back(fmt::format("machine.retract_mm = {} violates >= 0", retract_mm));
  return problems;
}

Job ParseJob(const std::string& text, const std::filesystem::path& source,
             const std::optional<std::filesystem::path>& wheel_summary_override, double max_wheel_change_mm,
             WheelProfileSource wheel_profile) {
  if (!(max_wheel_change_mm > 0.0)) {
    throw Error(ErrorCode::kInvalidOption, kJobStage,
                fmt::format("--max-wheel-change-mm = {} violates > 0", max_wheel_change_mm));
  }
  const nlohmann::json document = ParseJsonText(text, source.string(), kJobStage);
  JsonSection root(document, {.file = source.string(), .stage = kJobStage, .docs_page = "docs/grinding.md"});
  Job job;
  job.source = source;
  job.name = root.OptionalString("name").value_or(source.stem().string());
  root.SetResolved("name", job.name);

  root.Section("surface", true, [&](JsonSection& s) {
    job.surface = surfaces::ReadSurface(s, {"even_asphere", "xy_polynomial", "height_grid"});
  });
  root.Section("aperture", true, [&](JsonSection& s) { job.aperture = surfaces::ReadAperture(s); });
  std::optional<WheelSummary> summary;
  ProfileError unfollowed_profile;
  job.wheel_profile = wheel_profile;
  root.Section("wheel", false, [&](JsonSection& s) {
    WheelSource wheel =
        ReadWheel(s, source, wheel_summary_override, job.wheel_summary, max_wheel_change_mm, wheel_profile);
    job.wheel = std::move(wheel.wheel);
    job.wheel_change = wheel.change;
    unfollowed_profile = std::move(wheel.unfollowed_profile);
    summary = std::move(wheel.summary);
  });
  root.Section("path", true, [&](JsonSection& s) { job.path = ReadPath(s); });
  root.Section("gouge_check", false, [&](JsonSection& s) { ReadGougeCheck(s, job.path); });
  root.Section("machine", false, [&](JsonSection& s) {
    job.path.threads = s.Integer("threads", 0);
    job.machine.pmac_program = s.Integer("pmac_program", job.machine.pmac_program);
    job.machine.decimals = s.Integer("decimals", job.machine.decimals);
    job.machine.retract_mm = s.Number("retract_mm", job.machine.retract_mm);
  });
  root.Section("prediction", false, [&](JsonSection& s) {
    ReadPrediction(s, summary, job.path.feed_mm_per_min, job);
    job.prediction.threads = job.path.threads;
    job.prediction.profile_u_mm = unfollowed_profile.u_mm;
    job.prediction.profile_error_um = unfollowed_profile.error_um;
  });
  root.Section("outputs", false, [&](JsonSection& s) {
    job.outputs.csv = s.Boolean("csv", true);
    job.outputs.gcode = s.Boolean("gcode", true);
    job.outputs.pmac = s.Boolean("pmac", true);
  });
  root.Finish();
  Validate(root, job);
  job.resolved_json = JsonText(root.resolved());
  return job;
}

Job ReadJob(const std::filesystem::path& path,
            const std::optional<std::filesystem::path>& wheel_summary_override, double max_wheel_change_mm,
            WheelProfileSource wheel_profile) {
  std::ifstream in(path);
  if (!in) throw Error(ErrorCode::kIo, kJobStage, fmt::format("cannot open job file '{}'", path.string()));
  std::ostringstream text;
  text << in.rdbuf();
  return ParseJob(text.str(), path, wheel_summary_override, max_wheel_change_mm, wheel_profile);
}

}  // namespace arcwheel::grinding
