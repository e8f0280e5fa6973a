#pragma once
// The schema version every output file records ("MAJOR.MINOR", docs/outputs.md), and the rule by
// which readers accept it: a file without a version (written before versions were recorded) or of
// the same major version is read; a newer major version is refused, because its keys may mean
// something this reader does not know. A newer minor version only adds keys, which readers ignore.

#include <optional>
#include <string>
#include <string_view>

namespace arcwheel::schema {

struct Version {
  int major = 0;
  int minor = 0;
};

// "1.0" for {1, 0}.
[[nodiscard]] std::string VersionText(Version version);

// Throws Error{kBadInput, stage} unless `found` (the file's schema_version, std::nullopt when the
// file records none) is readable by a reader of `supported`. The message names `file`, `where`
// (the key or attribute that holds the version), the version found and the version supported.
void CheckVersion(const std::optional<std::string>& found, Version supported, std::string_view file,
                  std::string_view where, std::string_view stage);

}  // namespace arcwheel::schema
