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

}  // namespace arcwheel::reports::testing
