#include "reports/report.h"

#include <cairo.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>

#include "core/error.h"
#include "core/testing/testing.h"
#include "reports/browser_check.h"
#include "reports/report_fixture.h"

namespace arcwheel::reports {
namespace {

namespace fs = std::filesystem;
using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)
using testing::BrowserRun;
using testing::FixtureOptions;
using ::testing::HasSubstr;
using testing::LoadInChromium;
using ::testing::Not;
using testing::WriteFixture;

// The fixture's headline literals (reports/report_fixture.cc) as the report must print them:
// mm with 4 decimals (mean radius and sigma with 5), um with 2, percent with 3.
const std::vector<std::string> kFixtureHeadline = {
    "75.01234 ± 0.00021 mm", "0.0061 mm", "0.008 %", "0.0043 mm", "1.58 µm", "7.13 µm", "3.47 µm"};

Tolerances FixtureTolerances() {
  Tolerances t;
  t.limits["mean_arc_radius_mm"] = {.min = 74.9, .max = 75.1};  // 75.01234: pass
  t.limits["max_runout_um"] = {.max = 7.0};                     // 7.13: fail
  t.limits["max_arc_error_um"] = {.max = 2.0};                  // 1.58: pass
  return t;
}

TEST(ComposeReport, ShowsTheSummaryHeadlineNumbersAndJudgesThemAgainstTolerances) {
  TempDir dir;
  WriteFixture(dir.path());
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), FixtureTolerances());
  ASSERT_EQ(content.headline.size(), kFixtureHeadline.size());
  for (std::size_t i = 0; i < kFixtureHeadline.size(); ++i) {
    EXPECT_EQ(content.headline[i].key, kHeadlineKeys[i]);
    EXPECT_EQ(content.headline[i].value, kFixtureHeadline[i]);
  }
  EXPECT_EQ(content.headline[0].verdict, Verdict::kPass);
  EXPECT_EQ(content.headline[0].tolerance, "74.9 … 75.1 mm");
  EXPECT_EQ(content.headline[1].verdict, Verdict::kNoTolerance);
  EXPECT_EQ(content.headline[4].verdict, Verdict::kPass);
  EXPECT_EQ(content.headline[5].verdict, Verdict::kFail);
  EXPECT_EQ(content.headline[5].tolerance, "≤ 7 µm");
  EXPECT_EQ(content.overall, Verdict::kFail);
  EXPECT_EQ(content.title, "Wheel inspection report: W17-arc75");
}

TEST(ComposeReport, PassesOverallOnlyWhenEveryToleranceHolds) {
  TempDir dir;
  WriteFixture(dir.path());
  const ReportInputs inputs = ReadReportInputs(dir.path());
  Tolerances t = FixtureTolerances();
  t.limits["max_runout_um"] = {.max = 7.13};
  EXPECT_EQ(ComposeReport(inputs, t).overall, Verdict::kPass);
  EXPECT_EQ(ComposeReport(inputs, Tolerances{}).overall, Verdict::kNoTolerance);
}

// `processing` is flat in the file (one key per parameter, as the writer records them).
TEST(ComposeReport, ListsTheProcessingParametersByTheirKeys) {
  TempDir dir;
  WriteFixture(dir.path());
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), {});
  std::map<std::string, std::string> rows;
  for (const KeyValue& row : content.processing) rows[row.key] = row.value;
  // The parameters the fixture records (report_fixture.h), strings unquoted.
  EXPECT_EQ(rows["despike_threshold_um"], "5.0");
  EXPECT_EQ(rows["band_half_width_mm"], "8.0");
  EXPECT_EQ(rows["fit_span"], "band");
  EXPECT_EQ(rows["axial_step_mm"], "0.1");
}

TEST(SectionResiduals, AreZeroForPointsOnTheCircle) {
  TempDir dir;
  WriteFixture(dir.path());
  const ReportInputs inputs = ReadReportInputs(dir.path());
  const SectionResidual r = SectionResiduals(inputs, 5);
  // Band [2, 18] mm on nodes 0.1 mm apart: 161 nodes.
  ASSERT_EQ(r.y_mm.size(), 161u);
  for (double residual : r.residual_um) EXPECT_NEAR(residual, 0.0, 1e-6);
}

TEST(SectionResiduals, MatchTheClosedFormForARadialShift) {
  // Every rho shifted by d: |p - centre| = sqrt(R^2 + 2 d s + d^2) with s = sqrt(R^2 - u^2).
  constexpr double kShift_um = 2.0;
  TempDir dir;
  WriteFixture(dir.path(), {.radial_offset_um = kShift_um});
  const ReportInputs inputs = ReadReportInputs(dir.path());
  const std::size_t k = 7;
  const double phase = inputs.summary.phases.phase_deg[k];
  const double radius = testing::FixtureArcRadius_mm(phase);
  const double a = testing::FixtureCenterAxial_mm(phase);
  const SectionResidual r = SectionResiduals(inputs, k);
  ASSERT_FALSE(r.y_mm.empty());
  const double d = kShift_um / 1000.0;
  for (std::size_t j = 0; j < r.y_mm.size(); ++j) {
    const double s = std::sqrt(radius * radius - (r.y_mm[j] - a) * (r.y_mm[j] - a));
    const double expected_um = (std::sqrt(radius * radius + 2.0 * d * s + d * d) - radius) * 1000.0;
    EXPECT_NEAR(r.residual_um[j], expected_um, 1e-6) << "y = " << r.y_mm[j];
  }
}

