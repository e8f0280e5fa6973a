#include "reports/polish_report_inputs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/testing/testing.h"

namespace arcwheel::reports {
namespace {

using arcwheel::testing::ErrorMessageOf;
using arcwheel::testing::ErrorOf;
using arcwheel::testing::TempDir;
using ::testing::HasSubstr;

// A 3 x 2 grid (x = -2, 0, 2 mm; y = 5, 6 mm) with the node (2, 6) missing, rows in any order.
constexpr const char* kResidual =
    "x_mm,y_mm,target_um,removal_um,residual_um\n"
    "0,5,1.5,1.25,0.25\n"
    "-2,5,1,0.75,0.25\n"
    "2,5,2,2.5,-0.5\n"
    "-2,6,1.25,1,0.25\r\n"
    "0,6,3,2,1\n";

TEST(ParseResidualMapCsv, PutsTheNodesBackOnTheirGridWithGapsForMissingNodes) {
  const ResidualMap map = ParseResidualMapCsv(kResidual, "res.csv");
  EXPECT_EQ(map.x_mm, (std::vector<double>{-2.0, 0.0, 2.0}));
  EXPECT_EQ(map.y_mm, (std::vector<double>{5.0, 6.0}));
  EXPECT_EQ(map.nodes, 5u);
  // Index i * n_y + j.
  EXPECT_EQ(map.target_um[0 * 2 + 0], 1.0);
  EXPECT_EQ(map.target_um[1 * 2 + 1], 3.0);
  EXPECT_EQ(map.removal_um[2 * 2 + 0], 2.5);
  EXPECT_EQ(map.residual_um[0 * 2 + 1], 0.25);
  EXPECT_TRUE(std::isnan(map.residual_um[2 * 2 + 1])) << "node (2, 6) is not in the file";
}

TEST(ParseResidualMapCsv, RefusesMalformedLinesNamingSourceAndLine) {
  struct Case {
    std::string text;
    std::string message;
  };
  const std::vector<Case> cases = {
      {"x_mm,y_mm,target_um,removal_um\n0,0,1,1\n",
       "'res.csv' line 1: header 'x_mm,y_mm,target_um,removal_um' has no column 'residual_um'"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\n0,0,1,1,0\n2,0,1,x1,0\n",
       "'res.csv' line 3: removal_um 'x1' is not a number"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\n0,0,1,1,0\n2,0,1,1\n",
       "'res.csv' line 3: has 4 values, the header names 5"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\n0,0,1,1,0\n0,0,1,1,0\n",
       "'res.csv' line 3: node (0, 0) mm appears twice"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\n0,0,1,1,0\n2,0,1,1,0\n4,0,1,1,0\n4.5,0,1,1,0\n",
       "'res.csv' line 5: node (4.5, 0) mm is not on the grid"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\nnan,0,1,1,0\n",
       "'res.csv' line 2: x_mm and y_mm must be finite"},
      {"# only a comment\n", "'res.csv' line 1: has no header line"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\n", "'res.csv' has no aperture node"},
      {"x_mm,y_mm,target_um,removal_um,residual_um\n0,0,1,1,0\n1e-9,0,1,1,0\n2e-9,0,1,1,0\n1000,0,1,1,0\n",
       "'res.csv': the x_mm nodes would need a grid of"},
  };
  for (const Case& c : cases) {
    const Error error = ErrorOf([&] { (void)ParseResidualMapCsv(c.text, "res.csv"); });
    EXPECT_EQ(error.code(), ErrorCode::kBadInput) << c.text;
    EXPECT_THAT(error.what(), HasSubstr(c.message)) << c.text;
  }
}

TEST(ParsePolishingPathCsv, ReadsColumnsByNameKeepsCommentsAndMeasuresThePath) {
  // A 3-4-5 step then a 0-0-2 step: path lengths 0, 5, 7 mm. Extra column "note_id" ignored.
  const std::string text =
      "# arcwheel polish, job 'x'\n# surface: plane\n"
      "dwell_s,speed_mm_s,x,y,z,q1,q2,q3,q4,note_id\n"
      "0,150,0,0,0,0,1,0,0,7\n"
      "0.5,10,3,4,0,0,1,0,0,8\n"
      "1,2,3,4,2,0,1,0,0,9\n";
  const PolishingPathTable path = ParsePolishingPathCsv(text, "path.csv");
  ASSERT_EQ(path.size(), 3u);
  EXPECT_EQ(path.comments, (std::vector<std::string>{"arcwheel polish, job 'x'", "surface: plane"}));
  EXPECT_EQ(path.speed_mm_s, (std::vector<double>{150.0, 10.0, 2.0}));
  EXPECT_EQ(path.dwell_s, (std::vector<double>{0.0, 0.5, 1.0}));
  EXPECT_EQ(path.x_mm[1], 3.0);
  EXPECT_DOUBLE_EQ(path.path_length_mm[1], 5.0);
  EXPECT_DOUBLE_EQ(path.path_length_mm[2], 7.0);
}

TEST(ParsePolishingPathCsv, RefusesBadRowsNamingSourceAndLine) {
  const std::string header = "x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s\n";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {header + "0,0,0,1,0,0,0,0,1\n", "'path.csv' line 2: speed_mm_s = 0 is not > 0"},
      {header + "0,0,0,1,0,0,0,5,1\n0,0,0,1,0,0,0,5,-1\n", "'path.csv' line 3: dwell_s = -1 is negative"},
      {header + "0,0,inf,1,0,0,0,5,1\n", "'path.csv' line 2: every value must be finite"},
      {"x,y,z,q1,q2,q3,q4,speed_mm_s\n",
       "'path.csv' line 1: header 'x,y,z,q1,q2,q3,q4,speed_mm_s' has no column 'dwell_s'"},
      {header, "'path.csv' has no path point"},
      {header + "0, 0,0,1,0,0,0,5,1\n", "'path.csv' line 2: y ' 0' is not a number"},
  };
  for (const auto& [text, message] : cases) {
    const Error error = ErrorOf([&, &input = text] { (void)ParsePolishingPathCsv(input, "path.csv"); });
    EXPECT_EQ(error.code(), ErrorCode::kBadInput) << text;
    EXPECT_THAT(error.what(), HasSubstr(message)) << text;
  }
}

constexpr const char* kSummary = R"({
  "arcwheel_version": "9.9.9",
  "job": {"name": "disc", "error_map": {"file": "map.csv"},
          "machine": {"max_speed_mm_s": 150.0, "min_speed_mm_s": 0.5, "max_acceleration_mm_s2": 0.0}},
  "points": 3, "aperture_nodes": 5, "total_time_s": 35.31234567890123,
  "before": {"pv_um": 0.7221604992191419, "rms_um": 0.16116578047031774},
  "after": {"pv_um": 0.00941040908370816, "rms_um": 1.495433475096257e-05},
  "speed_mm_s": {"min": 33.5, "max": 132.25}, "max_acceleration_mm_s2": 2761.75,
  "solver": {"iterations": 352, "converged": true, "nonzeros": 1000}
})";

