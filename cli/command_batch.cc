// arcwheel batch INPUTS... -o OUTDIR [-j N] [-- PROCESS OPTIONS]: the options bound to
// workflows::RunBatch (workflows/batch.h), and its outcome printed (docs/batch.md).

#include <fmt/core.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "workflows/batch.h"

namespace arcwheel::cli {

namespace {
// The arguments after `--` on the command line (main.cc takes them off before CLI11 parses).
std::vector<std::string>& PassThroughStorage() {
  static std::vector<std::string> options;
  return options;
}
}  // namespace

void SetBatchProcessOptions(std::vector<std::string> options) { PassThroughStorage() = std::move(options); }

// A named namespace: the command files are compiled as one unity translation unit.
namespace batch {

namespace fs = std::filesystem;
constexpr const char* kStage = "batch";

// The options go to every child unchanged; they are parsed once here by the process command's
// own definition, so that a typo stops the batch before any scan runs.
void CheckProcessOptions(const std::vector<std::string>& options, const fs::path& some_scan) {
  CLI::App app{"arcwheel", "arcwheel"};
  app.require_subcommand(1);
  AddProcessCommand(app);
  // Runs once every option is converted and checked, before the process command's own callback:
  // stop there, the options are valid.
  app.parse_complete_callback([] { throw CLI::Success(); });
  std::vector<std::string> arguments = {"process", some_scan.string(), "-o", "unused"};
  arguments.insert(arguments.end(), options.begin(), options.end());
  std::reverse(arguments.begin(), arguments.end());  // CLI11 takes them last first
  try {
    app.parse(arguments);
  } catch (const CLI::Success&) {
    return;
  } catch (const CLI::ParseError& error) {
    throw Error(ErrorCode::kInvalidOption, kStage,
                fmt::format("the process options after --: {}", error.what()));
  }
  throw Error(ErrorCode::kInternal, kStage, "the process options were not checked");
}

void Run(workflows::BatchOptions& options) {
  options.process_options = PassThroughStorage();
  options.check_process_options = CheckProcessOptions;
  const workflows::BatchReport report = workflows::RunBatch(options);
  if (!report.slurm_script.empty()) {
    fmt::print("slurm: {} ({} array tasks); submit with `sbatch {}`\n", options.emit_slurm, report.scans,
               options.emit_slurm);
    return;
  }
  const std::string index =
      report.index_csv.empty() ? std::string() : fmt::format("; index: {}", report.index_csv.string());
  fmt::print("batch: {} scans: {} done, {} reused, {} failed, {} interrupted, {} not run{}\n", report.scans,
             report.done, report.reused, report.failed, report.interrupted, report.not_run, index);
  ThrowIfInterrupted();
  if (report.Unfinished() > 0) {
    throw SomeFailed(fmt::format(
        "batch: {} of {} scans have no result{}", report.Unfinished(), report.scans,
        report.index_csv.empty() ? std::string()
                                 : fmt::format(" (the index names them: {})", report.index_csv.string())));
  }
}

}  // namespace batch

void AddBatchCommand(CLI::App& app) {
  auto args = std::make_shared<workflows::BatchOptions>();
  CLI::App* cmd =
      app.add_subcommand("batch", "process many scans, each into OUTDIR/<scan name>, with an index");
  cmd->footer(
      "INPUTS: scan files, folders (their *.h5, *.hdf5, *.csv, *.txt), globs, and @LIST files (one path a\n"
      "line, # comments; relative paths from the list's folder). A scan's result folder is named\n"
      "after its file without the extension; two scans of one name are refused.\n"
      "Options after -- go unchanged to every `arcwheel process` (e.g. -- --phases 180 --no-model).\n"
      "Each scan runs as a child `arcwheel process`; a scan whose input SHA-256 and options match a\n"
      "finished result is reused. OUTDIR/index.csv and index.json list every scan: status, exit\n"
      "status, message, the headline numbers with their sigmas. OUTDIR/logs/<name>.log holds each\n"
      "child's output. Exit status 0 when every scan has a result, 6 when some have none,\n"
      "130 when interrupted (finished results and the index are kept). See docs/batch.md.");
  cmd->add_option("INPUTS", args->inputs, "scans, folders, globs, @lists")->required();
  cmd->add_option("-o,--output", args->outdir, "output folder")->required();
  cmd->add_option("-j,--jobs", args->jobs, "scans processed at once")->capture_default_str();
  cmd->add_option("--emit-slurm", args->emit_slurm,
                  "write an sbatch array script (one task per scan) instead of running");
  cmd->add_option("--sbatch", args->sbatch_lines,
                  "with --emit-slurm: an extra #SBATCH line, e.g. --sbatch=--partition=short (repeatable)");
  cmd->add_flag("--index-only", args->index_only,
                "run nothing: write the index of what OUTDIR holds (after a Slurm or HTCondor run)");
  cmd->add_flag("--no-index", args->no_index, "write no index (each Slurm array task)");
  AddDbOption(cmd, args->db);
  cmd->callback([args] { batch::Run(*args); });
}

}  // namespace arcwheel::cli
