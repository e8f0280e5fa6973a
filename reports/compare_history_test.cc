// `arcwheel compare` and `arcwheel history` on simulated scans of known geometry, and their
// building blocks against closed forms.

#include <fmt/format.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <random>
#include <sstream>

#include "core/error.h"
#include "core/testing/testing.h"
#include "reports/compare.h"
#include "reports/history.h"
#include "reports/report_fixture.h"

namespace arcwheel::reports {
namespace {

namespace fs = std::filesystem;
using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)
using ::testing::HasSubstr;

constexpr double kArcRadius_mm = 55.4423;  // simulate's default

// Simulates a small scan (66000 samples) of a wheel of arc radius `radius_mm` and processes it
// into `out` (no wheel model, 180 phases: quick).
void SimulateAndProcess(const fs::path& work, const std::string& name, double radius_mm, int seed,
                        const std::string& timestamp = "2026-03-01T08:00:00Z",
                        const std::string& extra = "") {
  const fs::path scan = work / (name + ".h5");
  const auto simulated = RunArcwheel(fmt::format(
      "simulate '{}' --sample-period-s 0.0002 --noise-um 0.4 --arc-radius-mm {:.7f} --seed {} --timestamp {} "
      "--wheel-id W9-arc55 {}",
      scan.string(), radius_mm, seed, timestamp, extra));
  ASSERT_EQ(simulated.exit_status, 0) << simulated.output;
  const auto processed = RunArcwheel(
      fmt::format("process '{}' -o '{}' -q --no-model --phases 180", scan.string(), (work / name).string()));
  ASSERT_EQ(processed.exit_status, 0) << processed.output;
}

const nlohmann::json& ChangeOf(const nlohmann::json& comparison, const std::string& key) {
  for (const nlohmann::json& change : comparison.at("changes")) {
    if (change.at("key") == key) return change;
  }
  throw std::runtime_error("no change '" + key + "'");
}

// Three scans of one wheel: "a" and "c" of the same radius (other noise), "b" 5 um larger.
class Compare : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    work_ = new TempDir;
    SimulateAndProcess(work_->path(), "a", kArcRadius_mm, 1);
    SimulateAndProcess(work_->path(), "b", kArcRadius_mm + 0.005, 2);
    SimulateAndProcess(work_->path(), "c", kArcRadius_mm, 3);
    // A 2.5 um eccentricity: the runout grows by its peak-to-valley, 5 um.
    SimulateAndProcess(work_->path(), "d", kArcRadius_mm, 4, "2026-03-01T08:00:00Z",
                       "--radial-harmonic 1:2.5");
  }
  static void TearDownTestSuite() { delete work_; }
  static nlohmann::json Run(const std::string& before, const std::string& after, const std::string& out) {
    const auto result = RunArcwheel(fmt::format("compare '{}' '{}' -o '{}'", (*work_ / before).string(),
                                                (*work_ / after).string(), (*work_ / out).string()));
    EXPECT_EQ(result.exit_status, 0) << result.output;
    return nlohmann::json::parse(ReadText(*work_ / out / "compare.json"));
  }
  static TempDir* work_;
};
TempDir* Compare::work_ = nullptr;

