#include "reports/report.h"

#include <cairo.h>
#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <map>
#include <nlohmann/json.hpp>
#include <regex>
#include <set>
#include <sstream>
#include <stdexcept>
#include <variant>

#include "core/error.h"
#include "core/testing/testing.h"
#include "reports/browser_check.h"
#include "reports/report_fixture.h"
#include "reports/report_inputs.h"

namespace arcwheel::reports {
namespace {

namespace fs = std::filesystem;
using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)
using testing::BrowserRun;
using testing::FixtureOptions;
using ::testing::HasSubstr;
using testing::LayoutInChromium;
using testing::LoadInChromium;
using ::testing::Not;
using testing::WriteFixture;

// The fixture's headline literals (reports/report_fixture.cc) as the report must print them:
// mm with 4 decimals (mean radius with 5), um with 2, percent with 3.
const std::vector<std::string> kFixtureHeadline = {"75.01234 mm", "0.0061 mm", "0.008 %", "0.0043 mm",
                                                   "1.58 µm",     "7.13 µm",   "3.47 µm"};

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
  EXPECT_EQ(content.headline[1].tolerance, "–") << "a row without a limit says so once";
  EXPECT_EQ(content.headline[4].verdict, Verdict::kPass);
  EXPECT_EQ(content.headline[5].verdict, Verdict::kFail);
  EXPECT_EQ(content.headline[5].tolerance, "≤ 7 µm");
  EXPECT_EQ(content.overall, Verdict::kFail);
  EXPECT_THAT(content.failing, ::testing::ElementsAre("Max runout in the band: 7.13 µm (limit ≤ 7 µm)"));
  EXPECT_EQ(content.title, "Wheel inspection report: W17-arc75");
}

// The fixture records sigma of the mean 0.00021 mm and phase-to-phase sigma 0.0021 mm
// (report_fixture.cc); the map values' median 1-sigma is 0.05 um.
TEST(ComposeReport, StatesWhatEachUncertaintyMeans) {
  TempDir dir;
  WriteFixture(dir.path());
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), {});
  EXPECT_THAT(content.headline[0].uncertainty, HasSubstr("± 0.00021 mm (σ of the mean)"));
  EXPECT_THAT(content.headline[0].uncertainty, HasSubstr("phase-to-phase σ 0.0021 mm"));
  EXPECT_THAT(content.headline[1].uncertainty, HasSubstr("phase-to-phase σ 0.0021 mm"));
  EXPECT_THAT(content.headline[5].uncertainty, HasSubstr("map value 1σ 0.050 µm (median)"));
  EXPECT_THAT(content.headline[5].note, HasSubstr("spindle")) << "the runout caveat sits with runout";
}

// Runout is a peak-to-valley of 72 map values (one per phase) of 1-sigma 0.05 um: noise alone
// gives d2(72) * 0.05 um with d2(72) = 4.776 (expected range of 72 standard normals, between the
// tabulated d2(50) = 4.498 and d2(100) = 5.015), so about 0.24 um.
TEST(ComposeReport, GivesThePartOfEachPeakToValleyThatNoiseExplains) {
  TempDir dir;
  WriteFixture(dir.path());
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), {});
  EXPECT_THAT(content.headline[5].noise,
              HasSubstr("≈ 0.24 µm from noise (expected PV of 72 values of 1σ 0.050 µm)"));
  EXPECT_TRUE(content.headline[0].noise.empty()) << "the mean is no peak-to-valley";
}

TEST(ExpectedNormalRange, MatchesTheControlChartConstants) {
  // d2(n) from the standard tables (e.g. ASTM STP 15D): independent of the integral computed here.
  EXPECT_NEAR(ExpectedNormalRange(2), 1.128, 1e-3);
  EXPECT_NEAR(ExpectedNormalRange(10), 3.078, 1e-3);
  EXPECT_NEAR(ExpectedNormalRange(25), 3.931, 1e-3);
  EXPECT_NEAR(ExpectedNormalRange(100), 5.015, 1e-3);
  EXPECT_EQ(ExpectedNormalRange(1), 0.0);
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
  EXPECT_EQ(rows["despike_threshold_um"], "5") << "a whole number without decimals";
  EXPECT_EQ(rows["band_half_width_mm"], "8");
  EXPECT_EQ(rows["fit_span"], "band");
  EXPECT_EQ(rows["axial_step_mm"], "0.1");
}

// ---- The wheel model (reports/report_fixture.h gives its known values). ----

