#pragma once
// JSON inputs as every reader takes them: whatever the parser refuses (bad syntax, a number too
// large for a double, invalid UTF-8) is bad input naming the file, never a library exception
// escaping as an internal error. And JSON text as every writer makes it.
//
// nlohmann-json's parser and serializer are templates that each translation unit calling them
// compiles anew (2.5 and 1.5 CPU-s at -O3); here they are compiled once, for every library.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <string_view>

#include "core/error.h"

namespace arcwheel {

// Parses `text`, the contents of `name`. Throws Error{code, stage} naming `name`.
[[nodiscard]] nlohmann::json ParseJsonText(std::string_view text, const std::string& name,
                                           std::string_view stage, ErrorCode code = ErrorCode::kBadInput);

// Reads and parses `path`. Throws Error{kIo, stage} if it cannot be read, else as ParseJsonText.
[[nodiscard]] nlohmann::json ReadJsonFile(const std::filesystem::path& path, std::string_view stage);

// The text of `value` as nlohmann::json::dump(indent) writes it: one line when indent < 0, else
// one member or element a line, indented by `indent` spaces; UTF-8 kept as it is.
[[nodiscard]] std::string JsonText(const nlohmann::json& value, int indent = -1);

}  // namespace arcwheel
