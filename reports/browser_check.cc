#include "reports/browser_check.h"

#include <cairo.h>

#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <nlohmann/json.hpp>
#include <set>
#include <sstream>
#include <utility>
#include <vector>

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

std::string LayoutInChromium(const fs::path& page, int width, int height, const std::string& expression) {
  // Headless chromium keeps its window at least 500 px wide, so the page is laid out in an iframe
  // of the wanted size; the probe inside posts its result to the frame's parent, which holds it
  // where --dump-dom sees it.
  TempDir work;
  std::string html = ReadText(page);
  const std::string probe = "<script>parent.postMessage(String(" + expression + "), '*');</script>";
  const std::size_t end = html.rfind("</body>");
  html.insert(end == std::string::npos ? html.size() : end, probe);
  std::ofstream(work / "page.html") << html;
  std::ofstream(work / "frame.html")
      << "<!DOCTYPE html><html><body style=\"margin:0\"><script>window.addEventListener('message', e => {"
         "const pre = document.createElement('pre'); pre.id = 'layout-probe'; pre.textContent = e.data;"
         "document.body.appendChild(pre); });</script><iframe src=\"page.html\" style=\"border:0; width:"
      << width << "px; height:" << height << "px\"></iframe></body></html>";
  const fs::path dom = work / "dom.html";
  const std::string command =
      "chromium --headless --no-sandbox --disable-gpu --no-first-run --disable-background-networking "
      "--disable-component-update --disable-sync --allow-file-access-from-files --virtual-time-budget=5000 "
      "--user-data-dir='" +
      (work / "profile").string() + "' --window-size=" + std::to_string(width + 200) + "," +
      std::to_string(height + 100) + " --dump-dom 'file://" + (work / "frame.html").string() + "' > '" +
      dom.string() + "' 2> /dev/null";
  if (Shell(command) != 0) return "";
  const std::string text = ReadText(dom);
  // The last one: the script that makes it holds the same words.
  const std::size_t start = text.rfind("<pre id=\"layout-probe\">");
  if (start == std::string::npos) return "";
  const std::size_t from = start + std::string("<pre id=\"layout-probe\">").size();
  return text.substr(from, text.find("</pre>", from) - from);
}

std::string VisibleHtmlText(const std::string& html) {
  // By hand: std::regex recurses per character and overflows the stack on a page of inline SVG.
  std::string text;
  std::size_t i = 0;
  while (i < html.size()) {
    if (html[i] != '<') {
      text += html[i++];
      continue;
    }
    for (const char* block : {"svg", "style"}) {
      if (html.compare(i + 1, std::strlen(block), block) == 0) {
        const std::size_t close = html.find(std::string("</") + block + ">", i);
        i = close == std::string::npos ? html.size() : close;
        break;
      }
    }
    const std::size_t tag_end = html.find('>', i);
    i = tag_end == std::string::npos ? html.size() : tag_end + 1;
    text += ' ';
  }
  for (const auto& [entity, character] :
       {std::pair{"&amp;", "&"}, std::pair{"&lt;", "<"}, std::pair{"&gt;", ">"}, std::pair{"&#39;", "'"},
        std::pair{"&quot;", "\""}}) {
    for (std::size_t at = text.find(entity); at != std::string::npos; at = text.find(entity, at + 1))
      text.replace(at, std::strlen(entity), character);
  }
  return text;
}

namespace {

bool IsWordCharacter(char c) {
  return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '/' || c == '-';
}

// Every number of `text` (see MaxSignificantDigits) with its significant digit count.
std::vector<std::pair<std::string, int>> Numbers(const std::string& text) {
  std::vector<std::pair<std::string, int>> numbers;
  std::size_t i = 0;
  while (i < text.size()) {
    if (!std::isdigit(static_cast<unsigned char>(text[i]))) {
      ++i;
      continue;
    }
    std::size_t end = i;
    while (end < text.size() && (std::isdigit(static_cast<unsigned char>(text[end])) || text[end] == '.'))
      ++end;
    std::string run = text.substr(i, end - i);
    while (!run.empty() && run.back() == '.') run.pop_back();  // a full stop
    const bool word =
        (i > 0 && IsWordCharacter(text[i - 1])) || (end < text.size() && IsWordCharacter(text[end]));
    const auto points = std::count(run.begin(), run.end(), '.');
    if (!word && points <= 1) {
      std::string digits = run;
      std::erase(digits, '.');
      digits.erase(0, std::min(digits.find_first_not_of('0'), digits.size()));
      if (points == 0 && !digits.empty()) digits.erase(digits.find_last_not_of('0') + 1);
      numbers.emplace_back(run, static_cast<int>(digits.size()));
    }
    i = end;
  }
  return numbers;
}

}  // namespace

int MaxSignificantDigits(const std::string& text) {
  int most = 0;
  for (const auto& [number, digits] : Numbers(text)) most = std::max(most, digits);
  return most;
}

std::string LongestNumber(const std::string& text) {
  std::string longest;
  int most = -1;
  for (const auto& [number, digits] : Numbers(text)) {
    if (digits > most) most = digits, longest = number;
  }
  return longest;
}

}  // namespace arcwheel::reports::testing