// The fixture model's numbers as the report must print them (report_fixture.cc, FixtureModel).
const std::vector<std::string> kFixtureModelText = {
    "75.00003 ± 0.00002 mm",
    "0.0060 ± 0.0003 mm",
    "yes (χ² = 912.3 with 7 dof, p < 0.001; significance level 0.01)",
    "0.313 µm against a noise estimate of 0.310 µm (ratio 1.01)",
    "0.84 µm",
    "0.04 ± 0.11 µm",
    "12.5 ± 160.0 deg",
    "3.00 ± 0.12 µm",
    "−90.0 ± 2.3 deg"};

const plot::LinePlot& LinePlotTitled(const ReportContent& content, const std::string& title_start) {
  for (const ReportFigure& figure : content.figures) {
    const auto* plot = std::get_if<plot::LinePlot>(&figure.figure);
    if (plot != nullptr && plot->title.rfind(title_start, 0) == 0) return *plot;
  }
  throw std::runtime_error("no line plot titled '" + title_start + "...'");
}

const plot::Series& SeriesLabelled(const plot::LinePlot& plot, const std::string& label) {
  for (const plot::Series& series : plot.series) {
    if (series.label == label) return series;
  }
  throw std::runtime_error("no series '" + label + "' in '" + plot.title + "'");
}

TEST(ComposeReport, ShowsTheWheelModelsNumbersRounded) {
  TempDir dir;
  WriteFixture(dir.path());
  const ModelReport model = ComposeReport(ReadReportInputs(dir.path()), {}).model;
  ASSERT_TRUE(model.shown);
  std::vector<std::string> values;
  for (const KeyValue& row : model.rows) values.push_back(row.value);
  EXPECT_THAT(values, ::testing::ElementsAre(
                          kFixtureModelText[0], kFixtureModelText[1], kFixtureModelText[2],
                          "Ra(c) 8, a(c) 4, b(c) 16 per turn; chosen by the Bayesian information criterion",
                          kFixtureModelText[3], kFixtureModelText[4]));
  using Row = std::vector<std::string>;
  EXPECT_THAT(model.harmonics, ::testing::ElementsAre(Row{"1", kFixtureModelText[5], kFixtureModelText[6]},
                                                      Row{"2", kFixtureModelText[7], kFixtureModelText[8]}));
}

TEST(ComposeReport, SaysWhenTheModelsRadiusIsAConstant) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21});
  ReportInputs inputs = ReadReportInputs(dir.path());
  // As the writer records a radius the information criterion found constant.
  inputs.summary.model->radius_knots = 1;
  inputs.summary.model->arc_radius_range_mm = 0.0;
  inputs.summary.model->arc_radius_range_sigma_mm = 0.0;
  inputs.summary.model->radius_harmonics.clear();
  const ReportContent content = ComposeReport(inputs, {});
  EXPECT_EQ(content.model.rows[1].value, "0.0000 ± 0.0000 mm (Ra(c) fitted as a constant)");
  EXPECT_THAT(content.model.rows[3].value, HasSubstr("Ra(c) 1 (constant), a(c) 4"));
  EXPECT_TRUE(content.model.harmonics.empty());
  EXPECT_THAT(RenderHtml(content), HasSubstr("None: Ra(c) is modelled as a constant."));
}

TEST(ComposeReport, DrawsTheModelRadiusWithItsBandOverThePerPhaseRadii) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 36, .n_y = 41});
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), {});
  const plot::LinePlot& radius = LinePlotTitled(content, "Arc radius vs phase");
  const plot::Series& per_phase = SeriesLabelled(radius, "per-phase fits");
  const plot::Series& model = SeriesLabelled(radius, "model Ra(c)");
  EXPECT_TRUE(per_phase.markers) << "points under the model's line";
  ASSERT_EQ(model.x.size(), 36u);
  for (std::size_t i = 0; i < model.x.size(); ++i) {
    const double ra = testing::FixtureArcRadius_mm(10.0 * static_cast<double>(i));
    EXPECT_DOUBLE_EQ(model.x[i], 10.0 * static_cast<double>(i));
    EXPECT_NEAR(model.y[i], ra, 1e-12);
    EXPECT_NEAR(model.band_low[i], ra - 0.0002, 1e-12);
    EXPECT_NEAR(model.band_high[i], ra + 0.0002, 1e-12);
  }
}

