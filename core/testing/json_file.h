#pragma once
// The JSON a test reads back from a file the program wrote.

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

namespace arcwheel::testing {

// The parsed file; throws nlohmann::json::parse_error when it is not JSON (a test failure).
inline nlohmann::json ReadJson(const std::filesystem::path& path) {
  std::ifstream in(path);
  return nlohmann::json::parse(in);
}

}  // namespace arcwheel::testing