TEST_F(Compare, ReportsAKnownRadiusChangeOfFiveMicrometresWithinThreeSigma) {
  const nlohmann::json comparison = Run("a", "b", "ab");
  const nlohmann::json& radius = ChangeOf(comparison, "mean_arc_radius_mm");
  const double sigma = radius["sigma"].get<double>();
  EXPECT_NEAR(sigma, std::hypot(radius["before_sigma"].get<double>(), radius["after_sigma"].get<double>()),
              1e-15)
      << "combined sigma sqrt(s1^2 + s2^2)";
  EXPECT_NEAR(radius["change"].get<double>(), 0.005, 3.0 * sigma);
  EXPECT_TRUE(radius["significant"].get<bool>()) << "5 um against a sigma of " << sigma * 1000.0 << " um";
  // simulate keeps the rim's apex at the wheel diameter (Rb = D/2 - Ra), so a larger arc radius
  // moves the rim at u from the apex by dRa (Ra / sqrt(Ra^2 - u^2) - 1): 0 at the apex, 0.05 um
  // 8 mm off it. The map difference's median is that over the common grid's axial nodes (the
  // same at every phase; the arc centre is at y = 0).
  const nlohmann::json& map = comparison["map_difference"];
  std::vector<double> closed_form_um;
  const auto n_y = map["n_y"].get<std::size_t>();
  for (std::size_t j = 0; j < n_y; ++j) {
    const double u =
        map["y_min_mm"].get<double>() + (map["y_max_mm"].get<double>() - map["y_min_mm"].get<double>()) *
                                            static_cast<double>(j) / static_cast<double>(n_y - 1);
    const double ra = kArcRadius_mm + 0.005;
    closed_form_um.push_back(
        (std::sqrt(ra * ra - u * u) - std::sqrt(kArcRadius_mm * kArcRadius_mm - u * u) - 0.005) * 1000.0);
  }
  std::nth_element(closed_form_um.begin(), closed_form_um.begin() + n_y / 2, closed_form_um.end());
  EXPECT_NEAR(map["median_um"].get<double>(), closed_form_um[n_y / 2], 0.1);
  const std::string text = PdfText(*work_ / "ab" / "compare.pdf");
  EXPECT_THAT(text, HasSubstr("Scan comparison: W9-arc55"));
  EXPECT_THAT(text, HasSubstr("|change| > 3 combined σ"));
  EXPECT_THAT(ReadText(*work_ / "ab" / "compare.html"), HasSubstr("yes (&gt; 3σ)"));
}

TEST_F(Compare, CallsAFiveMicrometreRunoutChangeSignificantWithItsU) {
  const nlohmann::json comparison = Run("a", "d", "ad");
  const nlohmann::json& runout = ChangeOf(comparison, "max_runout_um");
  const double sigma = runout["sigma"].get<double>();
  ASSERT_GT(sigma, 0.0);
  EXPECT_NEAR(runout["change"].get<double>(), 5.0, 3.0 * sigma + 0.05);  // 0.05 um: the map's own error
  EXPECT_TRUE(runout["significant"].get<bool>());
  EXPECT_NEAR(runout["U"].get<double>(), 1.959964 * sigma, 1e-9);
}

TEST_F(Compare, ReportsNoChangeOfTheSameWheelAsNotSignificant) {
  const nlohmann::json comparison = Run("a", "c", "ac");
  const nlohmann::json& radius = ChangeOf(comparison, "mean_arc_radius_mm");
  EXPECT_FALSE(radius["significant"].get<bool>())
      << radius["change"].get<double>() * 1000.0 << " um against " << radius["sigma"].get<double>() * 1000.0;
  // The noise-corrected runouts, both of a round wheel, with their type A sigmas: no change.
  const nlohmann::json& runout = ChangeOf(comparison, "max_runout_um");
  EXPECT_FALSE(runout["significant"].get<bool>())
      << runout["change"].get<double>() << " um against " << runout["sigma"].get<double>();
  EXPECT_NEAR(runout["change"].get<double>(), 0.0, 3.0 * runout["sigma"].get<double>() + 1e-9);
  EXPECT_NEAR(comparison["map_difference"]["median_um"].get<double>(), 0.0, 0.5);
}

TEST(CompareScans, RefusesScansOfTwoWheelsAndWritesNothing) {
  TempDir dir;
  const testing::FixtureOptions options{.n_phase = 12, .n_y = 21};
  testing::WriteFixture(dir / "a", options);
  nlohmann::json other = testing::FixtureSummary(options);
  other["scan"]["wheel_id"] = "W18-arc75";
  testing::WriteFixture(dir / "b", options, other);
  const auto result = RunArcwheel(fmt::format("compare '{}' '{}' -o '{}'", (dir / "a").string(),
                                              (dir / "b").string(), (dir / "out").string()));
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_THAT(result.output, HasSubstr("key 'scan.wheel_id' = 'W17-arc75'"));
  EXPECT_THAT(result.output, HasSubstr("'W18-arc75'"));
  EXPECT_FALSE(fs::exists(dir / "out")) << "no output folder left";
}