TEST(ComposeReport, DrawsTheModelCentreAgainstThePerPhaseMeanInMicrometres) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 36, .n_y = 41});
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), {});
  const plot::LinePlot& centre = LinePlotTitled(content, "Arc centre vs phase");
  const plot::Series& axial = SeriesLabelled(centre, "model a(c)");
  const plot::Series& radial = SeriesLabelled(centre, "model b(c)");
  // a = 10 + 0.002 cos c mm and b = 25 + 0.001 sin c mm: over whole turns the per-phase means are 10
  // and 25 mm, so the deviations are 2 cos c and sin c um, with bands of 0.1 and 0.15 um.
  for (std::size_t i = 0; i < axial.x.size(); ++i) {
    const double c = 10.0 * static_cast<double>(i) * M_PI / 180.0;
    EXPECT_NEAR(axial.y[i], 2.0 * std::cos(c), 1e-9);
    EXPECT_NEAR(axial.band_high[i] - axial.y[i], 0.1, 1e-9);
    EXPECT_NEAR(radial.y[i], std::sin(c), 1e-9);
    EXPECT_NEAR(radial.y[i] - radial.band_low[i], 0.15, 1e-9);
  }
}

TEST(ComposeReport, DrawsTheProfileErrorAndTheResidualMapOfTheModel) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 36, .n_y = 41});
  const ReportContent content = ComposeReport(ReadReportInputs(dir.path()), {});
  const plot::Series& profile = SeriesLabelled(LinePlotTitled(content, "Profile error p(u)"), "p(u)");
  ASSERT_EQ(profile.x.size(), 161u);
  for (std::size_t k = 0; k < profile.x.size(); ++k) {
    EXPECT_NEAR(profile.y[k], 0.42 * std::cos(M_PI * profile.x[k] / 8.0), 1e-12);
    EXPECT_NEAR(profile.band_high[k] - profile.band_low[k], 0.04, 1e-12);
  }
  const plot::HeatMap* residual = nullptr;
  for (const ReportFigure& figure : content.figures) {
    const auto* map = std::get_if<plot::HeatMap>(&figure.figure);
    if (map != nullptr && map->colour_bar_label == "model residual (µm)") residual = map;
  }
  ASSERT_NE(residual, nullptr);
  EXPECT_EQ(residual->y.min, 2.0) << "the band, where the model has residuals";
  EXPECT_EQ(residual->y.max, 18.0);
  ASSERT_EQ(residual->values.size(), 36u * 41u);
  for (std::size_t i = 0; i < 36; ++i) {
    for (std::size_t j = 0; j < 41; ++j) {
      const double expected =
          testing::FixtureModelResidual_um(10.0 * static_cast<double>(i), 0.5 * static_cast<double>(j), true);
      const double value = residual->values[i * 41 + j];
      if (std::isnan(expected)) {
        EXPECT_TRUE(std::isnan(value)) << i << ", " << j;
      } else {
        EXPECT_NEAR(value, expected, 1e-12) << i << ", " << j;
      }
    }
  }
}

// The worst roundness section is drawn from the map's turn at the node the characteristic names,
// filtered and associated as its operator says. A turn of three lobes of amplitude a: the 50 UPR
// Gaussian passes a 2^-(3/50)^2 of them, and the minimum zone of r = R + a' cos 3c is 2 a' wide
// (its six extremes alternate on two circles about the axis).
TEST(ComposeReport, DrawsTheWorstRoundnessSectionAsItsOperatorSeesIt) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 360, .n_y = 41});
  ReportInputs inputs = ReadReportInputs(dir.path());
  const std::size_t node = 17, n_y = inputs.map.n_y();
  const double lobes_um = 1.234;
  for (std::size_t i = 0; i < 360; ++i)
    inputs.map.rho_mm[i * n_y + node] =
        lobes_um / 1000.0 * std::cos(3.0 * static_cast<double>(i) * M_PI / 180.0);
  Summary::Characteristic roundness;
  roundness.value = 2.0;
  roundness.operator_text = "RONt, 50 UPR, MZ";
  roundness.cutoff_upr = 50.0;
  roundness.association = "minimum-zone";
  roundness.at_y_mm = inputs.map.y_mm[node] + 0.01;  // the nearest node is the one
  inputs.summary.characteristics["max_roundness_um"] = roundness;
  const ReportContent content = ComposeReport(inputs, {});
  const plot::PathMap* polar = nullptr;
  std::string caption;
  for (const ReportFigure& figure : content.figures) {
    if (const auto* path = std::get_if<plot::PathMap>(&figure.figure);
        path != nullptr && path->title.starts_with("Worst roundness section")) {
      polar = path;
      caption = figure.caption;
    }
  }
  ASSERT_NE(polar, nullptr);
  const double passed_um = lobes_um * std::pow(2.0, -(3.0 / 50.0) * (3.0 / 50.0));
  EXPECT_THAT(caption, HasSubstr(fmt::format("its RONt here {:.3f} µm", 2.0 * passed_um)));
  const auto [low, high] = std::minmax_element(polar->values.begin(), polar->values.end());
  EXPECT_NEAR(*high, passed_um, 1e-6);
  EXPECT_NEAR(*low, -passed_um, 1e-6);
  EXPECT_THAT(polar->title, HasSubstr(fmt::format("y = {:.3f} mm", inputs.map.y_mm[node])));
  const plot::Series& spectrum = SeriesLabelled(
      LinePlotTitled(content, "Harmonic spectrum of the worst roundness section"), "amplitude");
  ASSERT_GE(spectrum.y.size(), 3u);
  EXPECT_NEAR(spectrum.y[2], lobes_um, 1e-6) << "3 UPR, before the filter";
  EXPECT_NEAR(spectrum.y[1], 0.0, 1e-6);
}