TEST(ParsePolishSummary, KeepsTheNumbersAsTheFileWritesThem) {
  const PolishSummary s = ParsePolishSummary(kSummary, "sum.json");
  EXPECT_EQ(s.job_name, "disc");
  EXPECT_EQ(s.error_map_file, "map.csv");
  EXPECT_EQ(s.points, 3);
  EXPECT_EQ(s.aperture_nodes, 5);
  EXPECT_EQ(s.total_time_text, "35.31234567890123");
  EXPECT_EQ(s.before_pv_text, "0.7221604992191419");
  EXPECT_EQ(s.before_rms_text, "0.16116578047031774");
  EXPECT_EQ(s.after_pv_text, "0.00941040908370816");
  EXPECT_EQ(s.after_rms_text, "1.495433475096257e-05");
  EXPECT_EQ(s.after_rms_um, 1.495433475096257e-05);
  EXPECT_EQ(s.limit_max_speed_mm_s, 150.0);
  EXPECT_EQ(s.limit_min_speed_mm_s, 0.5);
  EXPECT_EQ(s.solver_iterations, 352);
  EXPECT_TRUE(s.solver_converged);
}

TEST(ParsePolishSummary, RefusesMissingOrMistypedKeysByDottedName) {
  nlohmann::json base = nlohmann::json::parse(kSummary);
  auto without = [&](const std::string& a, const std::string& b) {
    nlohmann::json j = base;
    if (b.empty())
      j.erase(a);
    else
      j[a].erase(b);
    return j.dump();
  };
  nlohmann::json typed = base;
  typed["solver"]["iterations"] = "many";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {without("before", "pv_um"), "'sum.json' key 'before.pv_um' is missing"},
      {without("total_time_s", ""), "'sum.json' key 'total_time_s' is missing"},
      {typed.dump(), "'sum.json' key 'solver.iterations' is not a non-negative integer"},
      {"{\"arcwheel_version\": ", "'sum.json' is not valid JSON"},
  };
  for (const auto& [text, message] : cases) {
    const Error error = ErrorOf([&, &input = text] { (void)ParsePolishSummary(input, "sum.json"); });
    EXPECT_EQ(error.code(), ErrorCode::kBadInput);
    EXPECT_THAT(error.what(), HasSubstr(message));
  }
}

