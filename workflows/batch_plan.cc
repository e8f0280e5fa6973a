#include <fmt/core.h>
#include <glob.h>

#include <algorithm>
#include <cctype>
#include <fstream>
#include <map>

#include "acquisition/scan_format.h"
#include "core/error.h"
#include "workflows/batch_internal.h"

namespace arcwheel::workflows::batch {

namespace {

bool IsScanFile(const fs::path& path) { return acquisition::ScanFormatOfName(path).has_value(); }

std::vector<fs::path> ScansInFolder(const fs::path& folder) {
  std::vector<fs::path> scans;
  for (const fs::directory_entry& entry : fs::directory_iterator(folder)) {
    if (entry.is_regular_file() && IsScanFile(entry.path())) scans.push_back(entry.path());
  }
  std::sort(scans.begin(), scans.end());
  return scans;
}

std::vector<fs::path> Glob(const std::string& pattern) {
  glob_t matches{};
  const int status = ::glob(pattern.c_str(), 0, nullptr, &matches);
  std::vector<fs::path> paths;
  if (status == 0) {
    for (size_t i = 0; i < matches.gl_pathc; ++i) paths.emplace_back(matches.gl_pathv[i]);
  }
  ::globfree(&matches);
  if (paths.empty()) {
    throw Error(ErrorCode::kInvalidOption, kStage, fmt::format("no file matches '{}'", pattern));
  }
  return paths;
}

// `@LIST`: one scan path a line; blank lines and lines starting with '#' are skipped, relative
// paths are relative to the list's folder.
std::vector<fs::path> ScansOfList(const fs::path& list) {
  std::ifstream in(list);
  if (!in) throw Error(ErrorCode::kIo, kStage, fmt::format("cannot read the list '{}'", list.string()));
  std::vector<fs::path> scans;
  int number = 0;
  for (std::string line; std::getline(in, line);) {
    ++number;
    while (!line.empty() && std::isspace(static_cast<unsigned char>(line.back()))) line.pop_back();
    if (line.empty() || line[0] == '#') continue;
    fs::path path = line;
    if (path.is_relative()) path = list.parent_path() / path;
    if (!fs::is_regular_file(path)) {
      throw Error(ErrorCode::kBadInput, kStage,
                  fmt::format("'{}' line {}: '{}' is not a file", list.string(), number, line));
    }
    scans.push_back(path);
  }
  return scans;
}

std::vector<fs::path> ExpandInput(const std::string& input) {
  if (!input.empty() && input[0] == '@') return ScansOfList(input.substr(1));
  if (fs::is_directory(input)) {
    std::vector<fs::path> scans = ScansInFolder(input);
    if (scans.empty()) {
      throw Error(ErrorCode::kInvalidOption, kStage,
                  fmt::format("the folder '{}' holds no {} scan", input, acquisition::ScanExtensionsText()));
    }
    return scans;
  }
  if (fs::is_regular_file(input)) return {input};
  if (input.find_first_of("*?[") != std::string::npos) return Glob(input);
  throw Error(ErrorCode::kInvalidOption, kStage,
              fmt::format("'{}' is neither a scan, a folder, a glob nor an @list", input));
}

}  // namespace

std::vector<Scan> PlanScans(const std::vector<std::string>& inputs) {
  std::vector<Scan> scans;
  std::map<fs::path, size_t> by_file;
  std::map<std::string, size_t> by_name;
  for (const std::string& input : inputs) {
    for (const fs::path& path : ExpandInput(input)) {
      const fs::path file = fs::weakly_canonical(path);
      if (by_file.count(file) != 0) continue;
      const std::string name = path.stem().string();
      if (name == kLogsFolder) {
        throw Error(
            ErrorCode::kInvalidOption, kStage,
            fmt::format("the scan '{}' would be written to OUTDIR/{}, which holds the logs: rename it",
                        path.string(), name));
      }
      if (const auto clash = by_name.find(name); clash != by_name.end()) {
        throw Error(ErrorCode::kInvalidOption, kStage,
                    fmt::format("'{}' and '{}' would both be written to OUTDIR/{}: rename one, or run them "
                                "as two batches into different folders",
                                scans[clash->second].path.string(), path.string(), name));
      }
      by_file[file] = scans.size();
      by_name[name] = scans.size();
      scans.push_back({path, name});
    }
  }
  if (scans.empty()) throw Error(ErrorCode::kInvalidOption, kStage, "no scans given");
  return scans;
}

}  // namespace arcwheel::workflows::batch
