// Every number a person reads from `process`, `toolpath`, `polish` and `regenerate` (their terminal
// lines and the text of their HTML and PDF reports) shows at most seven significant digits
// (core/number_format.h). The digits are counted here, independently of the formatter.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include <regex>
#include <string>
#include <vector>

#include "core/testing/testing.h"

namespace arcwheel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using testing::ReadText;
using testing::RunArcwheel;
using testing::TempDir;
using testing::WriteText;

constexpr int kMaxDigits = 7;

// Significant digits of a number token as printed: leading zeros do not count, zeros after the
// point do, trailing zeros of a whole number do not (they say where it was rounded).
int SignificantDigits(const std::string& token) {
  const std::string mantissa = token.substr(0, token.find_first_of("eE"));
  std::string digits;
  for (char c : mantissa) {
    if (c >= '0' && c <= '9') digits += c;
  }
  const size_t first = digits.find_first_not_of('0');
  if (first == std::string::npos) return 0;
  digits = digits.substr(first);
  if (mantissa.find('.') == std::string::npos) digits = digits.substr(0, digits.find_last_not_of('0') + 1);
  return static_cast<int>(digits.size());
}

// The numbers in `text` with more than seven significant digits. Not numbers a person reads as
// measurements: dates and times, version numbers, paths and hashes.
std::vector<std::string> OverlongNumbers(std::string text) {
  static const std::vector<std::regex> kNotMeasurements = {
      std::regex(R"(\d{4}-\d{2}-\d{2}([T ]\d{2}:\d{2}(:\d{2}(\.\d+)?)?Z?)?)"),  // dates and times
      std::regex(R"(\b\d{1,2}:\d{2}(:\d{2})?\b)"),                              // clock times
      std::regex(R"(\b\d+\.\d+\.\d+\b)"),                                       // versions
      std::regex(R"(\S*/\S*)"),                                                 // paths, units per unit
      std::regex(R"(\b[0-9a-f]{12,}\b)"),                                       // hashes
  };
  for (const std::regex& pattern : kNotMeasurements) text = std::regex_replace(text, pattern, " ");
  static const std::regex kNumber(R"((^|[^\w.])(\d+(\.\d+)?([eE][-+]?\d+)?)(?![\w]))");
  std::vector<std::string> overlong;
  for (auto it = std::sregex_iterator(text.begin(), text.end(), kNumber); it != std::sregex_iterator();
       ++it) {
    const std::string token = (*it)[2];
    if (SignificantDigits(token) > kMaxDigits) overlong.push_back(token);
  }
  return overlong;
}

// What a browser shows of a page: the text between the tags, without styles and scripts (an SVG
// plot's tick labels are text; its path coordinates are not).
std::string VisibleText(const std::string& html) {
  static const std::regex kStyle(R"(<style[\s\S]*?</style>)");
  static const std::regex kScript(R"(<script[\s\S]*?</script>)");
  static const std::regex kTag(R"(<[^>]*>)");
  std::string text = std::regex_replace(html, kStyle, " ");
  text = std::regex_replace(text, kScript, " ");
  return std::regex_replace(text, kTag, " ");
}

TEST(ShownDigits, TheCheckFlagsAFullPrecisionDoubleAndPassesRoundedOnes) {
  EXPECT_THAT(OverlongNumbers("measured 55.401577631285676 mm"),
              ::testing::ElementsAre("55.401577631285676"));
  EXPECT_THAT(OverlongNumbers("Ra = 55.40158 mm, Rb = 144.5984 mm, range 0.0452 mm (−0.00012)"),
              ::testing::IsEmpty());
  EXPECT_THAT(OverlongNumbers("[\"toolpath.csv\",144.59842236871432]"),
              ::testing::ElementsAre("144.59842236871432"));
  EXPECT_THAT(OverlongNumbers("1.2345678e-05 and 132000000 samples"),
              ::testing::ElementsAre("1.2345678e-05"));
  EXPECT_THAT(OverlongNumbers("written 2026-12-03T07:26:23Z by arcwheel 0.1.0 to /tmp/a1234567890/b, "
                              "sha256 9f86d081884c7d659a2feaa0c55ad015"),
              ::testing::IsEmpty());
  EXPECT_THAT(OverlongNumbers(VisibleText("<svg><path d=\"M 1.23456789 2\"/><text>0.123456789</text></svg>")),
              ::testing::ElementsAre("0.123456789"));
}

