// arcwheel regenerate --scan SCAN --job PART.json [--polish POLISH.json] -o OUTDIR [--previous DIR]:
// after a dressing, the chain scan -> wheel -> toolpath -> predicted form error -> polishing
// program in one command (docs/regenerate.md).

#include <fmt/chrono.h>
#include <fmt/core.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "cli/step_inputs.h"
#include "cli/steps.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"
#include "core/version.h"
#include "grinding/job.h"
#include "grinding/prediction.h"
#include "reports/regenerate_report.h"
#include "schema/grid_map.h"
#include "schema/polish_outputs.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"

namespace arcwheel::cli {
// A named namespace, not an anonymous one: the command files are compiled as one unity
// translation unit, where helpers of the same name in two files would clash.
namespace regenerate {

namespace fs = std::filesystem;
using nlohmann::json;

constexpr const char* kRegenerateStage = "regenerate";
// In OUTDIR: the headline numbers of a finished regeneration, written last.
constexpr const char* kRecordFileName = "regenerate.json";
constexpr const char* kNominalPathFileName = "nominal_path_prediction.h5";
constexpr const char* kPredictionFileName = "prediction.h5";
constexpr const char* kToolpathSummaryFileName = "toolpath_summary.json";

struct RegenerateArgs {
  std::string scan;
  std::string job;
  std::string polish;
  std::string output;
  std::string previous;
  std::string polish_map = "prediction";
  std::string wheel_profile = "mean";
  double max_wheel_change_mm = grinding::kDefaultMaxWheelChangeMm;
};

// One step of the chain: its folder in OUTDIR and the files that show it complete.
struct ChainStepSpec {
  int number;
  std::string id;
  std::vector<std::string> outputs;
};
const ChainStepSpec kWheelStep{1, "wheel", {"summary.json", "wheel_map.h5"}};
const ChainStepSpec kToolpathStep{2, "toolpath", {kToolpathSummaryFileName, kPredictionFileName}};
const ChainStepSpec kPolishStep{3, "polish", {"polish_summary.json", "residual_map.h5", "polish.mod"}};
constexpr int kStepCount = 4;  // and the report

// Runs a step unless its inputs are unchanged. A failing step leaves no folder of its own; the
// message names the step, and the error keeps its code (so the exit status).
bool RunOrReuse(const fs::path& outdir, const ChainStepSpec& step, const json& inputs,
                const std::function<void(const fs::path&)>& run) {
  const fs::path folder = outdir / step.id;
  if (UpToDate(folder, step.outputs, inputs)) {
    fmt::print("step {}/{} {}: inputs unchanged, outputs in {} reused\n", step.number, kStepCount, step.id,
               folder.string());
    return false;
  }
  fs::remove_all(folder);
  fmt::print("step {}/{} {}:\n", step.number, kStepCount, step.id);
  try {
    run(folder);
    WriteFileAtomically(folder / kStepInputsFileName, inputs.dump(2) + "\n");
  } catch (const Error& e) {
    std::error_code ignored;
    fs::remove_all(folder, ignored);
    throw Error(e.code(), kRegenerateStage,
                fmt::format("step {}/{} '{}' failed (earlier steps' outputs in '{}' are complete, later ones "
                            "absent): {}",
                            step.number, kStepCount, step.id, outdir.string(), e.what()));
  }
  return true;
}

// Files a polishing job names besides its map (a measured removal function), as step inputs.
std::vector<std::pair<std::string, fs::path>> PolishJobFiles(const fs::path& job_path) {
  std::vector<std::pair<std::string, fs::path>> files = {{"polish_job", job_path}};
  const json job = ReadJsonFile(job_path, "polishing.job");
  if (job.contains("removal_function") && job["removal_function"].is_object() &&
      job["removal_function"].contains("file") && job["removal_function"]["file"].is_string()) {
    const fs::path file = job["removal_function"]["file"].get<std::string>();
    files.emplace_back("removal_function", file.is_absolute() ? file : job_path.parent_path() / file);
  }
  return files;
}

// The form error the job's nominal wheel's path prints when ground with the measured wheel: the
// arc-radius part alone (method.md A.8, fig. 7), what regenerating the toolpath avoids.
void WriteNominalPathPrediction(const grinding::Job& job, const fs::path& path) {
  const grinding::WheelChange& change = *job.wheel_change;
  grinding::Wheel nominal = job.wheel;
  nominal.arc_radius_mm = *change.nominal_arc_radius_mm;
  nominal.base_radius_mm = job.wheel.TotalRadius() - nominal.arc_radius_mm;
  nominal.profile_u_mm.clear();
  nominal.profile_error_um.clear();
  nominal.description =
      fmt::format("nominal wheel Ra = {} mm, Rb = {} mm", nominal.arc_radius_mm, nominal.base_radius_mm);
  grinding::PredictionOptions options = job.prediction;
  options.arc_radius_error_mm = change.DifferenceMm();
  options.runout_phase_deg.clear();
  options.runout_radial_um.clear();
  const grinding::FormPrediction p = grinding::PredictFormError(*job.surface, job.aperture, nominal, options);
  OutputSet outputs;
  grinding::WritePredictionHdf5(p, outputs.Stage(path), job.surface->Describe(),
                                nominal.description + ", ground with " + job.wheel.description);
  outputs.Commit();
  fmt::print(
      "the nominal wheel's path would print PV {:.3f} um, RMS {:.3f} um (arc radius {:+.4f} mm off): {}\n",
      p.pv_um, p.rms_um, change.DifferenceMm(), path.string());
}

// ------------------------------------------------------------------------------------------------
// The report and the record, from the steps' files.

std::string Mm(const json& v, int decimals) {
  return v.is_number() ? fmt::format("{:.{}f} mm", v.get<double>(), decimals) : "n/a";
}
std::string Um(const json& v, int decimals = 3) {
  return v.is_number() ? fmt::format("{:.{}f} µm", v.get<double>(), decimals) : "n/a";
}
const json& At(const json& object, std::string_view key) {
  static const json kNull;
  if (!object.is_object()) return kNull;
  const auto it = object.find(key);
  return it == object.end() ? kNull : *it;
}

reports::ChainMap ReadChainMap(const fs::path& path, const std::string& caption) {
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  const schema::grid_map::Location at = schema::grid_map::LocateGridMap(file, kRegenerateStage);
  reports::ChainMap map{
      .caption = caption, .x_mm = {}, .y_mm = {}, .values_um = file.ReadDoubles(at.error_dataset)};
  for (int i = 0; i < at.nx; ++i) map.x_mm.push_back(at.x0_mm + i * at.dx_mm);
  for (int j = 0; j < at.ny; ++j) map.y_mm.push_back(at.y0_mm + j * at.dy_mm);
  return map;
}

struct ChainFiles {
  json wheel;                        // wheel/summary.json
  json toolpath;                     // toolpath/toolpath_summary.json
  json polish;                       // polish/polish_summary.json, null without polishing
  std::optional<json> nominal_path;  // figures of the nominal path's map
};

json MapFigures(const fs::path& path) {
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  return {{"pv_um", file.ReadAttributeDouble("/", "pv_um").value_or(NAN)},
          {"rms_um", file.ReadAttributeDouble("/", "rms_um").value_or(NAN)}};
}

ChainFiles ReadChainFiles(const fs::path& outdir) {
  ChainFiles f;
  f.wheel = ReadJsonFile(outdir / kWheelStep.id / schema::summary::kFileName, kRegenerateStage);
  f.toolpath = ReadJsonFile(outdir / kToolpathStep.id / kToolpathSummaryFileName, kRegenerateStage);
  const fs::path polish = outdir / kPolishStep.id / schema::polish::kSummaryFileName;
  if (fs::exists(polish)) f.polish = ReadJsonFile(polish, kRegenerateStage);
  const fs::path nominal = outdir / kToolpathStep.id / kNominalPathFileName;
  if (fs::exists(nominal)) f.nominal_path = MapFigures(nominal);
  return f;
}

// The headline numbers kept in OUTDIR/regenerate.json and compared with the previous one.
json Record(const ChainFiles& f) {
  namespace key = schema::summary;
  json record = {{"finished_utc", fmt::format("{:%Y-%m-%dT%H:%M:%SZ}", fmt::gmtime(std::time(nullptr)))},
                 {"arcwheel_version", kVersion},
                 {"wheel",
                  {{"mean_arc_radius_mm", At(f.wheel, key::kMeanArcRadiusMm)},
                   {"mean_arc_radius_sigma_mm", At(f.wheel, key::kMeanArcRadiusSigmaMm)},
                   {"arc_radius_range_mm", At(f.wheel, key::kArcRadiusRangeMm)},
                   {"max_runout_um", At(f.wheel, key::kMaxRunoutUm)}}},
                 {"prediction", At(f.toolpath, "prediction")}};
  if (f.nominal_path) record["nominal_path"] = *f.nominal_path;
  if (!f.polish.is_null()) record["polish_after"] = At(f.polish, schema::polish::summary::kAfter);
  return record;
}

// The regeneration beside OUTDIR finished most recently, if any (its regenerate.json says when).
std::optional<fs::path> FindPreviousBeside(const fs::path& outdir) {
  const fs::path parent = fs::absolute(outdir).parent_path();
  std::optional<fs::path> best;
  std::string best_time;
  std::error_code error;
  for (const fs::directory_entry& entry : fs::directory_iterator(parent, error)) {
    if (!entry.is_directory() || fs::equivalent(entry.path(), outdir, error)) continue;
    const fs::path record = entry.path() / kRecordFileName;
    if (!fs::exists(record)) continue;
    try {
      const std::string time = At(ReadJsonFile(record, kRegenerateStage), "finished_utc").get<std::string>();
      if (!best || time > best_time) best = entry.path(), best_time = time;
    } catch (const std::exception&) {
      continue;  // not a record this command wrote
    }
  }
  return best;
}

std::vector<std::string> ChangeRow(const std::string& label, const json& before, const json& now,
                                   const char* unit, int decimals) {
  const auto text = [&](const json& v) {
    return v.is_number() ? fmt::format("{:.{}f} {}", v.get<double>(), decimals, unit) : std::string("n/a");
  };
  const std::string change =
      before.is_number() && now.is_number()
          ? fmt::format("{:+.{}f} {}", now.get<double>() - before.get<double>(), decimals, unit)
          : "n/a";
  return {label, text(before), text(now), change};
}

std::vector<std::vector<std::string>> Changes(const json& previous, const json& now) {
  const json &pw = At(previous, "wheel"), &nw = At(now, "wheel");
  const json &pp = At(previous, "prediction"), &np = At(now, "prediction");
  return {
      ChangeRow("Mean arc radius", At(pw, "mean_arc_radius_mm"), At(nw, "mean_arc_radius_mm"), "mm", 5),
      ChangeRow("Its 1-sigma", At(pw, "mean_arc_radius_sigma_mm"), At(nw, "mean_arc_radius_sigma_mm"), "mm",
                5),
      ChangeRow("Arc radius range", At(pw, "arc_radius_range_mm"), At(nw, "arc_radius_range_mm"), "mm", 4),
      ChangeRow("Max runout", At(pw, "max_runout_um"), At(nw, "max_runout_um"), "µm", 2),
      ChangeRow("Predicted form error PV", At(pp, "pv_um"), At(np, "pv_um"), "µm", 3),
      ChangeRow("Predicted form error RMS", At(pp, "rms_um"), At(np, "rms_um"), "µm", 3)};
}

std::vector<reports::KeyValue> WheelRows(const ChainFiles& f) {
  namespace key = schema::summary;
  const json& arc = At(f.toolpath, "arc_radius");
  std::string verdict = "measured arc radius used by the toolpath";
  if (At(arc, "nominal_mm").is_number()) {
    verdict = fmt::format("accepted: {:+.4f} mm from the job's nominal {} mm, within the limit of ±{} mm",
                          At(arc, "difference_mm").get<double>(), At(arc, "nominal_mm").get<double>(),
                          At(arc, "max_change_mm").get<double>());
  }
  const json& model = At(f.wheel, key::kModel);
  return {{"Verdict", verdict},
          {"Wheel", At(At(f.wheel, key::kScan), key::scan::kWheelId).is_string()
                        ? At(At(f.wheel, key::kScan), key::scan::kWheelId).get<std::string>()
                        : "no id"},
          {"Mean arc radius", Mm(At(f.wheel, key::kMeanArcRadiusMm), 5) + " (1-sigma " +
                                  Mm(At(f.wheel, key::kMeanArcRadiusSigmaMm), 5) + ")"},
          {"Arc radius range", Mm(At(f.wheel, key::kArcRadiusRangeMm), 4)},
          {"Max runout", Um(At(f.wheel, key::kMaxRunoutUm), 2)},
          {"Noise", Um(At(f.wheel, key::kNoiseSigmaUm), 3)},
          {"Radius varies with phase (model)",
           At(model, key::model::kVariationSignificant).is_boolean()
               ? (At(model, key::model::kVariationSignificant).get<bool>() ? "yes" : "no")
               : "no model"}};
}

std::vector<reports::KeyValue> ToolpathRows(const ChainFiles& f) {
  const json& t = At(f.toolpath, "toolpath");
  const json& arc = At(f.toolpath, "arc_radius");
  return {{"Job", At(At(f.toolpath, "job"), "name").is_string()
                      ? At(At(f.toolpath, "job"), "name").get<std::string>()
                      : ""},
          {"Wheel", At(f.toolpath, "wheel").is_string() ? At(f.toolpath, "wheel").get<std::string>() : ""},
          {"Arc radius used", Mm(At(arc, "measured_mm"), 5) + " measured (1-sigma " +
                                  Mm(At(arc, "measured_sigma_mm"), 5) + "); nominal " +
                                  Mm(At(arc, "nominal_mm"), 5)},
          {"Control points", At(t, "control_points").dump()},
          {"Passes x rows", At(t, "passes").dump() + " x " + At(t, "rows_per_pass").dump()},
          {"Smallest gouge gap", Um(At(t, "min_gouge_gap_um"), 3)},
          {"Files", At(f.toolpath, "files").dump()}};
}

std::vector<reports::KeyValue> PredictionRows(const ChainFiles& f) {
  const json& p = At(f.toolpath, "prediction");
  std::vector<reports::KeyValue> rows = {
      {"PV, RMS", Um(At(p, "pv_um")) + ", " + Um(At(p, "rms_um"))},
      {"After piston and tilt: PV, RMS",
       Um(At(p, "pv_after_tilt_um")) + ", " + Um(At(p, "rms_after_tilt_um"))},
      {"Runout ripple PV", Um(At(p, "ripple_pv_um"))},
      {"Arc radius error assumed",
       Mm(At(p, "arc_radius_error_mm"), 6) + " (" +
           (At(p, "arc_radius_error_source").is_string() ? At(p, "arc_radius_error_source").get<std::string>()
                                                         : "") +
           ")"}};
  if (f.nominal_path) {
    rows.push_back({"The nominal wheel's path would print (radius difference alone)",
                    "PV " + Um(At(*f.nominal_path, "pv_um")) + ", RMS " + Um(At(*f.nominal_path, "rms_um")) +
                        ": avoided by the regenerated toolpath"});
  }
  return rows;
}

std::vector<reports::KeyValue> PolishRows(const ChainFiles& f, const std::string& map_file) {
  namespace key = schema::polish::summary;
  const json& s = f.polish;
  return {{"Error map polished", map_file},
          {"Before: PV, RMS", Um(At(At(s, key::kBefore), key::figures::kPvUm), 4) + ", " +
                                  Um(At(At(s, key::kBefore), key::figures::kRmsUm), 4)},
          {"Predicted residual: PV, RMS", Um(At(At(s, key::kAfter), key::figures::kPvUm), 4) + ", " +
                                              Um(At(At(s, key::kAfter), key::figures::kRmsUm), 4)},
          {"Dwell points", At(s, key::kPoints).dump()},
          {"Total dwell", At(s, key::kTotalTimeS).is_number()
                              ? fmt::format("{:.1f} s", At(s, key::kTotalTimeS).get<double>())
                              : "n/a"},
          {"Program", "polish.mod (ABB RAPID), polishing_path.csv"}};
}

struct StepStatus {
  bool wheel_ran = false;
  bool toolpath_ran = false;
  std::optional<bool> polish_ran;  // none: no polishing job
};

std::string Status(bool ran) {
  return ran ? "done in this run" : "reused: its inputs (SHA-256) are unchanged";
}

void WriteChainReport(const RegenerateArgs& args, const StepStatus& status, const fs::path& polished_map) {
  const fs::path outdir(args.output);
  const ChainFiles files = ReadChainFiles(outdir);
  json record = Record(files);
  reports::RegenerateReportContent content;
  content.title = "Regeneration after a dressing: " + fs::path(args.job).stem().string();
  content.provenance = {{"Scan", args.scan},
                        {"Part job", args.job},
                        {"Polishing job", args.polish.empty() ? "none" : args.polish},
                        {"Output folder", args.output},
                        {"arcwheel", kVersion}};
  content.steps.push_back({"1. Wheel verdict", Status(status.wheel_ran), WheelRows(files)});
  content.steps.push_back({"2. Toolpath summary", Status(status.toolpath_ran), ToolpathRows(files)});
  content.steps.push_back({"3. Predicted form error", Status(status.toolpath_ran), PredictionRows(files)});
  content.maps.push_back(ReadChainMap(outdir / kToolpathStep.id / kPredictionFileName,
                                      "Predicted form error of the regenerated toolpath (µm)"));
  const fs::path nominal = outdir / kToolpathStep.id / kNominalPathFileName;
  if (fs::exists(nominal)) {
    content.maps.push_back(ReadChainMap(
        nominal, "Form error the nominal wheel's path would print with the measured wheel (µm)"));
  }
  if (status.polish_ran) {
    content.steps.push_back(
        {"4. Polishing plan", Status(*status.polish_ran), PolishRows(files, polished_map.string())});
    content.maps.push_back(ReadChainMap(outdir / kPolishStep.id / schema::polish::kResidualGridFileName,
                                        "Predicted residual after polishing (µm)"));
  } else {
    content.steps.push_back({"4. Polishing plan", "not run: no polishing job (--polish)", {}});
  }
  std::optional<fs::path> previous;
  if (!args.previous.empty()) {
    previous = args.previous;
  } else {
    previous = FindPreviousBeside(outdir);
  }
  if (previous) {
    const fs::path record_path = *previous / kRecordFileName;
    if (!fs::exists(record_path)) {
      throw Error(ErrorCode::kBadInput, kRegenerateStage,
                  fmt::format("--previous '{}' holds no {} (not a finished regeneration)", previous->string(),
                              kRecordFileName));
    }
    const json before = ReadJsonFile(record_path, kRegenerateStage);
    content.previous = fmt::format(
        "{} (finished {})", previous->string(),
        At(before, "finished_utc").is_string() ? At(before, "finished_utc").get<std::string>() : "?");
    content.changes = Changes(before, record);
    record["previous"] = previous->string();
  }
  const reports::WrittenRegenerateReport written = reports::WriteRegenerateReport(content, outdir);
  WriteFileAtomically(outdir / kRecordFileName, record.dump(2) + "\n");
  fmt::print("step 4/4 report: {}\n                 {}\n", written.html.string(), written.pdf.string());
}

void RemoveStale(const fs::path& outdir, const std::vector<std::string>& names) {
  for (const std::string& name : names) fs::remove_all(outdir / name);
}

void RunRegenerate(const RegenerateArgs& args) {
  if (args.polish_map == "nominal-path" && args.polish.empty()) {
    throw Error(ErrorCode::kInvalidOption, kRegenerateStage, "--polish-map nominal-path needs --polish");
  }
  // Checked before any step runs: a wrong --previous would otherwise fail only at the report.
  if (!args.previous.empty() && !fs::exists(fs::path(args.previous) / kRecordFileName)) {
    throw Error(ErrorCode::kInvalidOption, kRegenerateStage,
                fmt::format("--previous '{}' holds no {}: not a finished regeneration", args.previous,
                            kRecordFileName));
  }
  const fs::path outdir(args.output);
  EnsureDirectory(outdir);
  // The report and the record describe the steps below: gone until they are rewritten.
  RemoveStale(outdir, {kRecordFileName, "regenerate_report.html", "regenerate_report.pdf"});
  StepStatus status;
  const fs::path summary = outdir / kWheelStep.id / schema::summary::kFileName;
  status.wheel_ran = RunOrReuse(outdir, kWheelStep, StepInputs({{"scan", args.scan}}, json::object()),
                                [&](const fs::path& folder) {
                                  RunProcessStep(args.scan, folder);
                                  const json s = ReadJsonFile(summary, kRegenerateStage);
                                  fmt::print("mean arc radius {} (1-sigma {}), max runout {}: {}\n",
                                             Mm(At(s, schema::summary::kMeanArcRadiusMm), 5),
                                             Mm(At(s, schema::summary::kMeanArcRadiusSigmaMm), 5),
                                             Um(At(s, schema::summary::kMaxRunoutUm), 2), folder.string());
                                });
  if (status.wheel_ran) RemoveStale(outdir, {kToolpathStep.id, kPolishStep.id});

  // --wheel-profile model reads p(u) from the wheel map too.
  const json toolpath_inputs =
      StepInputs({{"job", args.job},
                  {"wheel_summary", summary},
                  {"wheel_map", outdir / kWheelStep.id / schema::wheel_map::kFileName}},
                 {{"max_wheel_change_mm", args.max_wheel_change_mm}, {"wheel_profile", args.wheel_profile}});
  status.toolpath_ran = RunOrReuse(outdir, kToolpathStep, toolpath_inputs, [&](const fs::path& folder) {
    const ToolpathStepResult result =
        RunToolpathStep(args.job, summary, args.max_wheel_change_mm, folder,
                        args.wheel_profile == "model" ? grinding::WheelProfileSource::kModel
                                                      : grinding::WheelProfileSource::kMeanProfile);
    if (!result.report.predicted) {
      throw Error(ErrorCode::kBadInput, "grinding.job",
                  fmt::format("'{}': key 'prediction.enabled' is false: regenerate predicts the form error",
                              args.job));
    }
    if (result.job.wheel_change && result.job.wheel_change->nominal_arc_radius_mm) {
      WriteNominalPathPrediction(result.job, folder / kNominalPathFileName);
    }
  });
  if (status.toolpath_ran) RemoveStale(outdir, {kPolishStep.id});

  fs::path polished_map = outdir / kToolpathStep.id / kPredictionFileName;
  if (args.polish.empty()) {
    RemoveStale(outdir, {kPolishStep.id});
  } else {
    if (args.polish_map == "nominal-path") {
      polished_map = outdir / kToolpathStep.id / kNominalPathFileName;
      if (!fs::exists(polished_map)) {
        throw Error(ErrorCode::kBadInput, kRegenerateStage,
                    fmt::format("step 3/4 'polish' failed: --polish-map nominal-path needs the job's nominal "
                                "wheel.arc_radius_mm, and '{}' gives none",
                                args.job));
      }
    }
    std::vector<std::pair<std::string, fs::path>> files = PolishJobFiles(args.polish);
    files.emplace_back("error_map", polished_map);
    status.polish_ran =
        RunOrReuse(outdir, kPolishStep, StepInputs(files, {{"polish_map", args.polish_map}}),
                   [&](const fs::path& folder) { (void)RunPolishStep(args.polish, polished_map, folder); });
  }
  try {
    WriteChainReport(args, status, polished_map);
  } catch (const Error& e) {
    throw Error(e.code(), kRegenerateStage,
                fmt::format("step 4/4 'report' failed (the steps' outputs in '{}' are complete): {}",
                            outdir.string(), e.what()));
  }
}

}  // namespace regenerate

void AddRegenerateCommand(CLI::App& app) {
  auto args = std::make_shared<regenerate::RegenerateArgs>();
  CLI::App* cmd = app.add_subcommand("regenerate",
                                     "after a dressing: scan -> wheel -> toolpath with the measured wheel -> "
                                     "predicted form error -> polishing "
                                     "program, with one report");
  cmd->footer(
      "Steps, each in its own folder of OUTDIR with the files of the single command:\n"
      "  1 wheel/     arcwheel process SCAN\n"
      "  2 toolpath/  arcwheel toolpath JOB --wheel wheel/summary.json (and the predicted form error)\n"
      "  3 polish/    arcwheel polish POLISH with error_map.file = the predicted form error\n"
      "  4 regenerate_report.html/.pdf and regenerate.json\n"
      "A step whose inputs (SHA-256 of its files, its options) are unchanged is not redone. A failing step\n"
      "leaves the earlier steps' outputs complete and the later ones absent; the message names it.\n"
      "See docs/regenerate.md.");
  cmd->add_option("--scan", args->scan, "raw wheel scan (.h5/.hdf5 or .csv)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--job", args->job, "toolpath job of the part (docs/grinding.md)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--polish", args->polish,
                  "polishing job (docs/polishing.md); its error_map.file is replaced")
      ->check(CLI::ExistingFile);
  cmd->add_option(
         "--polish-map", args->polish_map,
         "map to polish: prediction (what the regenerated toolpath leaves) or nominal-path (what the "
         "job's nominal wheel's path leaves with the measured wheel, e.g. on a part ground before)")
      ->check(CLI::IsMember({"prediction", "nominal-path"}))
      ->capture_default_str();
  cmd->add_option(
         "--wheel-profile", args->wheel_profile,
         "the measured wheel for the toolpath: mean (per-phase fits) or model (the wheel model's radius "
         "and p(u)), as toolpath --wheel-profile")
      ->check(CLI::IsMember({"mean", "model"}))
      ->capture_default_str();
  cmd->add_option("--max-wheel-change-mm", args->max_wheel_change_mm,
                  "refuse a measured arc radius farther than this from the job's nominal one")
      ->capture_default_str();
  cmd->add_option("--previous", args->previous,
                  "an earlier regeneration's OUTDIR to compare with (default: the latest one beside OUTDIR)")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("-o,--output", args->output, "output folder")->required();
  cmd->callback([args] { regenerate::RunRegenerate(*args); });
}

}  // namespace arcwheel::cli