TEST(WriteReports, PdfTextCarriesTheHeadlineNumbersAsInTheSummary) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  EXPECT_EQ(written.overall, Verdict::kFail);
  ASSERT_EQ(
      Shell("pdftotext -enc UTF-8 '" + written.pdf.string() + "' '" + (dir / "report.txt").string() + "'"), 0)
      << "poppler-utils' pdftotext is installed by scripts/install_deps.sh";
  const std::string text = ReadText(dir / "report.txt");
  for (const std::string& number : kFixtureHeadline) EXPECT_THAT(text, HasSubstr(number));
  EXPECT_THAT(text, HasSubstr("W17-arc75"));
  EXPECT_THAT(text, HasSubstr("3b1f5e0c9a7d4e2b8c6f1a0d9e8b7c6a")) << "SHA-256 of the input";
  EXPECT_THAT(text, HasSubstr("Overall: FAIL"));
  EXPECT_THAT(text, HasSubstr("despike_threshold_um"));
  // The plots are vector drawings with their own text: axis labels come through too.
  EXPECT_THAT(text, HasSubstr("phase c (deg)"));
  EXPECT_THAT(text, HasSubstr("form error (µm)"));
  ASSERT_EQ(Shell("pdfinfo '" + written.pdf.string() + "' > '" + (dir / "info.txt").string() + "'"), 0);
  EXPECT_THAT(ReadText(dir / "info.txt"), HasSubstr("595.276 x 841.89 pts (A4)"));
}

TEST(WriteReports, HtmlCarriesTheHeadlineNumbersAndReferencesNothingOutside) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  const std::string html = ReadText(written.html);
  for (const std::string& number : kFixtureHeadline) EXPECT_THAT(html, HasSubstr(number));
  EXPECT_THAT(html, HasSubstr("<meta name=\"viewport\""));
  EXPECT_THAT(html, Not(HasSubstr("<script")));
  EXPECT_THAT(html, Not(HasSubstr("<link")));
  EXPECT_THAT(html, Not(HasSubstr("src=")));
  EXPECT_THAT(html, Not(HasSubstr("@import")));
  // Every reference is in-document (#id) or inline data.
  const std::regex reference(R"re((?:href|url)\s*[=(]\s*"?([^")\s]*))re");
  int references = 0;
  for (auto it = std::sregex_iterator(html.begin(), html.end(), reference); it != std::sregex_iterator();
       ++it) {
    const std::string target = (*it)[1].str();
    EXPECT_TRUE(target.rfind("#", 0) == 0 || target.rfind("data:", 0) == 0) << target;
    ++references;
  }
  EXPECT_GT(references, 100) << "the plots' glyphs are referenced in-document";
}

TEST(WriteReports, RefusesABrokenMapAndLeavesNoReport) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21});
  std::ofstream(dir / "wheel_map.h5", std::ios::trunc) << "truncated";
  const std::string before = arcwheel::testing::ListFolder(dir.path());
  EXPECT_THAT(ErrorMessageOf([&] { (void)WriteReports(dir.path(), {}); }),
              HasSubstr((dir / "wheel_map.h5").string()));
  EXPECT_EQ(arcwheel::testing::ListFolder(dir.path()), before);
}

TEST(WriteReports, RefusesAMissingSummaryAndLeavesNoReport) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21});
  fs::remove(dir / "summary.json");
  EXPECT_THAT(ErrorMessageOf([&] { (void)WriteReports(dir.path(), {}); }, ErrorCode::kIo),
              HasSubstr((dir / "summary.json").string()));
  EXPECT_EQ(arcwheel::testing::ListFolder(dir.path()), "wheel_map.h5\n");
}

// ---- The HTML as a browser sees it (Debian's chromium, headless). ----

TEST(Chromium, HarnessSeesConsoleErrorsMissingFilesAndNetworkRequests) {
  // A deliberately bad page proves that the checks below can fail.
  TempDir dir;
  std::ofstream(dir / "bad.html") << "<!DOCTYPE html><html><body><h1>bad</h1><img src=\"missing.png\">"
                                     "<img src=\"http://example.invalid/x.png\">"
                                     "<script>console.error('broken page')</script></body></html>";
  const BrowserRun run = LoadInChromium(dir / "bad.html", 400, 300);
  ASSERT_EQ(run.exit_status, 0) << "chromium is installed by scripts/install_deps.sh";
  ASSERT_EQ(run.console.size(), 1u);
  EXPECT_THAT(run.console[0], HasSubstr("broken page"));
  EXPECT_THAT(run.files_loaded, ::testing::Contains(HasSubstr("missing.png")));
  EXPECT_THAT(run.page_requests, ::testing::Contains("http://example.invalid/x.png"));
}

TEST(Chromium, LoadsTheHtmlReportCleanlyOnADesktopAndAPhoneScreen) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  for (const auto& [width, height] : {std::pair{1280, 2400}, std::pair{390, 844}}) {
    SCOPED_TRACE(std::to_string(width) + " x " + std::to_string(height));
    const BrowserRun run = LoadInChromium(written.html, width, height);
    ASSERT_EQ(run.exit_status, 0);
    EXPECT_THAT(run.console, ::testing::IsEmpty()) << "no console errors or warnings";
    EXPECT_THAT(run.files_loaded, ::testing::ElementsAre("file://" + written.html.string()))
        << "nothing but itself";
    EXPECT_THAT(run.page_requests, ::testing::IsEmpty()) << "no network";
    // Text, tables and the viridis map give hundreds of colours; a blank page gives one.
    EXPECT_GT(run.distinct_colours, 100u);
  }
}

}  // namespace
}  // namespace arcwheel::reports
