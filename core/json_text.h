#pragma once
// JSON inputs as every reader takes them: whatever the parser refuses (bad syntax, a number too
// large for a double, invalid UTF-8) is bad input naming the file, never a library exception
// escaping as an internal error.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>

namespace arcwheel {

// Parses `text`, the contents of `name`. Throws Error{kBadInput, stage} naming `name`.
[[nodiscard]] nlohmann::json ParseJsonText(std::string_view text, const std::string& name,
                                           std::string_view stage);

// Reads and parses `path`. Throws Error{kIo, stage} if it cannot be read, else as ParseJsonText.
[[nodiscard]] nlohmann::json ReadJsonFile(const std::filesystem::path& path, std::string_view stage);

}  // namespace arcwheel
