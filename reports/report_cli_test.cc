// `arcwheel report` as a user runs it: on a fixture folder, on broken folders, and end to end
// after `arcwheel simulate` and `arcwheel process`.

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <fstream>
#include <nlohmann/json.hpp>
#include <regex>
#include <sstream>

#include "core/testing/testing.h"
#include "reports/report_fixture.h"

namespace arcwheel::reports {
namespace {

using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)
using ::testing::HasSubstr;

TEST(ReportCommand, WritesBothReportsAndJudgesAToleranceFile) {
  TempDir dir;
  testing::WriteFixture(dir / "out", {.n_phase = 36, .n_y = 81});
  std::ofstream(dir / "tol.json") << R"({"max_runout_um": 7.5, "max_roundness_um": {"max": 3.0}})";
  const auto result = RunArcwheel("report '" + (dir / "out").string() + "' --tolerances '" +
                                  (dir / "tol.json").string() + "'");
  ASSERT_EQ(result.exit_status, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("overall: FAIL")) << "roundness 3.47 um > 3.0 um";
  EXPECT_EQ(ListFolder(dir / "out"), "report.html\nreport.pdf\nsummary.json\nwheel_map.h5\n");
  const std::string text = PdfText(dir / "out" / "report.pdf");
  EXPECT_THAT(text, HasSubstr("7.13 µm"));
  EXPECT_THAT(text, HasSubstr("≤ 7.5 µm"));
}

TEST(ReportCommand, FlagsOverrideTheToleranceFile) {
  TempDir dir;
  testing::WriteFixture(dir / "out", {.n_phase = 36, .n_y = 81});
  std::ofstream(dir / "tol.json") << R"({"max_roundness_um": 3.0})";
  const auto result = RunArcwheel("report '" + (dir / "out").string() + "' --tolerances '" +
                                  (dir / "tol.json").string() + "' --tolerance max_roundness_um=3.5");
  ASSERT_EQ(result.exit_status, 0) << result.output;
  EXPECT_THAT(result.output, HasSubstr("overall: PASS"));
}

// Runs `arcwheel report` on `dir` with `extra` arguments and checks that it exits with `status`,
// saying `words`, and that the folder then holds `listing` alone.
void ExpectRefused(const TempDir& dir, const std::string& extra, int status, const std::string& words,
                   const std::string& listing) {
  const auto result = RunArcwheel("report '" + dir.path().string() + "'" + extra);
  EXPECT_EQ(result.exit_status, status) << result.output;
  EXPECT_THAT(result.output, HasSubstr(words));
  EXPECT_EQ(ListFolder(dir.path()), listing);
}

constexpr const char* kFixtureListing = "summary.json\nwheel_map.h5\n";

TEST(ReportCommand, RefusesAFolderWithoutSummaryAndWritesNothing) {
  TempDir dir;
  ExpectRefused(dir, "", 4, (dir / "summary.json").string() + "' does not exist", "");
}

TEST(ReportCommand, RefusesASummaryMissingAKeyAndWritesNothing) {
  TempDir dir;
  nlohmann::json summary = testing::FixtureSummary({.n_phase = 12, .n_y = 21});
  summary.erase("mean_arc_radius_sigma_mm");
  testing::WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21}, summary);
  ExpectRefused(dir, "", 3, "summary.json' key 'mean_arc_radius_sigma_mm' is missing", kFixtureListing);
}

TEST(ReportCommand, RefusesASummaryOfANewerSchemaMajorVersionAsBadInput) {
  TempDir dir;
  nlohmann::json summary = testing::FixtureSummary({.n_phase = 12, .n_y = 21});
  summary["schema_version"] = "3.1";
  testing::WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21}, summary);
  ExpectRefused(dir, "", 3, "summary.json' key 'schema_version' = '3.1'", kFixtureListing);
}

TEST(ReportCommand, RefusesAMalformedToleranceFlag) {
  TempDir dir;
  testing::WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21});
  ExpectRefused(dir, " --tolerance runout=3", 2, "tolerance 'runout=3'", kFixtureListing);
}

