#pragma once
// Regular expressions (std::regex, ECMAScript grammar) for the few texts that need one: a store's
// URL and SQL, a history's timestamps. Compiled here once: libstdc++'s regex templates cost each
// translation unit that instantiates them 2-3 CPU-s.

#include <optional>
#include <string>
#include <vector>

namespace arcwheel {

// `text` with every match of `pattern` replaced by `format` ($1, $2, ... its groups), as
// std::regex_replace writes it.
[[nodiscard]] std::string ReplaceMatches(const std::string& text, const std::string& pattern,
                                         const std::string& format);

// When `pattern` matches the whole of `text`: its groups, [0] the whole text and [i] group i, or
// nullopt for a group that took no part in the match. Nullopt when it does not match.
[[nodiscard]] std::optional<std::vector<std::optional<std::string>>> MatchWhole(const std::string& text,
                                                                                const std::string& pattern);

}  // namespace arcwheel
