// arcwheel regenerate --scan SCAN --job PART.json [--polish POLISH.json] -o OUTDIR [--previous DIR]:
// the options bound to workflows::RunRegenerate (workflows/regenerate.h; docs/regenerate.md).

#include <memory>

#include "cli/commands.h"
#include "workflows/regenerate.h"

namespace arcwheel::cli {

void AddRegenerateCommand(CLI::App& app) {
  auto args = std::make_shared<workflows::RegenerateOptions>();
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
  cmd->add_option("--scan-settings", args->scan_settings,
                  "the scan's settings the file lacks, as process --scan-settings (formats.md 2.4)")
      ->check(CLI::ExistingFile);
  cmd->add_option("--format", args->scan_format, "the scan's reader, as process --format (default: sniffed)");
  cmd->add_option("--columns", args->columns, "which column holds what, as process --columns");
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
  AddDbOption(cmd, args->db);
  cmd->callback([args] { workflows::RunRegenerate(*args); });
}

}  // namespace arcwheel::cli
