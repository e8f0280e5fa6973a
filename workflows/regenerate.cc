#include "workflows/regenerate.h"

#include <fmt/core.h>

#include <filesystem>
#include <functional>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <vector>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "core/number_format.h"
#include "grinding/job.h"
#include "grinding/prediction.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"
#include "store/records.h"
#include "workflows/record.h"
#include "workflows/regenerate_internal.h"
#include "workflows/step_inputs.h"
#include "workflows/steps.h"

namespace arcwheel::workflows {
namespace regenerate {
namespace {

using nlohmann::json;

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
    WriteFileAtomically(folder / kStepInputsFileName, JsonText(inputs, 2) + "\n");
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
      Shown(p.pv_um), Shown(p.rms_um), Shown(change.DifferenceMm()), path.string());
}

void RemoveStale(const fs::path& outdir, const std::vector<std::string>& names) {
  for (const std::string& name : names) fs::remove_all(outdir / name);
}

}  // namespace
}  // namespace regenerate

void RunRegenerate(const RegenerateOptions& args) {
  using namespace regenerate;
  if (args.polish_map == "nominal-path" && args.polish.empty()) {
    throw Error(ErrorCode::kInvalidOption, kRegenerateStage, "--polish-map nominal-path needs --polish");
  }
  // Checked before any step runs: a wrong --previous would otherwise fail only at the report.
  if (!args.previous.empty() && !fs::exists(fs::path(args.previous) / kRecordFileName)) {
    throw Error(ErrorCode::kInvalidOption, kRegenerateStage,
                fmt::format("--previous '{}' holds no {}: not a finished regeneration", args.previous,
                            kRecordFileName));
  }
  std::optional<store::Store> results = OpenRunStore(args.db);
  const fs::path outdir(args.output);
  EnsureDirectory(outdir);
  // The report and the record describe the steps below: gone until they are rewritten.
  RemoveStale(outdir, {kRecordFileName, "regenerate_report.html", "regenerate_report.pdf"});
  StepStatus status;
  const fs::path summary = outdir / kWheelStep.id / schema::summary::kFileName;
  // The settings file is an input like the scan; the reader's choice an option (absent at the
  // defaults, so that earlier records stay equal).
  std::vector<std::pair<std::string, fs::path>> wheel_files = {{"scan", args.scan}};
  if (!args.scan_settings.empty()) wheel_files.emplace_back("scan_settings", args.scan_settings);
  json wheel_options = json::object();
  if (!args.scan_format.empty()) wheel_options["format"] = args.scan_format;
  if (!args.columns.empty()) wheel_options["columns"] = args.columns;
  status.wheel_ran =
      RunOrReuse(outdir, kWheelStep, StepInputs(wheel_files, wheel_options), [&](const fs::path& folder) {
        RunProcessStep(
            args.scan, folder,
            {.scan_settings = args.scan_settings, .format = args.scan_format, .columns = args.columns});
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
  if (!results) return;
  std::vector<store::StoredRun> runs;
  if (status.wheel_ran) runs.push_back(store::ProcessRun(outdir / kWheelStep.id, "regenerate"));
  if (status.toolpath_ran) {
    runs.push_back(store::ToolpathRun(outdir / kToolpathStep.id, args.job, summary, "regenerate"));
  }
  if (status.polish_ran.value_or(false)) {
    runs.push_back(store::PolishRun(outdir / kPolishStep.id, args.polish, polished_map, "regenerate"));
  }
  results->Record(runs);
}

}  // namespace arcwheel::workflows