// The shipped trial part with coarse rows and map, so that the chain runs in seconds.
json SmallTrialPart() {
  json job = json::parse(ReadText(testing::SourceDir() / "grinding/examples/trial_part.json"));
  job["path"]["step_over_mm"] = 10.0;
  job["path"]["point_spacing_mm"] = 10.0;
  job["gouge_check"] = {{"spacing_mm", 50.0}, {"samples", 9}};
  job["prediction"]["map_nodes"] = {44, 44};
  return job;
}

json TrialPolishJob(const json& part) {
  return {{"name", "trial part after grinding"},
          {"surface", part["surface"]},
          {"aperture", part["aperture"]},
          {"error_map", json::object()},
          {"removal_target", {{"uniform_layer_um", 0.2}}},
          {"removal_function", {{"peak_rate_um_per_s", 0.1}, {"fwhm_mm", 60.0}}},
          {"path", {{"line_spacing_mm", 10.0}, {"point_spacing_mm", 10.0}, {"extension_mm", 40.0}}},
          {"machine", {{"max_speed_mm_s", 500.0}}}};
}

void ExpectShortNumbers(const std::string& what, const std::string& text) {
  EXPECT_FALSE(text.empty()) << what << " is empty";
  EXPECT_THAT(OverlongNumbers(text), ::testing::IsEmpty()) << what << ":\n" << text;
}

void ExpectShortNumbersInReport(const fs::path& html, const fs::path& pdf) {
  ExpectShortNumbers(html.string(), VisibleText(ReadText(html)));
  ExpectShortNumbers(pdf.string(), testing::PdfText(pdf));
}

class ShownDigitsOfCommands : public ::testing::Test {
 protected:
  TempDir dir_;
  const fs::path scan_ = testing::SourceDir() / "testdata/paper_wheel_scan.h5";
};

TEST_F(ShownDigitsOfCommands, ProcessAndItsReport) {
  const auto run =
      RunArcwheel("process " + scan_.string() + " -o " + (dir_ / "p").string() + " --report html,pdf");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  ExpectShortNumbers("process output", run.output);
  ExpectShortNumbersInReport(dir_ / "p/report.html", dir_ / "p/report.pdf");
}

TEST_F(ShownDigitsOfCommands, ToolpathPolishAndRegenerateAndTheirReports) {
  const json part = SmallTrialPart();
  WriteText(dir_ / "part.json", part.dump(2));
  WriteText(dir_ / "polish.json", TrialPolishJob(part).dump(2));
  const auto regenerate =
      RunArcwheel("regenerate --scan " + scan_.string() + " --job " + (dir_ / "part.json").string() +
                  " --polish " + (dir_ / "polish.json").string() + " -o " + (dir_ / "r").string());
  ASSERT_EQ(regenerate.exit_status, 0) << regenerate.output;
  ExpectShortNumbers("regenerate output", regenerate.output);
  ExpectShortNumbersInReport(dir_ / "r/regenerate_report.html", dir_ / "r/regenerate_report.pdf");

  const auto toolpath =
      RunArcwheel("toolpath " + (dir_ / "part.json").string() + " --wheel " +
                  (dir_ / "r/wheel/summary.json").string() + " -o " + (dir_ / "t").string());
  ASSERT_EQ(toolpath.exit_status, 0) << toolpath.output;
  ExpectShortNumbers("toolpath output", toolpath.output);

  const auto polish =
      RunArcwheel("polish " + (testing::SourceDir() / "polishing/examples/disc_job.json").string() + " -o " +
                  (dir_ / "q").string() + " --report html,pdf");
  ASSERT_EQ(polish.exit_status, 0) << polish.output;
  ExpectShortNumbers("polish output", polish.output);
  ExpectShortNumbersInReport(dir_ / "q/polish_report.html", dir_ / "q/polish_report.pdf");
}

}  // namespace
}  // namespace arcwheel
