#include <fmt/core.h>

#include "core/version.h"
#include "workflows/batch_internal.h"

namespace arcwheel::workflows::batch {

namespace {

std::string ShellQuote(const std::string& text) {
  std::string quoted = "'";
  for (char c : text) {
    if (c == '\'') {
      quoted += "'\\''";
    } else {
      quoted += c;
    }
  }
  quoted += '\'';
  return quoted;
}

// An #SBATCH option's value as sbatch reads it: inside double quotes a space does not end the
// value, and a backslash keeps the next character (a quote, a backslash, or a '#', which would
// otherwise start a comment even inside quotes).
std::string SbatchQuote(const std::string& text) {
  std::string quoted = "\"";
  for (char c : text) {
    if (c == '"' || c == '\\' || c == '#') quoted += '\\';
    quoted += c;
  }
  quoted += '"';
  return quoted;
}

std::string QuotedList(const std::vector<std::string>& words) {
  std::string text;
  for (const std::string& word : words) {
    text += ' ';
    text += ShellQuote(word);
  }
  return text;
}

}  // namespace

// An array job of one task per scan; each task is a batch of one scan, which runs the same
// `arcwheel process` child into the same OUTDIR/<scan name> and records it as a local batch does.
std::string SlurmScript(const BatchOptions& args, const std::vector<Scan>& scans) {
  const std::string binary = ArcwheelBinary(args).string();
  const std::string outdir = fs::absolute(args.outdir).string();
  std::vector<std::string> inputs;
  for (const std::string& input : args.inputs) inputs.push_back(input);
  const std::string options = args.process_options.empty() ? "" : " --" + QuotedList(args.process_options);
  std::string script = fmt::format(
      "#!/bin/bash\n"
      "# arcwheel {} batch as a Slurm array job: one task per scan ({} scans). Each task runs\n"
      "#   arcwheel batch SCAN -o OUTDIR --no-index -- OPTIONS\n"
      "# a batch of one scan: `arcwheel process SCAN -o OUTDIR/<scan name> OPTIONS` as a child, its\n"
      "# result recorded as a local batch records it (a finished scan is skipped on a rerun).\n"
      "# Submit:  sbatch {}\n"
      "# Index, when the tasks have ended (or: sbatch --dependency=afterany:JOBID --wrap '...'):\n"
      "#   cd {} && {} batch{} -o {} --index-only{}\n"
      "#SBATCH --job-name=arcwheel-batch\n"
      "#SBATCH --array=0-{}\n"
      "#SBATCH --ntasks=1\n"
      "#SBATCH --cpus-per-task=1\n"
      "#SBATCH --chdir={}\n"
      "#SBATCH --output={}\n",
      kVersion, scans.size(), ShellQuote(fs::absolute(args.emit_slurm).string()),
      ShellQuote(fs::current_path().string()), ShellQuote(binary), QuotedList(inputs), ShellQuote(outdir),
      options, scans.size() - 1, SbatchQuote(fs::current_path().string()),
      SbatchQuote((fs::path(outdir) / kLogsFolder / "slurm-%A_%a.out").string()));
  for (const std::string& line : args.sbatch_lines) script += "#SBATCH " + line + "\n";
  script += "set -euo pipefail\nscans=(\n";
  for (const Scan& scan : scans) script += "  " + ShellQuote(fs::absolute(scan.path).string()) + "\n";
  script += ")\n";
  const std::string db = args.db.empty() ? "" : " --db " + ShellQuote(args.db);
  script += fmt::format("exec {} batch \"${{scans[$SLURM_ARRAY_TASK_ID]}}\" -o {} --no-index{}{}\n",
                        ShellQuote(binary), ShellQuote(outdir), db, options);
  return script;
}

}  // namespace arcwheel::workflows::batch