TEST(ReportCommand, ReportsASimulatedAndProcessedScanWithTheSummaryNumbers) {
  TempDir dir;
  const auto simulated =
      RunArcwheel("simulate '" + (dir / "scan.h5").string() + "' --noise-um 0.5 --spike-rate 0.0005");
  ASSERT_EQ(simulated.exit_status, 0) << simulated.output;
  const auto processed =
      RunArcwheel("process '" + (dir / "scan.h5").string() + "' -o '" + (dir / "out").string() + "' -q");
  ASSERT_EQ(processed.exit_status, 0) << processed.output;
  const auto reported = RunArcwheel("report '" + (dir / "out").string() + "' --tolerance max_runout_um=1000");
  ASSERT_EQ(reported.exit_status, 0) << reported.output;

  // The headline numbers as summary.json has them, printed at the report's documented precision.
  const nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "summary.json"));
  // pdftotext breaks wrapped table cells into lines: read the text with single spaces.
  const std::string text = std::regex_replace(PdfText(dir / "out" / "report.pdf"), std::regex(R"(\s+)"), " ");
  const std::string html = ReadText(dir / "out" / "report.html");
  // Page 1's rows for the characteristics read as summary.json's characteristics block has them:
  // the value, U and k, then the operator and where the largest value is. pdftotext interleaves a
  // wrapped cell with its neighbour's lines, so the whole cell is read in the HTML. Precision as
  // the report documents it per unit.
  struct Row {
    const char* name;
    const char* value_key;
    const char* unit;
    int digits;
  };
  for (const Row& row :
       {Row{"mean_arc_radius", "value_mm", "mm", 5}, Row{"arc_radius_range", "value_mm", "mm", 4},
        Row{"center_axial_deviation", "value_mm", "mm", 4}, Row{"max_arc_error", "value_um", "µm", 2},
        Row{"max_runout", "value_um", "µm", 2}, Row{"max_roundness", "value_um", "µm", 2}}) {
    const nlohmann::json& c = summary.at("characteristics").at(row.name);
    const std::string value =
        fmt::format("{:.{}f} {}", c.at(row.value_key).get<double>(), row.digits, row.unit);
    const std::string expanded = fmt::format("U = {:.{}f} {}", c.at("U").get<double>(), row.digits, row.unit);
    const std::string where = c.contains("where") ? ", " + c.at("where").get<std::string>() : "";
    EXPECT_THAT(text, HasSubstr(value)) << row.name;
    EXPECT_THAT(text, HasSubstr(expanded)) << row.name;
    EXPECT_THAT(html, HasSubstr(fmt::format("{} (k = {:.2f}); {}{}", expanded, c.at("k").get<double>(),
                                            c.at("operator").at("short").get<std::string>(), where)))
        << row.name;
  }
  // Where the largest value is, as a number too: the node's y in the band (the text rounds it),
  // the phase of the worst section; the report draws the worst roundness section at that node.
  for (const char* name : {"max_runout", "max_roundness"}) {
    const nlohmann::json& c = summary.at("characteristics").at(name);
    const double y = c.at("at_y_mm").get<double>();
    EXPECT_EQ(c.at("where").get<std::string>(), fmt::format("at y = {:.3f} mm", y)) << name;
    EXPECT_GE(y, summary.at("band_mm").at(0).get<double>()) << name;
    EXPECT_LE(y, summary.at("band_mm").at(1).get<double>()) << name;
  }
  const double arc_phase = summary.at("characteristics").at("max_arc_error").at("at_phase_deg").get<double>();
  EXPECT_TRUE(arc_phase >= 0.0 && arc_phase < 360.0) << arc_phase;
  EXPECT_THAT(text, HasSubstr(fmt::format(
                        "Worst roundness section, y = {:.3f} mm",
                        summary.at("characteristics").at("max_roundness").at("at_y_mm").get<double>())));
  // The caveat's cell wraps beside the uncertainty's, so pdftotext interleaves their lines: its
  // first words are checked.
  EXPECT_THAT(text, HasSubstr("Caveat: " + summary["runout_note"].get<std::string>().substr(0, 9)));
  EXPECT_THAT(text, HasSubstr(fmt::format("{:.3f} %", summary["arc_radius_fluctuation_pct"].get<double>())));
  EXPECT_THAT(text, HasSubstr(summary["input"]["sha256"].get<std::string>()));
  EXPECT_THAT(text, HasSubstr("Overall: PASS"));
  // The wheel model, which `process` fits by default, as summary.json has it.
  const nlohmann::json& model = summary.at("model");
  EXPECT_THAT(text, HasSubstr(fmt::format("{:.5f} ± {:.5f} mm", model["mean_arc_radius_mm"].get<double>(),
                                          model["mean_arc_radius_sigma_mm"].get<double>())));
  EXPECT_THAT(text, HasSubstr(fmt::format("{:.4f} ± {:.4f} mm", model["arc_radius_range_mm"].get<double>(),
                                          model["arc_radius_range_sigma_mm"].get<double>())));
  EXPECT_THAT(text, HasSubstr(fmt::format("{} (χ² = {:.1f} with {} dof",
                                          model["radius_variation_significant"].get<bool>() ? "yes" : "no",
                                          model["radius_variation_chi2"].get<double>(),
                                          model["radius_variation_dof"].get<int>())));
  EXPECT_THAT(text, HasSubstr(fmt::format("{:.2f} µm", model["profile_pv_um"].get<double>())));
}

