#pragma once
// Where the JSON-printing commands send their results.

#include <string>

namespace arcwheel::cli {

// `text` to OUTPUT (written atomically) when given, else to stdout.
void EmitText(const std::string& text, const std::string& output);
// A human-readable summary on stderr, only when stderr is a terminal.
void SummariseOnTerminal(const std::string& text);

}  // namespace arcwheel::cli
