#include "core/json_text.h"

#include <fmt/core.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.h"

namespace arcwheel {

nlohmann::json ParseJsonText(std::string_view text, const std::string& name, std::string_view stage,
                             ErrorCode code) {
  try {
    return nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& error) {
    // parse_error for syntax, out_of_range for a number that overflows a double.
    throw Error(code, stage, fmt::format("'{}' is not valid JSON: {}", name, error.what()));
  }
}

nlohmann::json ReadJsonFile(const std::filesystem::path& path, std::string_view stage) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(ErrorCode::kIo, stage, fmt::format("cannot open '{}'", path.string()));
  std::stringstream text;
  text << in.rdbuf();
  if (in.bad()) throw Error(ErrorCode::kIo, stage, fmt::format("cannot read '{}'", path.string()));
  return ParseJsonText(text.str(), path.string(), stage);
}

std::string JsonText(const nlohmann::json& value, int indent) { return value.dump(indent); }

}  // namespace arcwheel