// ISO 14253-1 through the CLI: limits placed by hand around the summary's noise-corrected runout
// and its U.
TEST(ReportCommand, DecidesByIso14253AgainstValueAndExpandedUncertainty) {
  TempDir dir;
  ASSERT_EQ(RunArcwheel("simulate '" + (dir / "scan.h5").string() + "' --noise-um 0.4 --radial-harmonic 1:3")
                .exit_status,
            0);
  const auto processed =
      RunArcwheel("process '" + (dir / "scan.h5").string() + "' -o '" + (dir / "out").string() + "' -q");
  ASSERT_EQ(processed.exit_status, 0) << processed.output;
  const nlohmann::json summary = nlohmann::json::parse(ReadText(dir / "out" / "summary.json"));
  // Page 1 decides the characteristic (TIR under its operator) on its own value and U.
  const nlohmann::json& runout = summary["characteristics"]["max_runout"];
  const double value = runout["value_um"].get<double>();
  const double u = runout["U"].get<double>();
  ASSERT_GT(u, 0.0);
  const auto overall = [&](double limit, const std::string& extra = "") {
    const auto reported = RunArcwheel("report '" + (dir / "out").string() +
                                      "' --tolerance max_runout_um=" + fmt::format("{:.9f}", limit) + extra);
    EXPECT_EQ(reported.exit_status, 0) << reported.output;
    const std::size_t at = reported.output.find("overall: ");
    return at == std::string::npos ? reported.output
                                   : reported.output.substr(at, reported.output.find('\n', at) - at);
  };
  EXPECT_EQ(overall(value + u / 2), "overall: NOT PROVEN");
  EXPECT_EQ(overall(value - u / 2), "overall: NOT PROVEN");
  EXPECT_EQ(overall(value + 2 * u), "overall: PASS");
  EXPECT_EQ(overall(value - 2 * u), "overall: FAIL");
  const std::string text = std::regex_replace(PdfText(dir / "out" / "report.pdf"), std::regex(R"(\s+)"), " ");
  EXPECT_THAT(text, HasSubstr("ISO 14253-1:2017 default rule"));
  // Shared risk, named in the tolerance file: the value alone decides.
  WriteText(dir / "shared.json", R"({"decision_rule": "simple-acceptance"})");
  EXPECT_EQ(overall(value + u / 2, " --tolerances '" + (dir / "shared.json").string() + "'"),
            "overall: PASS");
  EXPECT_THAT(PdfText(dir / "out" / "report.pdf"), HasSubstr("simple acceptance"));
}