// kSummary records no schema_version, as files written before 1.0: it is read (test above).
TEST(ParsePolishSummary, ReadsTheSameMajorVersionAndRefusesANewerOne) {
  nlohmann::json summary = nlohmann::json::parse(kSummary);
  summary["schema_version"] = "1.2";
  EXPECT_EQ(ParsePolishSummary(summary.dump(), "sum.json").points, 3);
  summary["schema_version"] = "2.0";
  const std::string message =
      ErrorMessageOf([&] { (void)ParsePolishSummary(summary.dump(), "out/polish_summary.json"); });
  EXPECT_THAT(message, HasSubstr("'out/polish_summary.json' key 'schema_version' = '2.0'"));
  EXPECT_THAT(message, HasSubstr("reads schema version 1.x only"));
}

TEST(ReadPolishReportInputs, RefusesFilesThatDisagreeAndNamesMissingFiles) {
  TempDir dir;
  std::ofstream(dir / "polish_summary.json") << kSummary;
  std::ofstream(dir / "residual_map.csv") << kResidual;
  std::ofstream(dir / "polishing_path.csv")
      << "x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s\n0,0,0,1,0,0,0,5,0\n1,0,0,1,0,0,0,5,0.2\n";
  const Error count = ErrorOf([&] { (void)ReadPolishReportInputs(dir.path()); });
  EXPECT_EQ(count.code(), ErrorCode::kBadInput);
  EXPECT_THAT(count.what(), HasSubstr("polishing_path.csv' has 2 points but"));
  EXPECT_THAT(count.what(), HasSubstr("polish_summary.json' key 'points' says 3"));

  std::ofstream(dir / "polishing_path.csv", std::ios::app) << "2,0,0,1,0,0,0,5,0.2\n";
  const PolishReportInputs inputs = ReadPolishReportInputs(dir.path());
  ASSERT_EQ(inputs.sources.size(), 3u);
  EXPECT_EQ(inputs.sources[1].path, dir / "residual_map.csv");
  EXPECT_EQ(inputs.sources[1].sha256.size(), 64u);

  std::filesystem::remove(dir / "residual_map.csv");
  const Error missing = ErrorOf([&] { (void)ReadPolishReportInputs(dir.path()); });
  EXPECT_EQ(missing.code(), ErrorCode::kIo);
  EXPECT_THAT(missing.what(), HasSubstr((dir / "residual_map.csv").string() + "' does not exist"));
}

}  // namespace
}  // namespace arcwheel::reports
