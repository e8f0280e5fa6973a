#include "workflows/step_inputs.h"

#include <nlohmann/json.hpp>

#include "core/error.h"
#include "core/json_text.h"
#include "core/sha256.h"
#include "core/version.h"

namespace arcwheel::workflows {

namespace fs = std::filesystem;
using nlohmann::json;

json StepInputs(const std::vector<std::pair<std::string, fs::path>>& files, const json& options) {
  json inputs = {{"arcwheel_version", kVersion},
                 {"options", options},
                 {"sha256", json::object()},
                 {"paths", json::object()}};
  for (const auto& [name, path] : files) {
    inputs["sha256"][name] = Sha256OfFile(path);
    inputs["paths"][name] = fs::absolute(path).string();
  }
  return inputs;
}

bool UpToDate(const fs::path& folder, const std::vector<std::string>& outputs, const json& inputs) {
  for (const std::string& name : outputs) {
    if (!fs::exists(folder / name)) return false;
  }
  const fs::path recorded_path = folder / kStepInputsFileName;
  if (!fs::exists(recorded_path)) return false;
  try {
    const json recorded = ReadJsonFile(recorded_path, "step_inputs");
    for (const char* key : {"arcwheel_version", "options", "sha256"}) {
      if (!recorded.contains(key) || recorded.at(key) != inputs.at(key)) return false;
    }
    return true;
  } catch (const Error&) {
    return false;  // unreadable: redo the step
  }
}

}  // namespace arcwheel::workflows