// `process --tolerances`: summary.json records the rule and, for each toleranced quantity, the
// value, U, k and decision the report's page 1 shows. The limits are placed against the value and
// U of a run without tolerances (the same scan gives the same figures: the bootstrap is seeded).
TEST(ProcessCommand, RecordsTheDecisionsInTheSummary) {
  TempDir dir;
  const std::string scan = (dir / "scan.h5").string();
  ASSERT_EQ(RunArcwheel("simulate '" + scan + "' --noise-um 0.4 --radial-harmonic 1:3").exit_status, 0);
  ASSERT_EQ(RunArcwheel("process '" + scan + "' -o '" + (dir / "plain").string() + "' -q").exit_status, 0);
  const nlohmann::json plain = nlohmann::json::parse(ReadText(dir / "plain" / "summary.json"));
  ASSERT_FALSE(plain["uncertainty"].contains("decisions"));
  const nlohmann::json& q = plain["uncertainty"]["quantities"];
  const auto value = [&](const char* key) { return q[key]["value"].get<double>(); };
  const auto u = [&](const char* key) { return q[key]["U"].get<double>(); };
  ASSERT_GT(u("max_runout_um"), 0.0);
  const nlohmann::json tolerances = {
      {"max_runout_um", {{"max", value("max_runout_um") + u("max_runout_um") / 2}}},
      {"mean_arc_radius_mm",
       {{"min", value("mean_arc_radius_mm") - 2 * u("mean_arc_radius_mm")},
        {"max", value("mean_arc_radius_mm") + 2 * u("mean_arc_radius_mm")}}},
      {"max_roundness_um", value("max_roundness_um") - 2 * u("max_roundness_um")}};
  WriteText(dir / "tolerances.json", tolerances.dump());
  const auto run = RunArcwheel("process '" + scan + "' -o '" + (dir / "decided").string() +
                               "' -q --tolerances '" + (dir / "tolerances.json").string() + "'");
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const nlohmann::json decided =
      nlohmann::json::parse(ReadText(dir / "decided" / "summary.json"))["uncertainty"];
  EXPECT_EQ(decided["decision_rule"], "iso14253-1");
  const nlohmann::json& d = decided["decisions"];
  ASSERT_EQ(d.size(), 3u) << d.dump();
  EXPECT_EQ(d["max_runout_um"]["decision"], "not proven");
  EXPECT_EQ(d["mean_arc_radius_mm"]["decision"], "conforms");
  EXPECT_EQ(d["max_roundness_um"]["decision"], "does not conform");
  EXPECT_TRUE(d["max_roundness_um"]["min"].is_null());
  EXPECT_EQ(d["max_runout_um"]["U"].get<double>(), u("max_runout_um"));
  EXPECT_EQ(d["max_runout_um"]["value"].get<double>(), value("max_runout_um"));
  EXPECT_EQ(d["max_runout_um"]["k"].get<double>(), q["max_runout_um"]["k"].get<double>());
  EXPECT_EQ(decided["overall"], "does not conform");

  // A tolerance file that does not parse is refused before the scan is read: exit 3 (bad input,
  // docs/reports.md), nothing written.
  WriteText(dir / "bad.json", R"({"max_runout_um": {"max": "ten"}})");
  const auto refused = RunArcwheel("process '" + scan + "' -o '" + (dir / "refused").string() +
                                   "' -q --tolerances '" + (dir / "bad.json").string() + "'");
  EXPECT_EQ(refused.exit_status, 3) << refused.output;
  EXPECT_THAT(refused.output, HasSubstr("bad.json"));
  EXPECT_FALSE(std::filesystem::exists(dir / "refused"));
}

}  // namespace
}  // namespace arcwheel::reports
