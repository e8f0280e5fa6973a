// The polishing report from a real polish run (`arcwheel polish` on the example disc job): what
// the PDF says against polish_summary.json, the HTML in a browser, `arcwheel report` on a polish
// folder, and refused inputs.
#include "reports/polish_report.h"

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/testing/testing.h"
#include "reports/browser_check.h"

namespace arcwheel::reports {
namespace {

namespace fs = std::filesystem;
using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)
using ::testing::HasSubstr;
using ::testing::Not;

// Output of a shell command (stdout), or "" when it fails.
std::string Capture(const std::string& command, const fs::path& scratch) {
  if (std::system((command + " > '" + scratch.string() + "'").c_str()) != 0) return "";
  return ReadText(scratch);
}

// Runs the example disc job into `out`, with `extra` arguments.
void Polish(const fs::path& out, const std::string& extra = "") {
  const fs::path job = SourceDir() / "polishing" / "examples" / "disc_job.json";
  const auto result = RunArcwheel(fmt::format("polish '{}' -o '{}' {}", job.string(), out.string(), extra));
  ASSERT_EQ(result.exit_status, 0) << result.output;
}

// A height as the report must print it: in nm with 1 decimal when the column's PV is below
// 0.1 um, else in um with 3 decimals (docs/reports.md).
std::string Height(double value_um, double column_pv_um) {
  return column_pv_um < 0.1 ? fmt::format("{:.1f} nm", value_um * 1000.0)
                            : fmt::format("{:.3f} µm", value_um);
}

// A duration as the report must print it (docs/reports.md).
std::string Duration(double seconds) {
  if (seconds < 600.0) return fmt::format("{:.2f} s", seconds);
  if (seconds < 7200.0) return fmt::format("{:.1f} min", seconds / 60.0);
  return fmt::format("{:.2f} h", seconds / 3600.0);
}

TEST(PolishReport, PdfCarriesPvRmsBeforeAfterAndTotalTimeRoundedFromTheSummary) {
  TempDir dir;
  Polish(dir / "out", "--report pdf,html");
  EXPECT_EQ(ListFolder(dir / "out"),
            "polish.mod\npolish_report.html\npolish_report.pdf\npolish_summary.json\npolishing_path."
            "csv\nresidual_map.csv\nresidual_map.h5\nrobot_joints.csv\n");
  const std::string summary_text = ReadText(dir / "out" / "polish_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_text);
  const std::string text = PdfText(dir / "out" / "polish_report.pdf");
  ASSERT_FALSE(text.empty()) << "poppler-utils' pdftotext is installed by scripts/install_deps.sh";
  for (const char* side : {"before", "after"}) {
    const double pv = summary[side]["pv_um"].get<double>();
    EXPECT_THAT(text, HasSubstr(Height(pv, pv))) << side;
    EXPECT_THAT(text, HasSubstr(Height(summary[side]["rms_um"].get<double>(), pv))) << side;
  }
  EXPECT_THAT(text, HasSubstr(Duration(summary["total_time_s"].get<double>())));
  EXPECT_THAT(text, HasSubstr(summary["job"]["name"].get<std::string>()));
  EXPECT_THAT(text, HasSubstr(fmt::format("{} (rows of polishing_path.csv)", summary["points"].get<int>())));
  EXPECT_THAT(text, HasSubstr(fmt::format("{:.3f} … {:.3f} mm/s", summary["speed_mm_s"]["min"].get<double>(),
                                          summary["speed_mm_s"]["max"].get<double>())));
  EXPECT_THAT(text, HasSubstr(fmt::format("{:.1f} mm/s²", summary["max_acceleration_mm_s2"].get<double>())));
  EXPECT_THAT(text,
              HasSubstr(fmt::format(
                  "{} ({})", summary["solver"]["iterations"].get<int>(),
                  summary["solver"]["converged"].get<bool>() ? "converged" : "iteration limit reached")));
  // Each source file with its SHA-256, as coreutils computes it.
  for (const char* file : {"polish_summary.json", "residual_map.csv", "polishing_path.csv"}) {
    const std::string sha =
        Capture("sha256sum '" + (dir / "out" / file).string() + "' | cut -c1-64", dir / "sha.txt");
    ASSERT_EQ(sha.size(), 65u) << file;
    EXPECT_THAT(text, HasSubstr(sha.substr(0, 64))) << file;
  }
  // Plots are vector drawings: their labels are text, including the speed limits of the job.
  for (const char* label : {"Removal target (before)", "Predicted residual (after)", "depth (µm)",
                            "speed (mm/s)", "path length (mm)", "max speed 150 mm/s", "min speed 0.5 mm/s"}) {
    EXPECT_THAT(text, HasSubstr(label));
  }
  EXPECT_THAT(Capture("pdfinfo '" + (dir / "out" / "polish_report.pdf").string() + "'", dir / "info.txt"),
              HasSubstr("595.276 x 841.89 pts (A4)"));
  EXPECT_THAT(
      ReadText(dir / "out" / "polish_report.html"),
      HasSubstr(Height(summary["after"]["rms_um"].get<double>(), summary["after"]["pv_um"].get<double>())));
  EXPECT_LE(testing::MaxSignificantDigits(text), 7) << testing::LongestNumber(text);
  EXPECT_LE(
      testing::MaxSignificantDigits(testing::VisibleHtmlText(ReadText(dir / "out" / "polish_report.html"))),
      7);
}

TEST(PolishReport, MapsShareOneColourScaleSpanningTargetRemovalAndResidual) {
  TempDir dir;
  Polish(dir / "out");
  // The range of the three columns, read here with the C library rather than the report's reader.
  double low = INFINITY, high = -INFINITY;
  std::ifstream csv(dir / "out" / "residual_map.csv");
  std::string line;
  std::getline(csv, line);
  int rows = 0;
  while (std::getline(csv, line)) {
    double x, y, target, removal, residual;
    ASSERT_EQ(std::sscanf(line.c_str(), "%lf,%lf,%lf,%lf,%lf", &x, &y, &target, &removal, &residual), 5)
        << line;
    low = std::min({low, target, removal, residual});
    high = std::max({high, target, removal, residual});
    ++rows;
  }
  const PolishReportContent content = ComposePolishReport(ReadPolishReportInputs(dir / "out"));
  ASSERT_GE(content.figure_rows.size(), 2u);
  int shared = 0;
  for (const auto* figure :
       {&content.figure_rows[0][0], &content.figure_rows[0][1], &content.figure_rows[1][0]}) {
    const auto& map = std::get<plot::HeatMap>(figure->figure);
    EXPECT_EQ(map.colour_min, low) << map.title;
    EXPECT_EQ(map.colour_max, high) << map.title;
    EXPECT_TRUE(map.equal_aspect);
    std::size_t nodes = 0;
    for (double v : map.values) nodes += std::isfinite(v) ? 1 : 0;
    EXPECT_EQ(nodes, static_cast<std::size_t>(rows)) << "every node of the file is on the map";
    ++shared;
  }
  EXPECT_EQ(shared, 3);
  const auto& own = std::get<plot::HeatMap>(content.figure_rows[1][1].figure);
  EXPECT_FALSE(own.colour_min.has_value()) << "the residual's own scale";
}

TEST(PolishReport, PlotsTheSixJointsAlongThePathWithTheSpecifiedLimits) {
  TempDir dir;
  Polish(dir / "out");
  const PolishReportContent content = ComposePolishReport(ReadPolishReportInputs(dir / "out"));
  // The example's IRB 4600-40/2.55: axis ranges of ABB's product specification (deg).
  const double limits[6][2] = {{-180, 180}, {-90, 150}, {-180, 75}, {-400, 400}, {-125, 120}, {-400, 400}};
  std::string joints_csv = ReadText(dir / "out" / "robot_joints.csv");
  const std::size_t targets =
      static_cast<std::size_t>(std::count(joints_csv.begin(), joints_csv.end(), '\n')) - 1;
  int found = 0;
  for (const auto& row : content.figure_rows) {
    for (const ReportFigure& figure : row) {
      const auto* plot = std::get_if<plot::LinePlot>(&figure.figure);
      if (plot == nullptr || plot->title.rfind("Joint ", 0) != 0) continue;
      const int joint = std::stoi(plot->title.substr(6));
      ASSERT_GE(joint, 1);
      ASSERT_LE(joint, 6);
      ASSERT_EQ(plot->series.size(), 3u) << plot->title;
      EXPECT_EQ(plot->series[0].y.size(), targets) << plot->title;
      for (int side = 0; side < 2; ++side) {
        EXPECT_TRUE(plot->series[1 + side].dashed);
        for (double y : plot->series[1 + side].y)
          EXPECT_NEAR(y, limits[joint - 1][side], 1e-9) << plot->title;
      }
      for (double angle : plot->series[0].y) {
        EXPECT_GT(angle, limits[joint - 1][0]) << plot->title;
        EXPECT_LT(angle, limits[joint - 1][1]) << plot->title;
      }
      ++found;
    }
  }
  EXPECT_EQ(found, 6);
}

TEST(PolishReport, HtmlLoadsCleanlyInChromiumOnADesktopAndAPhoneScreen) {
  TempDir dir;
  Polish(dir / "out", "--report html");
  const fs::path html = dir / "out" / "polish_report.html";
  const std::string page = ReadText(html);
  EXPECT_THAT(page, Not(HasSubstr("<script")));
  EXPECT_THAT(page, Not(HasSubstr("src=")));
  for (const auto& [width, height] : {std::pair{1280, 2400}, std::pair{390, 844}}) {
    SCOPED_TRACE(std::to_string(width) + " x " + std::to_string(height));
    const testing::BrowserRun run = testing::LoadInChromium(html, width, height);
    ASSERT_EQ(run.exit_status, 0) << "chromium is installed by scripts/install_deps.sh";
    EXPECT_THAT(run.console, ::testing::IsEmpty()) << "no console errors or warnings";
    EXPECT_THAT(run.files_loaded, ::testing::ElementsAre("file://" + html.string())) << "nothing but itself";
    EXPECT_THAT(run.page_requests, ::testing::IsEmpty()) << "no network";
    EXPECT_GT(run.distinct_colours, 100u);
  }
}

// On a 400 px phone the PV/RMS table shows its "after" column whole (it was clipped when the
// numbers had 17 digits).
TEST(PolishReport, PhoneShowsTheWholeBeforeAfterTable) {
  TempDir dir;
  Polish(dir / "out", "--report html");
  const std::string layout = testing::LayoutInChromium(
      dir / "out" / "polish_report.html", 400, 900,
      "(function() {"
      "  const table = document.querySelectorAll('table')[1];"
      "  const cells = Array.from(table.querySelectorAll('td, th'));"
      "  const right = Math.max(...cells.map(c => c.getBoundingClientRect().right));"
      "  return document.documentElement.clientWidth + ' ' + right + ' ' + "
      "table.rows[0].cells[2].textContent;"
      "})()");
  std::istringstream fields(layout);
  double viewport = 0.0, right = 0.0;
  fields >> viewport >> right;
  ASSERT_GT(viewport, 0.0) << "chromium laid the page out: '" << layout << "'";
  EXPECT_THAT(layout, HasSubstr("After (predicted residual)")) << "the table measured is the PV/RMS table";
  EXPECT_LE(right, viewport) << layout;
}

TEST(PolishReportCommand, MakesThePolishReportForAPolishFolder) {
  TempDir dir;
  Polish(dir / "out");
  EXPECT_THAT(ListFolder(dir / "out"), Not(HasSubstr("polish_report")));
  const auto result = RunArcwheel("report '" + (dir / "out").string() + "'");
  ASSERT_EQ(result.exit_status, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr((dir / "out" / "polish_report.pdf").string()));
  EXPECT_EQ(ListFolder(dir / "out"),
            "polish.mod\npolish_report.html\npolish_report.pdf\npolish_summary.json\npolishing_path."
            "csv\nresidual_map.csv\nresidual_map.h5\nrobot_joints.csv\n");
}

TEST(PolishReportCommand, RefusesACorruptResidualLineNamingFileAndLineAndKeepsTheEarlierReport) {
  TempDir dir;
  Polish(dir / "out", "--report pdf,html");
  const std::string pdf_before = ReadText(dir / "out" / "polish_report.pdf");
  const std::string html_before = ReadText(dir / "out" / "polish_report.html");
  const std::string listing = ListFolder(dir / "out");
  // Line 7 of the file (header + 5 rows before it) loses its residual value.
  const fs::path residual = dir / "out" / "residual_map.csv";
  std::istringstream lines(ReadText(residual));
  std::string corrupted;
  int number = 0;
  for (std::string line; std::getline(lines, line);) {
    if (++number == 7) line = line.substr(0, line.rfind(',')) + ",0.1.2";
    corrupted += line + "\n";
  }
  std::ofstream(residual, std::ios::trunc) << corrupted;
  const auto result = RunArcwheel("report '" + (dir / "out").string() + "'");
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_THAT(result.output,
              HasSubstr(fmt::format("'{}' line 7: residual_um '0.1.2' is not a number", residual.string())));
  EXPECT_EQ(ListFolder(dir / "out"), listing) << "no temporary or new file left";
  EXPECT_EQ(ReadText(dir / "out" / "polish_report.pdf"), pdf_before);
  EXPECT_EQ(ReadText(dir / "out" / "polish_report.html"), html_before);
}

TEST(PolishReportCommand, RefusesASummaryMissingAKeyAndWritesNothing) {
  TempDir dir;
  Polish(dir / "out");
  nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "polish_summary.json"));
  summary["after"].erase("rms_um");
  std::ofstream(dir / "out" / "polish_summary.json", std::ios::trunc) << summary.dump(2);
  const std::string listing = ListFolder(dir / "out");
  const auto result = RunArcwheel("report '" + (dir / "out").string() + "'");
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_THAT(result.output, HasSubstr("polish_summary.json' key 'after.rms_um' is missing"));
  EXPECT_EQ(ListFolder(dir / "out"), listing);
}

TEST(PolishReportCommand, RefusesWheelTolerancesForAPolishFolder) {
  TempDir dir;
  Polish(dir / "out");
  const std::string listing = ListFolder(dir / "out");
  const auto result = RunArcwheel("report '" + (dir / "out").string() + "' --tolerance max_runout_um=3");
  EXPECT_EQ(result.exit_status, 2) << result.output;
  EXPECT_THAT(result.output, HasSubstr("tolerances apply to the wheel report"));
  EXPECT_EQ(ListFolder(dir / "out"), listing);
}

}  // namespace
}  // namespace arcwheel::reports