TEST(ComposeReport, SaysInOneLineWhyASummaryHasNoModel) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21, .with_model = false});
  ReportInputs inputs = ReadReportInputs(dir.path());
  const ReportContent off = ComposeReport(inputs, {});
  EXPECT_FALSE(off.model.shown);
  EXPECT_EQ(off.model.note, "Wheel model: not fitted (processed with --no-model).");
  for (const ReportFigure& figure : off.figures) {
    EXPECT_THAT(figure.caption, Not(HasSubstr("model"))) << "no model figure without a model";
  }
  inputs.summary.processing.erase("model");
  inputs.summary.schema_version = "1.0";
  EXPECT_EQ(ComposeReport(inputs, {}).model.note,
            "Wheel model: not in this summary (schema 1.0, written before the model).");
  inputs.summary.processing["model"] = "on";
  inputs.summary.schema_version = "1.1";
  EXPECT_EQ(ComposeReport(inputs, {}).model.note,
            "Wheel model: not in this summary (it could not be fitted; see Warnings).");
}

TEST(WriteReports, PdfAndHtmlCarryTheWheelModelsNumbers) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), {});
  ASSERT_EQ(
      Shell("pdftotext -enc UTF-8 '" + written.pdf.string() + "' '" + (dir / "report.txt").string() + "'"),
      0);
  const std::string text = ReadText(dir / "report.txt");
  const std::string html = ReadText(written.html);
  for (const std::string& number : kFixtureModelText) {
    EXPECT_THAT(text, HasSubstr(number));
    EXPECT_THAT(html, HasSubstr(std::regex_replace(number, std::regex("<"), "&lt;")));
  }
  // A long cell wraps in the PDF; its parts come through.
  EXPECT_THAT(text, HasSubstr("Ra(c) 8, a(c) 4, b(c) 16 per turn"));
  EXPECT_THAT(text, HasSubstr("Bayesian information criterion"));
  EXPECT_THAT(text, HasSubstr("model residual (µm)"));
  EXPECT_THAT(text, HasSubstr("profile error p (µm)"));
  EXPECT_THAT(text, HasSubstr("model Ra(c)"));
  EXPECT_THAT(text, HasSubstr("−2")) << "a negative tick of the centre plot, with the minus sign";
}

TEST(WriteReports, ReportsASummaryWithoutModelAndSaysSo) {
  TempDir dir;
  WriteFixture(dir.path(), {.with_model = false});
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  ASSERT_EQ(
      Shell("pdftotext -enc UTF-8 '" + written.pdf.string() + "' '" + (dir / "report.txt").string() + "'"),
      0);
  const std::string text = ReadText(dir / "report.txt");
  EXPECT_THAT(text, HasSubstr("Wheel model: not fitted (processed with --no-model)."));
  EXPECT_THAT(text, Not(HasSubstr("model Ra(c)")));
  for (const std::string& number : kFixtureHeadline) EXPECT_THAT(text, HasSubstr(number));
  EXPECT_THAT(ReadText(written.html), HasSubstr("Wheel model: not fitted (processed with --no-model)."));
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

// ---- The report as an operator reads it ----

// `text` with every run of white space as one space (pdftotext breaks wrapped cells into lines).
std::string OneLine(const std::string& text) { return std::regex_replace(text, std::regex(R"(\s+)"), " "); }

TEST(WriteReports, PdfOpensWithTheDecisionNamingTheFailingRows) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  const std::string text = OneLine(PdfText(written.pdf));
  const std::size_t verdict = text.find("Overall: FAIL");
  ASSERT_NE(verdict, std::string::npos);
  EXPECT_LT(verdict, text.find("Scan and provenance")) << "the decision before the provenance";
  EXPECT_LT(text.find("W17-arc75"), verdict) << "only the title before it";
  EXPECT_LT(verdict, text.find("Failing: Max runout in the band: 7.13 µm (limit ≤ 7 µm)."));
  EXPECT_LT(text.find("Failing:"), text.find("Scan and provenance"));
  EXPECT_THAT(text, HasSubstr("σ of the mean"));
  EXPECT_THAT(text, HasSubstr("phase-to-phase σ 0.0021 mm"));
  EXPECT_THAT(text, HasSubstr("spindle's error motion")) << "the runout caveat";
  EXPECT_THAT(text, HasSubstr("from noise (expected PV of"));
  // Provenance a release needs: the wheel's size, the report's date, pages, a signature.
  EXPECT_THAT(text, HasSubstr("Wheel diameter × width"));
  EXPECT_THAT(text, HasSubstr("Report date"));
  EXPECT_THAT(text, HasSubstr("Approved by"));
  EXPECT_THAT(text, ::testing::ContainsRegex("page 1 of [2-9]"));
  EXPECT_THAT(text, Not(HasSubstr("NO TOLERANCE"))) << "a row without a limit says '–' once";
}

