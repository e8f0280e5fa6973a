#include "schema/version.h"

#include <fmt/format.h>

#include <charconv>

#include "core/error.h"

namespace arcwheel::schema {
namespace {

// "MAJOR.MINOR" with both parts whole numbers; std::nullopt for anything else.
std::optional<Version> ParseVersion(std::string_view text) {
  const std::size_t dot = text.find('.');
  if (dot == std::string_view::npos) return std::nullopt;
  Version version;
  const auto whole = [](std::string_view part, int& value) {
    const auto [end, error] = std::from_chars(part.data(), part.data() + part.size(), value);
    return !part.empty() && error == std::errc() && end == part.data() + part.size() && value >= 0;
  };
  if (!whole(text.substr(0, dot), version.major) || !whole(text.substr(dot + 1), version.minor)) {
    return std::nullopt;
  }
  return version;
}

}  // namespace

std::string VersionText(Version version) { return fmt::format("{}.{}", version.major, version.minor); }

void CheckVersion(const std::optional<std::string>& found, Version supported, std::string_view file,
                  std::string_view where, std::string_view stage) {
  if (!found) return;
  const std::optional<Version> version = ParseVersion(*found);
  if (!version) {
    throw Error(ErrorCode::kBadInput, stage,
                fmt::format("'{}' {} = '{}' is not a schema version MAJOR.MINOR (this arcwheel reads {})",
                            file, where, *found, VersionText(supported)));
  }
  if (version->major != supported.major) {
    throw Error(
        ErrorCode::kBadInput, stage,
        fmt::format("'{}' {} = '{}': this arcwheel reads schema version {}.x only (up to {}); use the "
                    "arcwheel version that wrote the file",
                    file, where, *found, supported.major, VersionText(supported)));
  }
}

}  // namespace arcwheel::schema
