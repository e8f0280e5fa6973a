#pragma once
// The bodies of the `process`, `toolpath` and `polish` commands as functions, so that
// `arcwheel regenerate` runs each step exactly as the single command does (same library calls,
// same files, same terminal lines).

#include <filesystem>
#include <optional>

#include "grinding/toolpath_writer.h"
#include "polishing/job.h"

namespace arcwheel::workflows {

// `arcwheel process SCAN -o OUTDIR -q`: the pipeline the command runs (workflows/process_pipeline.h),
// its options at their defaults, so that the files are those `arcwheel process` writes.
void RunProcessStep(const std::filesystem::path& scan, const std::filesystem::path& output);

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
