#pragma once
// For fuzz targets whose reader takes a path: each input is written to a file in a folder of this
// process's own, so that the reader runs exactly as the command line runs it.

#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

namespace arcwheel::fuzz {

// The folder of this fuzzing process (created once, under TMPDIR).
inline const std::filesystem::path& WorkFolder() {
  static const std::filesystem::path folder = [] {
    const char* tmp = std::getenv("TMPDIR");
    std::filesystem::path base = tmp != nullptr ? tmp : "/tmp";
    std::filesystem::path dir = base / ("arcwheel_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir);
    return dir;
  }();
  return folder;
}

// Writes `text` to WorkFolder()/name and returns its path.
inline std::filesystem::path WriteFile(const std::string& name, const void* data, size_t size) {
  const std::filesystem::path path = WorkFolder() / name;
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(static_cast<const char*>(data), static_cast<std::streamsize>(size));
  return path;
}

inline std::filesystem::path WriteInput(const uint8_t* data, size_t size, const std::string& name) {
  return WriteFile(name, data, size);
}

}  // namespace arcwheel::fuzz
