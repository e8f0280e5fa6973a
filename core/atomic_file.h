#pragma once
// Outputs are never written half: a file is written under a temporary name in its final folder
// and renamed over the final name only when complete (rename(2) is atomic within a file system).

#include <filesystem>
#include <functional>
#include <string>
#include <vector>

namespace arcwheel {

// A set of output files committed together. Each Stage() returns the temporary path to write;
// Commit() renames all of them into place; destruction without Commit() removes the temporaries,
// so an exception or an interrupt leaves earlier outputs untouched.
class OutputSet {
 public:
  OutputSet() = default;
  OutputSet(const OutputSet&) = delete;
  OutputSet& operator=(const OutputSet&) = delete;
  ~OutputSet();

  // Creates `directory` and any missing parents; Error{kIo} naming it if that fails. The folders
  // this had to create are removed again (those still empty) when the set is destroyed without
  // Commit(): a failed run leaves no new folder behind, as it leaves no file.
  void CreateFolder(const std::filesystem::path& directory);
  // Reserves `final_path` and returns the temporary path (same folder) to write it to.
  [[nodiscard]] std::filesystem::path Stage(const std::filesystem::path& final_path);
  // Renames every staged file into place. Throws Error{kIo} naming the file that failed.
  void Commit();

 private:
  struct Entry {
    std::filesystem::path temporary;
    std::filesystem::path final;
  };
  std::vector<Entry> entries_;
  std::vector<std::filesystem::path> created_folders_;  // innermost first
  bool committed_ = false;
};

// Writes `contents` to `path` through a temporary file and a rename. Throws Error{kIo}.
void WriteFileAtomically(const std::filesystem::path& path, const std::string& contents);

// Creates `directory` (and parents) if needed. Throws Error{kIo} naming it.
void EnsureDirectory(const std::filesystem::path& directory);

}  // namespace arcwheel
