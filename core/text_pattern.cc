#include "core/text_pattern.h"

#include <regex>

namespace arcwheel {

std::string ReplaceMatches(const std::string& text, const std::string& pattern, const std::string& format) {
  return std::regex_replace(text, std::regex(pattern), format);
}

std::optional<std::vector<std::optional<std::string>>> MatchWhole(const std::string& text,
                                                                  const std::string& pattern) {
  std::smatch match;
  if (!std::regex_match(text, match, std::regex(pattern))) return std::nullopt;
  std::vector<std::optional<std::string>> groups;
  for (const auto& group : match) groups.push_back(group.matched ? std::optional(group.str()) : std::nullopt);
  return groups;
}

}  // namespace arcwheel