TEST(InterpolateRho, IsExactForAPlaneAndWrapsInPhase) {
  WheelMapData map;
  map.phase_deg = {0.0, 90.0, 180.0, 270.0};
  map.y_mm = {0.0, 1.0, 2.0};
  for (double c : map.phase_deg) {
    for (double y : map.y_mm) map.rho_mm.push_back(2.0 * y + c / 90.0);
  }
  EXPECT_DOUBLE_EQ(InterpolateRho_mm(map, 45.0, 0.5), 1.0 + 0.5);
  // Between 270 deg (value 3) and 360 = 0 deg (value 0) at y = 1: halfway, 1.5 + 2.
  EXPECT_DOUBLE_EQ(InterpolateRho_mm(map, 315.0, 1.0), 2.0 + 1.5);
  EXPECT_DOUBLE_EQ(InterpolateRho_mm(map, -45.0, 1.0), 2.0 + 1.5);
  EXPECT_TRUE(std::isnan(InterpolateRho_mm(map, 10.0, 2.5))) << "outside the axial nodes";
}

// ---- history ----

TEST(ParseTimestamp, ReadsIsoDateTimesWithZonesAndRefusesOthers) {
  EXPECT_EQ(ParseTimestamp_s("1970-01-02T00:00:00Z", "t"), 86400.0);
  EXPECT_EQ(ParseTimestamp_s("1970-01-01T01:00+01:00", "t"), 0.0);
  EXPECT_EQ(ParseTimestamp_s("1970-01-01 00:00:30.5", "t"), 30.5);
  EXPECT_THAT(ErrorMessageOf([] { (void)ParseTimestamp_s("01/03/2026", "'d.csv' line 3:"); }),
              HasSubstr("'d.csv' line 3: '01/03/2026' is not an ISO 8601 date and time"));
}

TEST(ParseDressingsCsv, SkipsAHeaderAndCommentsAndNamesABadLine) {
  std::vector<std::string> stamps;
  const std::vector<double> times =
      ParseDressingsCsv("date,note\n# shop log\n1970-01-01T02:00:00Z,diamond roll\n\n", "d.csv", &stamps);
  EXPECT_THAT(times, ::testing::ElementsAre(7200.0));
  EXPECT_THAT(stamps, ::testing::ElementsAre("1970-01-01T02:00:00Z"));
  EXPECT_THAT(ErrorMessageOf(
                  [] { (void)ParseDressingsCsv("date\n1970-01-01T02:00Z\n2026-13-01T00:00Z\n", "d.csv"); }),
              HasSubstr("'d.csv' line 3:"));
}

TEST(FitWearRate, RecoversAnExactLineAndTheTwoPointSigma) {
  // r = 50 - 0.002 mm/h * t, sigma 1 um each: slope exact; with two points the slope's sigma is
  // sqrt(s1^2 + s2^2) / dt.
  const WearRate exact = FitWearRate({0.0, 3600.0, 7200.0, 14400.0}, {50.0, 49.998, 49.996, 49.992},
                                     {0.001, 0.001, 0.001, 0.001});
  EXPECT_NEAR(exact.rate_um_per_h, -2.0, 1e-9);
  EXPECT_NEAR(exact.chi2_per_dof, 0.0, 1e-9);
  const WearRate two = FitWearRate({0.0, 7200.0}, {50.0, 49.999}, {0.001, 0.002});
  EXPECT_NEAR(two.rate_um_per_h, -0.5, 1e-9);
  EXPECT_NEAR(two.sigma_um_per_h, std::sqrt(1.0 + 4.0) / 2.0, 1e-9);
}

// Eight scans two hours apart, the arc radius shrinking 0.5 um per hour, and a dressing after the
// fourth that takes 20 um off: each segment's wear rate is -0.5 um/h within 3 sigma.
TEST(FitWearRate, AddsARepeatabilityTermForAKnownExtraScatterAndBringsChiSquareToOne) {
  // 40 scans an hour apart, wearing 0.5 um/h, each with a stated sigma of 0.1 um but an extra
  // scatter of 0.5 um between scans (a repeatability the per-scan sigma cannot see).
  std::mt19937 rng(20261203);
  std::normal_distribution<double> extra(0.0, 0.0005);
  std::vector<double> t, r, s;
  for (int i = 0; i < 40; ++i) {
    t.push_back(3600.0 * i);
    r.push_back(55.0 - 0.0005 * i + extra(rng));
    s.push_back(0.0001);
  }
  const WearRate w = FitWearRate(t, r, s);
  EXPECT_GT(w.chi2_per_dof_scans_alone, 10.0);  // (0.5^2 + 0.1^2) / 0.1^2 = 26 expected
  // s_R^2 + 0.1^2 ~ 0.5^2 + 0.1^2: s_R within about 3 standard errors (0.5 / sqrt(2 x 38)).
  EXPECT_NEAR(w.repeatability_um, 0.5, 0.17);
  EXPECT_NEAR(w.chi2_per_dof, 1.0, 1e-6);
  // The rate with its sigma from the widened weights covers the truth.
  EXPECT_NEAR(w.rate_um_per_h, -0.5, 3.0 * w.sigma_um_per_h);
  // Scans whose scatter their sigmas explain get no term.
  std::normal_distribution<double> own(0.0, 0.0001);
  for (int i = 0; i < 40; ++i) r[i] = 55.0 - 0.0005 * i + own(rng);
  EXPECT_EQ(FitWearRate(t, r, s).repeatability_um, 0.0);
}

