#pragma once
// Regular expressions (std::regex, ECMAScript grammar) for the few texts that need one: a store's
// URL and SQL, a history's timestamps. Compiled here once: libstdc++'s regex templates cost each
// translation unit that instantiates them 2-3 CPU-s.

#include <memory>
#include <optional>
#include <string>
#include <vector>

namespace arcwheel {

// A compiled pattern; make it once (a function's static) where it is used many times.
class TextPattern {
 public:
  explicit TextPattern(const std::string& pattern);
  ~TextPattern();
  TextPattern(const TextPattern&) = delete;
  TextPattern& operator=(const TextPattern&) = delete;

  // `text` with every match replaced by `format` ($1, $2, ... the groups), as
  // std::regex_replace writes it.
  [[nodiscard]] std::string ReplaceIn(const std::string& text, const std::string& format) const;

  // When the pattern matches the whole of `text`: its groups, [0] the whole text and [i] group i,
  // or nullopt for a group that took no part in the match. Nullopt when it does not match.
  [[nodiscard]] std::optional<std::vector<std::optional<std::string>>> MatchWhole(
      const std::string& text) const;

 private:
  struct Compiled;
  std::unique_ptr<const Compiled> compiled_;
};

}  // namespace arcwheel
