#include "reports/browser_check.h"

#include <cairo.h>

#include <cstdint>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>

#include "core/testing/testing.h"

namespace arcwheel::reports::testing {
namespace {

namespace fs = std::filesystem;
using arcwheel::testing::ReadText;
using arcwheel::testing::Shell;
using arcwheel::testing::TempDir;

std::size_t DistinctColours(const fs::path& png) {
  cairo_surface_t* image = cairo_image_surface_create_from_png(png.c_str());
  std::set<std::uint32_t> colours;
  if (cairo_surface_status(image) == CAIRO_STATUS_SUCCESS) {
    const int stride = cairo_image_surface_get_stride(image);
    const unsigned char* data = cairo_image_surface_get_data(image);
    for (int row = 0; row < cairo_image_surface_get_height(image); ++row) {
      const auto* line = reinterpret_cast<const std::uint32_t*>(data + row * stride);
      colours.insert(line, line + cairo_image_surface_get_width(image));
    }
  }
  cairo_surface_destroy(image);
  return colours.size();
}

}  // namespace

BrowserRun LoadInChromium(const fs::path& page, int width, int height) {
  TempDir work;
  const fs::path log = work / "chromium.log";
  const fs::path net_log = work / "net.json";
  const fs::path shot = work / "shot.png";
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run "
      "--disable-background-networking --disable-component-update --disable-sync --user-data-dir='" +
      (work / "profile").string() + "' --enable-logging=stderr --v=1 --log-net-log='" + net_log.string() +
      "' --screenshot='" + shot.string() + "' --window-size=" + std::to_string(width) + "," +
      std::to_string(height) + " 'file://" + page.string() + "' > /dev/null 2> '" + log.string() + "'";
  BrowserRun run;
  run.exit_status = Shell(command);
  std::istringstream lines(ReadText(log));
  for (std::string line; std::getline(lines, line);) {
    if (line.find(":CONSOLE") != std::string::npos) run.console.push_back(line);
    if (const auto at = line.find("FileURLLoader::Start: "); at != std::string::npos) {
      run.files_loaded.push_back(line.substr(at + 22));
    }
  }
  // Requests the browser makes for itself carry no origin; the page's carry its own ("null" for
  // a file:// page).
  const nlohmann::json net = nlohmann::json::parse(ReadText(net_log), nullptr, false);
  if (net.is_object() && net.contains("events")) {
    for (const auto& event : net["events"]) {
      const auto params = event.find("params");
      if (params == event.end() || !params->contains("url") || !params->contains("initiator")) continue;
      if ((*params)["initiator"] != "not an origin")
        run.page_requests.push_back((*params)["url"].get<std::string>());
    }
  }
  run.distinct_colours = DistinctColours(shot);
  return run;
}

}  // namespace arcwheel::reports::testing
