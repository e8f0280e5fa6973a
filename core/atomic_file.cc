#include "core/atomic_file.h"

#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <system_error>

#include "core/error.h"

namespace arcwheel {
namespace fs = std::filesystem;

OutputSet::~OutputSet() {
  if (committed_) return;
  for (const Entry& entry : entries_) {
    std::error_code ignored;
    fs::remove(entry.temporary, ignored);
  }
  for (const fs::path& folder : created_folders_) {
    std::error_code ignored;
    fs::remove(folder, ignored);  // removes a folder only while it is empty
  }
}

void OutputSet::CreateFolder(const fs::path& directory) {
  std::vector<fs::path> missing;
  std::error_code error;
  for (fs::path p = directory; !p.empty() && !fs::exists(p, error); p = p.parent_path()) {
    missing.push_back(p);
    if (p == p.parent_path()) break;
  }
  EnsureDirectory(directory);
  created_folders_.insert(created_folders_.end(), missing.begin(), missing.end());
}

fs::path OutputSet::Stage(const fs::path& final_path) {
  // The pid keeps two concurrent runs on the same folder from sharing a temporary.
  fs::path temporary = final_path;
  temporary += ".tmp-" + std::to_string(::getpid());
  entries_.push_back({temporary, final_path});
  return temporary;
}

void OutputSet::Commit() {
  for (const Entry& entry : entries_) {
    if (std::rename(entry.temporary.c_str(), entry.final.c_str()) != 0) {
      throw Error(ErrorCode::kIo, "output",
                  "cannot rename '" + entry.temporary.string() + "' to '" + entry.final.string() +
                      "': " + std::strerror(errno));
    }
  }
  committed_ = true;
}

void WriteFileAtomically(const fs::path& path, const std::string& contents) {
  OutputSet outputs;
  const fs::path temporary = outputs.Stage(path);
  {
    std::ofstream out(temporary, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw Error(ErrorCode::kIo, "output",
                  "cannot create '" + temporary.string() + "': " + std::strerror(errno));
    }
    out.write(contents.data(), static_cast<std::streamsize>(contents.size()));
    out.flush();
    if (!out) {
      throw Error(ErrorCode::kIo, "output",
                  "cannot write '" + path.string() + "' (disk full?): " + std::strerror(errno));
    }
  }
  outputs.Commit();
}

void EnsureDirectory(const fs::path& directory) {
  std::error_code error;
  fs::create_directories(directory, error);
  if (error || !fs::is_directory(directory)) {
    throw Error(ErrorCode::kIo, "output",
                "cannot create folder '" + directory.string() + "': " + error.message());
  }
}

}  // namespace arcwheel
