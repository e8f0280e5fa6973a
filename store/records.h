#pragma once
// What the store records of a run, read from the files the run committed (so that the store holds
// exactly what the output folder says): summary.json of `process`, toolpath_summary.json of
// `toolpath`, polish_summary.json of `polish`. Every headline number with its sigma where the file
// records one.

#include <filesystem>
#include <optional>
#include <string>

#include "store/store.h"

namespace arcwheel::store {

// `process` into `outdir`: its scan (path and SHA-256 as summary.json states them), the
// processing parameters as used, wheel id and scan time from summary.json's "scan". Throws
// Error{kBadInput} when summary.json is unreadable.
[[nodiscard]] StoredRun ProcessRun(const std::filesystem::path& outdir, const std::string& via);

// `toolpath JOB [--wheel SUMMARY]` into `outdir`: the job and the wheel's summary.json (whose wheel
// id the run takes), the job as used.
[[nodiscard]] StoredRun ToolpathRun(const std::filesystem::path& outdir, const std::filesystem::path& job,
                                    const std::optional<std::filesystem::path>& wheel_summary,
                                    const std::string& via);

// `polish JOB` into `outdir`: the job and its error map (`error_map` when it replaced the job's,
// else the job's error_map.file, relative to the job's folder), the job as used.
[[nodiscard]] StoredRun PolishRun(const std::filesystem::path& outdir, const std::filesystem::path& job,
                                  const std::optional<std::filesystem::path>& error_map,
                                  const std::string& via);

}  // namespace arcwheel::store
