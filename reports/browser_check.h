#pragma once
// Test helper: loads an HTML page in headless Debian chromium and records what a reader would
// not see (console messages, files and network requests the page made) and its screenshot's
// colour count. Used by the report tests.

#include <filesystem>
#include <string>
#include <vector>

namespace arcwheel::reports::testing {

struct BrowserRun {
  int exit_status = -1;
  std::vector<std::string> console;        // console messages the page logged
  std::vector<std::string> files_loaded;   // file:// URLs the page loaded
  std::vector<std::string> page_requests;  // network requests the page (not the browser) made
  std::size_t distinct_colours = 0;        // in the screenshot
};

// Loads `page` with its own fresh profile, logging verbosely (console messages, every file
// load) and recording the network log, then takes a screenshot of `width` x `height` pixels.
[[nodiscard]] BrowserRun LoadInChromium(const std::filesystem::path& page, int width, int height);

// Lays out a copy of `page` in a `width` x `height` headless chromium window with a script added
// at the end of its body, and returns the text that `expression` (JavaScript, a string) evaluates
// to there, e.g. bounding boxes from getBoundingClientRect(); "" if chromium fails.
[[nodiscard]] std::string LayoutInChromium(const std::filesystem::path& page, int width, int height,
                                           const std::string& expression);

// ---- Reading a report's text as a reader would ----

// The text of an HTML page a reader sees: without tags, inline SVG drawings (their text is glyph
// outlines, their numbers coordinates) and the style sheet; entities &amp; &lt; &gt; decoded.
[[nodiscard]] std::string VisibleHtmlText(const std::string& html);

// The most significant digits of any number in `text`: a run of digits with at most one decimal
// point, not touching a letter, digit, '_', '/' or '-' (ids, hashes, paths and dates are words, not
// numbers); leading zeros are not significant, nor trailing zeros of an integer.
[[nodiscard]] int MaxSignificantDigits(const std::string& text);
// That number, for a failure message.
[[nodiscard]] std::string LongestNumber(const std::string& text);

}  // namespace arcwheel::reports::testing
