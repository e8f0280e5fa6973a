#pragma once
// The bodies of the `process`, `toolpath` and `polish` commands as functions, so that
// `arcwheel regenerate` runs each step exactly as the single command does (same library calls,
// same files, same terminal lines).

#include <filesystem>
#include <optional>
#include <string>

#include "grinding/toolpath_writer.h"
#include "polishing/job.h"

namespace arcwheel::workflows {

// How the scan is read (formats.md 2.4): `process`'s --scan-settings, --format and --columns.
struct ProcessStepInput {
  std::string scan_settings;
  std::string format;
  std::string columns;
};

// `arcwheel process SCAN -o OUTDIR -q [--scan-settings F --format N --columns C]`: the pipeline the
// command runs (workflows/process_pipeline.h), its other options at their defaults, so that the
// files are those `arcwheel process` writes.
void RunProcessStep(const std::filesystem::path& scan, const std::filesystem::path& output,
                    const ProcessStepInput& input = {});

struct ToolpathStepResult {
  grinding::Job job;
  grinding::ToolpathRunReport report;
};

// `arcwheel toolpath JOB [--wheel SUMMARY] [--max-wheel-change-mm L] -o OUTDIR`, with its terminal
// lines.
ToolpathStepResult RunToolpathStep(
    const std::filesystem::path& job_path, const std::optional<std::filesystem::path>& wheel_summary,
    double max_wheel_change_mm, const std::filesystem::path& output,
    grinding::WheelProfileSource wheel_profile = grinding::WheelProfileSource::kMeanProfile);

// `arcwheel polish JOB -o OUTDIR`, with its terminal lines; `error_map` replaces the job's map.
polishing::PolishRunReport RunPolishStep(const std::filesystem::path& job_path,
                                         const std::optional<std::filesystem::path>& error_map,
                                         const std::filesystem::path& output);

}  // namespace arcwheel::workflows