TEST(HistoryCommand, ReportsTheKnownWearRateBetweenDressingsWithinThreeSigma) {
  TempDir dir;
  constexpr double kWear_um_per_h = -0.5;
  std::string folders;
  for (int k = 7; k >= 0; --k) {  // given newest first: the history sorts by scan time
    const double hours = 2.0 * k;
    const double radius_mm = kArcRadius_mm + (kWear_um_per_h * hours - (k >= 4 ? 20.0 : 0.0)) / 1000.0;
    const std::string name = fmt::format("scan{}", k);
    SimulateAndProcess(dir.path(), name, radius_mm, 10 + k,
                       fmt::format("2026-03-01T{:02d}:00:00Z", 6 + 2 * k));
    folders += " '" + (dir / name).string() + "'";
  }
  WriteText(dir / "dressings.csv", "date\n2026-03-01T13:00:00Z\n");
  const auto result = RunArcwheel(fmt::format("history{} -o '{}' --dressings '{}'", folders,
                                              (dir / "history").string(), (dir / "dressings.csv").string()));
  ASSERT_EQ(result.exit_status, 0) << result.output;
  const History history = BuildHistory(
      [&] {
        std::vector<fs::path> list;
        for (int k = 0; k < 8; ++k) list.push_back(dir / fmt::format("scan{}", k));
        return list;
      }(),
      {ParseTimestamp_s("2026-03-01T13:00:00Z", "t")}, {"2026-03-01T13:00:00Z"});
  ASSERT_EQ(history.wear.size(), 2u);
  for (const WearRate& wear : history.wear) {
    EXPECT_EQ(wear.scans, 4u);
    EXPECT_NEAR(wear.rate_um_per_h, kWear_um_per_h, 3.0 * wear.sigma_um_per_h)
        << "segment " << wear.segment << ", sigma " << wear.sigma_um_per_h;
    EXPECT_THAT(result.output, HasSubstr(fmt::format("wear, segment {} (4 scans): ", wear.segment)));
  }
  // The CSV lists the scans in time order, with their segment.
  std::istringstream csv(ReadText(dir / "history" / "history.csv"));
  std::vector<std::string> rows;
  for (std::string line; std::getline(csv, line);) {
    if (!line.empty() && line[0] != '#') rows.push_back(line);
  }
  ASSERT_EQ(rows.size(), 9u);
  for (int k = 0; k < 8; ++k) {
    EXPECT_THAT(rows[k + 1], ::testing::StartsWith(fmt::format("2026-03-01T{:02d}:00:00Z,{},{},", 6 + 2 * k,
                                                               2 * k, k >= 4 ? 1 : 0)));
  }
  const std::string text = PdfText(dir / "history" / "history.pdf");
  EXPECT_THAT(text, HasSubstr("Wheel history: W9-arc55"));
  EXPECT_THAT(text, HasSubstr("dressing"));
  EXPECT_THAT(text, HasSubstr("µm/h"));
}

TEST(HistoryCommand, RefusesFoldersOfTwoWheels) {
  TempDir dir;
  const testing::FixtureOptions options{.n_phase = 12, .n_y = 21};
  testing::WriteFixture(dir / "a", options);
  nlohmann::json other = testing::FixtureSummary(options);
  other["scan"]["wheel_id"] = "W18-arc75";
  other["scan"]["timestamp"] = "2026-03-02T08:00:00Z";
  testing::WriteFixture(dir / "b", options, other);
  const auto result = RunArcwheel(fmt::format("history '{}' '{}' -o '{}'", (dir / "a").string(),
                                              (dir / "b").string(), (dir / "out").string()));
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_THAT(result.output, HasSubstr("a history holds one wheel"));
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
}  // namespace arcwheel::reports