TEST(WriteReports, NoNumberInEitherReportHasMoreThanSevenSignificantDigits) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  const std::string pdf = PdfText(written.pdf);
  const std::string html = testing::VisibleHtmlText(ReadText(written.html));
  EXPECT_LE(testing::MaxSignificantDigits(pdf), 7) << testing::LongestNumber(pdf);
  EXPECT_LE(testing::MaxSignificantDigits(html), 7) << testing::LongestNumber(html);
  // The check sees what it must: a long number fails it, an id or hash does not.
  EXPECT_EQ(testing::MaxSignificantDigits("radius 0.19967978891870555 mm"), 17);
  EXPECT_EQ(
      testing::MaxSignificantDigits("sha 3b1f5e0c9a7d4e2b8c6f1a0d99887766554433221100, 2400000 samples"), 2);
  EXPECT_THAT(html, HasSubstr("Sample period")) << "the provenance was scanned too";
}

// The decision block and every Result cell inside a 400 px wide window; the plots' smallest text
// (the 7 pt tick labels) at least 9 px there.
TEST(Chromium, PhoneShowsTheDecisionAndResultColumnAndReadablePlotText) {
  TempDir dir;
  WriteFixture(dir.path());
  const WrittenReports written = WriteReports(dir.path(), FixtureTolerances());
  const std::string layout = LayoutInChromium(
      written.html, 400, 900,
      "(function() {"
      "  const lines = ['viewport ' + document.documentElement.clientWidth];"
      "  const box = (name, e) => { const r = e.getBoundingClientRect();"
      "    lines.push(name + ' ' + r.left + ' ' + r.right + ' ' + r.width); };"
      "  box('decision', document.getElementById('decision'));"
      "  document.querySelectorAll('#decision td.result, #decision td.quantity').forEach(e => box('cell', "
      "e));"
      "  document.querySelectorAll('figure svg').forEach(s => { const r = s.getBoundingClientRect();"
      "    if (r.width > 0) lines.push('svg ' + r.width / s.viewBox.baseVal.width); });"
      "  return lines.join(' | ');"
      "})()");
  ASSERT_THAT(layout, HasSubstr("viewport ")) << "chromium laid the page out";
  std::istringstream entries(std::regex_replace(layout, std::regex(R"( \| )"), "\n"));
  double viewport = 0.0;
  int cells = 0, plots = 0;
  for (std::string entry; std::getline(entries, entry);) {
    std::istringstream fields(entry);
    std::string name;
    fields >> name;
    if (name == "viewport") fields >> viewport;
    if (name == "decision" || name == "cell") {
      double left = 0.0, right = 0.0, width = 0.0;
      fields >> left >> right >> width;
      EXPECT_GE(left, 0.0) << entry;
      EXPECT_LE(right, viewport) << entry;
      EXPECT_GT(width, 0.0) << entry;
      cells += name == "cell";
    }
    if (name == "svg") {
      double px_per_pt = 0.0;
      fields >> px_per_pt;
      EXPECT_GE(px_per_pt * plot::kTickSize_pt, 9.0) << "tick labels of a plot render at least 9 px";
      ++plots;
    }
  }
  // 400 px less a scroll bar (chromium draws one; a phone overlays it).
  EXPECT_THAT(viewport, ::testing::AllOf(::testing::Ge(380.0), ::testing::Le(400.0))) << layout;
  EXPECT_EQ(cells, 14) << "7 quantities, each with its result";
  EXPECT_GE(plots, 7);
}

}  // namespace
}  // namespace arcwheel::reports
