// arcwheel process SCAN -o OUTDIR: raw helical scan -> summary.json + wheel_map.h5.

#include <fmt/core.h>

#include <filesystem>
#include <optional>
#include <string>
#include <type_traits>
#include <variant>
#include <vector>

#include "cli/commands.h"
#include "core/number_format.h"
#include "core/progress.h"
#include "core/stage_clock.h"
#include "fitting/wheel_model.h"
#include "reports/report.h"
#include "reports/tolerances.h"
#include "schema/summary.h"
#include "schema/wheel_map.h"
#include "store/records.h"
#include "workflows/process_options.h"
#include "workflows/process_pipeline.h"
#include "workflows/record.h"

namespace arcwheel::cli {
namespace {

struct ProcessArgs {
  std::string scan_path;
  std::string outdir;
  workflows::ProcessPipelineOptions pipeline;
  std::vector<std::string> report_formats;
  std::string tolerance_file;
  bool quiet = false;
  bool timings = false;
  std::string db;
};

// One line a characteristic: its value under its operator, U and, with a tolerance, the decision.
void PrintCharacteristics(const workflows::CharacteristicsResult& c) {
  for (const workflows::Characteristic& item : c.items) {
    const bool mm = item.unit == "mm";
    const std::string value = mm ? fmt::format("{:.5f} mm", Shown(item.value))
                                 : fmt::format("{:.3f} {}", Shown(item.value), item.unit);
    const std::string expanded =
        mm ? fmt::format("U = {:.5f} (k = {:.2f})", Shown(item.expanded), Shown(item.coverage_factor))
           : fmt::format("U = {:.3f} (k = {:.2f})", Shown(item.expanded), Shown(item.coverage_factor));
    fmt::print("{:<28} {:>14}  {:<24} {:<24} {}\n", item.label, value, expanded, item.operator_text,
               item.decision ? uncertainty::DecisionName(*item.decision) : "");
  }
}

void PrintHeadline(const ProcessArgs& args, const workflows::ProcessPipelineResult& result) {
  const processing::ProcessedScan& p = result.processed;
  const fitting::WheelFit& f = result.fit;
  const std::filesystem::path out(args.outdir);
  fmt::print("summary: {}\nmap:     {}\n", (out / schema::summary::kFileName).string(),
             (out / schema::wheel_map::kFileName).string());
  fmt::print("samples {} (valid {}, despiked {}); noise {:.3f} um; spindle {:.4f} rpm ({})\n", p.samples,
             p.valid_samples, p.despike.rejected, Shown(p.noise_sigma_mm * 1000.0), Shown(p.rpm_used),
             p.phase_source == processing::PhaseSource::kEncoder     ? "encoder"
             : p.phase_source == processing::PhaseSource::kEstimated ? "estimated from the data"
                                                                     : "nominal");
  fmt::print("{} of {} phases usable; band [{:.3f}, {:.3f}] mm\n", f.usable_phases, f.phases.size(),
             Shown(f.band_low_mm), Shown(f.band_high_mm));
  if (result.characteristics) {
    PrintCharacteristics(*result.characteristics);
    return;
  }
  // Without the uncertainty there is no operator's value to show: the contract's raw figures,
  // named as what they are.
  fmt::print("mean arc radius      {:.5f} +- {:.5f} mm (1 sigma, least squares)\n",
             Shown(f.mean_arc_radius_mm), Shown(f.mean_arc_radius_sigma_mm));
  fmt::print("arc radius range     {:.5f} mm (least squares)\n", Shown(f.arc_radius_range_mm));
  fmt::print("arc centre axial     deviation {:.5f} mm (least squares)\n",
             Shown(f.center_axial_deviation_mm));
  fmt::print("max arc error        {:.3f} um (unfiltered, least squares)\n", Shown(f.max_arc_error_um));
  fmt::print("max runout           {:.3f} um (unfiltered)\n", Shown(f.max_runout_um));
  fmt::print("max roundness        {:.3f} um (unfiltered, least squares)\n", Shown(f.max_roundness_um));
}

void PrintModelHeadline(const fitting::WheelModel& m) {
  fmt::print("model arc radius     {:.5f} +- {:.5f} mm, range {:.5f} +- {:.5f} mm\n",
             Shown(m.mean_arc_radius_mm), Shown(m.mean_arc_radius_sigma_mm), Shown(m.arc_radius_range_mm),
             Shown(m.arc_radius_range_sigma_mm));
  fmt::print("model radius varies  {} (chi-square {:.1f} on {} dof, p = {:.2g}); knots Ra/a/b {}/{}/{}\n",
             m.variation_significant ? "yes" : "no", Shown(m.variation_chi2), m.variation_dof,
             Shown(m.variation_p_value), m.radius_knots, m.axial_knots, m.runout_knots);
}

// One line per stage on stderr, so that the outputs and the headline stay as they are.
void PrintTimings(const StageClock& clock) {
  double total_s = 0.0, total_cpu_s = 0.0;
  for (const StageClock::Stage& stage : clock.stages()) {
    fmt::print(stderr, "timing  {:<32} {:8.3f} s   cpu {:7.3f} s   peak memory {:7.1f} MiB\n", stage.name,
               Shown(stage.seconds), Shown(stage.cpu_seconds), Shown(stage.peak_memory_mib));
    total_s += stage.seconds;
    total_cpu_s += stage.cpu_seconds;
  }
  fmt::print(stderr, "timing  {:<32} {:8.3f} s   cpu {:7.3f} s\n", "total", Shown(total_s),
             Shown(total_cpu_s));
}

void RunAndPrint(ProcessArgs& args) {
  // A bad tolerance file is refused before the scan is read (exit 2, nothing written).
  if (!args.tolerance_file.empty()) args.pipeline.tolerances = reports::ReadTolerances(args.tolerance_file);
  Progress progress(!args.quiet);
  const workflows::ProcessPipelineResult result =
      workflows::RunProcessPipeline(args.scan_path, args.outdir, args.pipeline, progress);
  progress.Done();
  if (args.timings) PrintTimings(result.clock);
  if (!args.quiet) PrintHeadline(args, result);
  if (!args.quiet && result.model) PrintModelHeadline(*result.model);
  if (!args.report_formats.empty()) {
    // The report is drawn from the files just written, exactly as `arcwheel report` would.
    const reports::WrittenReports written =
        reports::WriteReports(args.outdir, args.pipeline.tolerances.value_or(reports::Tolerances{}));
    if (!args.quiet) fmt::print("report:  {}\n         {}\n", written.html.string(), written.pdf.string());
  }
}

// One row of the options table as a flag: a number, a switch, a file or a choice, whose unknown
// name is reported with every other problem (ResolveProcessPipelineOptions).
void AddTableOption(CLI::App* cmd, const workflows::ProcessOption& row,
                    workflows::ProcessPipelineOptions& options) {
  const std::string flag(row.flag);
  const std::string help(row.help);
  std::visit(
      [&](const auto& value) {
        using T = std::decay_t<decltype(value)>;
        CLI::Option* option = nullptr;
        if constexpr (std::is_same_v<T, bool*>) {
          option = cmd->add_flag(flag, *value, help);
        } else if constexpr (std::is_same_v<T, workflows::ChoiceRef>) {
          option = cmd->add_option_function<std::string>(
              flag,
              [flag, value, &options](const std::string& name) {
                workflows::SetChoice(flag, value, name, options);
              },
              help);
          option->default_str(std::string(workflows::NameOf(value)));
        } else {
          option = cmd->add_option(flag, *value, help);
        }
        constexpr bool kTyped =
            std::is_same_v<T, int*> || std::is_same_v<T, double*> || std::is_same_v<T, std::string*>;
        if (row.show_default && kTyped) option->capture_default_str();
        if (row.existing_file) option->check(CLI::ExistingFile);
      },
      row.field(options));
}

void Run(ProcessArgs& args) {
  workflows::RunRecorded(
      args.db, [&] { RunAndPrint(args); },
      [&] { return std::vector<store::StoredRun>{store::ProcessRun(args.outdir, "process")}; });
}

}  // namespace

void AddProcessCommand(CLI::App& app) {
  auto args = std::make_shared<ProcessArgs>();
  CLI::App* cmd =
      app.add_subcommand("process", "turn a raw helical wheel scan into summary.json and wheel_map.h5");
  cmd->footer(
      "Steps: trim invalid ends; drop stuck-sensor runs; estimate the noise; despike; unwrap the helix "
      "(encoder, or the\n"
      "spindle speed estimated from the data when it differs significantly from nominal); lay out the\n"
      "map's nodes (every phase, one helix pitch apart over the axial span all phases cover); fit a\n"
      "circle to each phase's samples inside the band (least squares over every sample, with 1-sigma\n"
      "uncertainties); set each map node to its phase's circle plus the mean residual of the samples\n"
      "around it, for runout and roundness; fit the wheel model over every sample; estimate the\n"
      "uncertainty of the headline figures.\n"
      "Runout is the wheel's plus the spindle's error motion: one sensor cannot separate them.\n"
      "Outputs are written under temporary names and renamed when complete.");
  cmd->add_option("SCAN", args->scan_path, "raw scan, .h5/.hdf5 or .csv/.txt (formats.md section 2)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("-o,--output", args->outdir, "output folder")->required();
  for (const workflows::ProcessOption& option : workflows::ProcessOptionTable()) {
    if (!option.flag.empty()) AddTableOption(cmd, option, args->pipeline);
  }
  cmd->add_option("--report", args->report_formats,
                  "also render the inspection report: html,pdf (both are written)")
      ->delimiter(',')
      ->check(CLI::IsMember({"html", "pdf"}));
  cmd->add_option("--tolerances", args->tolerance_file,
                  "tolerance file for the report's pass/fail (docs/reports.md)")
      ->check(CLI::ExistingFile);
  AddDbOption(cmd, args->db);
  cmd->add_flag("-q,--quiet", args->quiet, "no progress and no headline");
  cmd->add_flag("--timings", args->timings,
                "print each stage's wall time, CPU time and peak memory so far on stderr");
  cmd->callback([args] { Run(*args); });
}

}  // namespace arcwheel::cli
