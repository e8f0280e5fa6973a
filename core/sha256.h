#pragma once
#include <filesystem>
#include <string>

namespace arcwheel {

// Lower-case hex SHA-256 of a file's bytes (OpenSSL). Throws Error{kIo} if it cannot be read.
[[nodiscard]] std::string Sha256OfFile(const std::filesystem::path& path);

}  // namespace arcwheel
