#pragma once
// What a result was made from, recorded beside it so that a later run can skip work whose inputs
// are unchanged (`regenerate`'s steps, `batch`'s scans): the SHA-256 of each input file, the
// options and the arcwheel version, in `step_inputs.json`, written last.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <utility>
#include <vector>

namespace arcwheel::workflows {

// In each result folder: the inputs it was made from, written after every other file.
inline constexpr const char* kStepInputsFileName = "step_inputs.json";

// What a result depends on: the arcwheel version, `options`, and the SHA-256 and absolute path
// of each named file. Equal inputs give equal outputs. Throws Error{kIo} if a file cannot be read.
[[nodiscard]] nlohmann::json StepInputs(
    const std::vector<std::pair<std::string, std::filesystem::path>>& files, const nlohmann::json& options);

// True when `folder` holds every file of `outputs` and a step_inputs.json equal to `inputs` in
// version, options and SHA-256s (paths aside: a moved but unchanged file is the same input). An
// unreadable record counts as out of date.
[[nodiscard]] bool UpToDate(const std::filesystem::path& folder, const std::vector<std::string>& outputs,
                            const nlohmann::json& inputs);

}  // namespace arcwheel::workflows
