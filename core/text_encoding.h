#pragma once
// Text from users' files into valid UTF-8 (summary.json and the reports must stay valid UTF-8).

#include <string>
#include <string_view>

namespace arcwheel {

// True if `text` is well-formed UTF-8 (no overlong forms, surrogates or code points past U+10FFFF).
[[nodiscard]] bool IsValidUtf8(std::string_view text);

// Each byte as the Latin-1 (ISO 8859-1) character of that code, encoded in UTF-8.
[[nodiscard]] std::string Latin1ToUtf8(std::string_view text);

// `text` as it is when it is valid UTF-8, else read as Latin-1; `was_latin1` says which.
[[nodiscard]] std::string AsUtf8(std::string_view text, bool& was_latin1);

// ASCII letters folded to lower case (metadata keys match case-insensitively).
[[nodiscard]] std::string AsciiLower(std::string_view text);

}  // namespace arcwheel
