#include "core/text_pattern.h"

#include <regex>

namespace arcwheel {

struct TextPattern::Compiled {
  std::regex regex;
};

TextPattern::TextPattern(const std::string& pattern) : compiled_(new Compiled{std::regex(pattern)}) {}

TextPattern::~TextPattern() = default;

std::string TextPattern::ReplaceIn(const std::string& text, const std::string& format) const {
  return std::regex_replace(text, compiled_->regex, format);
}

std::optional<std::vector<std::optional<std::string>>> TextPattern::MatchWhole(
    const std::string& text) const {
  std::smatch match;
  if (!std::regex_match(text, match, compiled_->regex)) return std::nullopt;
  std::vector<std::optional<std::string>> groups;
  for (const auto& group : match) groups.push_back(group.matched ? std::optional(group.str()) : std::nullopt);
  return groups;
}

}  // namespace arcwheel
