#include "reports/report_inputs.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/testing/testing.h"
#include "reports/report_fixture.h"

namespace arcwheel::reports {
namespace {

using namespace arcwheel::testing;  // the shared test helpers (core/testing/testing.h)
using testing::FixtureOptions;
using testing::FixtureSummary;
using ::testing::HasSubstr;
using testing::WriteFixture;

TEST(ReadReportInputs, ReadsBackTheFixtureValues) {
  TempDir dir;
  const FixtureOptions options{.n_phase = 36, .n_y = 41};
  WriteFixture(dir.path(), options);
  const ReportInputs inputs = ReadReportInputs(dir.path());
  const Summary& s = inputs.summary;
  EXPECT_EQ(s.arcwheel_version, "0.1.0");
  EXPECT_EQ(s.input.path, "/data/scans/wheel_W17.h5");
  EXPECT_EQ(s.input.samples, 2400000);
  EXPECT_EQ(s.input.despiked_samples, 37);
  EXPECT_DOUBLE_EQ(s.mean_arc_radius_mm, 75.01234);
  EXPECT_DOUBLE_EQ(s.max_runout_um, 7.13);
  EXPECT_DOUBLE_EQ(s.band_low_mm, 2.0);
  EXPECT_DOUBLE_EQ(s.band_high_mm, 18.0);
  ASSERT_EQ(s.phases.phase_deg.size(), 36u);
  EXPECT_DOUBLE_EQ(s.phases.phase_deg[9], 90.0);
  EXPECT_DOUBLE_EQ(s.phases.arc_radius_mm[9], testing::FixtureArcRadius_mm(90.0));
  EXPECT_EQ(s.scan.at("wheel_id"), "W17-arc75");
  EXPECT_EQ(s.processing.at("despike_threshold_um"), 5.0);
  EXPECT_EQ(s.processing.at("fit_span"), "band");
  ASSERT_EQ(s.warnings.size(), 1u);

  const WheelMapData& map = inputs.map;
  ASSERT_EQ(map.n_phase(), 36u);
  ASSERT_EQ(map.n_y(), 41u);
  EXPECT_DOUBLE_EQ(map.y_mm[40], 20.0);
  // rho at (c = 0, y = 10) from the fixture's closed form.
  const double a = testing::FixtureCenterAxial_mm(0.0);
  const double ra = testing::FixtureArcRadius_mm(0.0);
  EXPECT_NEAR(map.rho_mm[20],
              testing::FixtureCenterRadial_mm(0.0) + std::sqrt(ra * ra - (10.0 - a) * (10.0 - a)), 1e-12);
  EXPECT_TRUE(std::isnan(map.rho_mm[9 * 41 + 0])) << "missing cell at c = 90, y = 0";
  EXPECT_EQ(map.sample_count[9 * 41 + 0], 0.0);
  EXPECT_EQ(map.despiked_count[18 * 41 + 11], 1.0) << "despiked cell at c = 180, y = 5.5";
  EXPECT_EQ(map.input_sha256, s.input.sha256);
}

TEST(ReadReportInputs, ReadsBackTheFixtureModel) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 36, .n_y = 41});
  const ReportInputs inputs = ReadReportInputs(dir.path());
  ASSERT_TRUE(inputs.summary.model.has_value());
  const ModelSummary& m = *inputs.summary.model;
  // The values FixtureModel (report_fixture.cc) gives the writer.
  EXPECT_EQ(m.radius_knots, 8);
  EXPECT_EQ(m.axial_knots, 4);
  EXPECT_EQ(m.runout_knots, 16);
  EXPECT_EQ(m.knots_chosen_by, "bic");
  EXPECT_DOUBLE_EQ(m.mean_arc_radius_mm, 75.00003);
  EXPECT_DOUBLE_EQ(m.arc_radius_range_sigma_mm, 0.0003);
  EXPECT_DOUBLE_EQ(m.variation_chi2, 912.345);
  EXPECT_EQ(m.variation_dof, 7);
  EXPECT_TRUE(m.variation_significant);
  EXPECT_DOUBLE_EQ(m.residual_rms_um, 0.3127);
  ASSERT_EQ(m.radius_harmonics.size(), 2u);
  EXPECT_EQ(m.radius_harmonics[1].order, 2);
  EXPECT_DOUBLE_EQ(m.radius_harmonics[1].phase_deg, -90.0);
  EXPECT_EQ(inputs.summary.schema_version, "1.2");

  ASSERT_TRUE(inputs.map.model.has_value());
  const ModelCurves& curves = *inputs.map.model;
  ASSERT_EQ(curves.arc_radius_mm.size(), 36u);
  EXPECT_DOUBLE_EQ(curves.arc_radius_mm[4], testing::FixtureArcRadius_mm(40.0));
  EXPECT_DOUBLE_EQ(curves.center_radial_sigma_mm[4], 0.00015);
  ASSERT_EQ(curves.profile_u_mm.size(), 161u);
  EXPECT_NEAR(curves.profile_error_um[80], 0.42, 1e-12) << "p(0)";
  ASSERT_EQ(curves.residual_um.size(), 36u * 41u);
  EXPECT_NEAR(curves.residual_um[5 * 41 + 20], testing::FixtureModelResidual_um(50.0, 10.0, true), 1e-12);
}

TEST(ReadReportInputs, ReadsFilesWithoutAModel) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21, .with_model = false});
  const ReportInputs inputs = ReadReportInputs(dir.path());
  EXPECT_FALSE(inputs.summary.model.has_value());
  EXPECT_FALSE(inputs.map.model.has_value());
}

TEST(ReadReportInputs, RefusesASummaryWithAModelBesideAMapWithout) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21, .with_model = false},
               FixtureSummary({.n_phase = 12, .n_y = 21}));
  const std::string message = ErrorMessageOf([&] { (void)ReadReportInputs(dir.path()); });
  EXPECT_THAT(message, HasSubstr("wheel_map.h5' group '/model' is missing, but '"));
  EXPECT_THAT(message, HasSubstr("summary.json' has key 'model'"));
}

TEST(ReadSummary, ReadsNullAsNaN) {
  nlohmann::json summary = FixtureSummary({});
  summary["max_roundness_um"] = nullptr;
  summary["phases"]["arc_radius_mm"][3] = nullptr;
  const Summary s = ParseSummary(summary.dump(), "s.json");
  EXPECT_TRUE(std::isnan(s.max_roundness_um));
  EXPECT_TRUE(std::isnan(s.phases.arc_radius_mm[3]));
}

// 1.1 since both files gained the wheel model (docs/outputs.md).
TEST(WriteFixture, RecordsTheSchemaVersionOfEachFile) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21});
  std::ifstream summary_file(dir / "summary.json");
  EXPECT_EQ(nlohmann::json::parse(summary_file).at("schema_version"), "1.2");
  EXPECT_EQ(hdf5::File::OpenReadOnly(dir / "wheel_map.h5").ReadAttributeString("/", "schema_version"), "1.1");
}

TEST(ReadSummary, ReadsAFileWrittenBeforeSchemaVersions) {
  nlohmann::json summary = FixtureSummary({.n_phase = 12, .n_y = 21});
  summary.erase("schema_version");
  const Summary s = ParseSummary(summary.dump(), "old/summary.json");
  EXPECT_DOUBLE_EQ(s.mean_arc_radius_mm, 75.01234);
  EXPECT_EQ(s.phases.phase_deg.size(), 12u);
}

TEST(ReadSummary, ReadsALaterMinorVersionOfTheSameMajor) {
  nlohmann::json summary = FixtureSummary({.n_phase = 12, .n_y = 21});
  summary["schema_version"] = "1.7";
  summary["a_key_added_in_1_7"] = 42;
  EXPECT_DOUBLE_EQ(ParseSummary(summary.dump(), "s.json").max_runout_um, 7.13);
}

TEST(ReadSummary, RefusesANewerMajorVersionNamingTheFileAndBothVersions) {
  nlohmann::json summary = FixtureSummary({.n_phase = 12, .n_y = 21});
  summary["schema_version"] = "2.0";
  const std::string message = ErrorMessageOf([&] { (void)ParseSummary(summary.dump(), "out/summary.json"); });
  EXPECT_THAT(message, HasSubstr("'out/summary.json' key 'schema_version' = '2.0'"));
  EXPECT_THAT(message, HasSubstr("reads schema version 1.x only"));
}

TEST(ReadSummary, RefusesASchemaVersionThatIsNotText) {
  nlohmann::json summary = FixtureSummary({.n_phase = 12, .n_y = 21});
  summary["schema_version"] = 2;
  const std::string message = ErrorMessageOf([&] { (void)ParseSummary(summary.dump(), "out/summary.json"); });
  EXPECT_THAT(message, HasSubstr("key 'schema_version' is not a string (found 2)"));
}

TEST(ReadSummary, RefusesAMissingFileNamingIt) {
  TempDir dir;
  const std::string message =
      ErrorMessageOf([&] { (void)ReadSummary(dir / "summary.json"); }, ErrorCode::kIo);
  EXPECT_THAT(message, HasSubstr((dir / "summary.json").string()));
  EXPECT_THAT(message, HasSubstr("does not exist"));
}

TEST(ReadSummary, RefusesInvalidJsonNamingTheFile) {
  EXPECT_THAT(ErrorMessageOf([] { (void)ParseSummary("{\"arcwheel_version\": ", "out/summary.json"); }),
              HasSubstr("'out/summary.json' is not valid JSON"));
}

struct BrokenSummaryCase {
  const char* name;
  void (*damage)(nlohmann::json&);
  const char* expected_message;
};

class ReadSummaryRefuses : public ::testing::TestWithParam<BrokenSummaryCase> {};

TEST_P(ReadSummaryRefuses, NamingTheKey) {
  nlohmann::json summary = FixtureSummary({.n_phase = 12, .n_y = 21});
  GetParam().damage(summary);
  const std::string message = ErrorMessageOf([&] { (void)ParseSummary(summary.dump(), "out/summary.json"); });
  EXPECT_THAT(message, HasSubstr(GetParam().expected_message));
}

INSTANTIATE_TEST_SUITE_P(
    BadSummaries, ReadSummaryRefuses,
    ::testing::Values(
        BrokenSummaryCase{"MissingHeadline", [](nlohmann::json& s) { s.erase("max_runout_um"); },
                          "'out/summary.json' key 'max_runout_um' is missing"},
        BrokenSummaryCase{"MissingInputHash", [](nlohmann::json& s) { s["input"].erase("sha256"); },
                          "key 'input.sha256' is missing"},
        BrokenSummaryCase{"TextForNumber", [](nlohmann::json& s) { s["mean_arc_radius_mm"] = "75.0"; },
                          "key 'mean_arc_radius_mm' is not a number (found \"75.0\")"},
        BrokenSummaryCase{"ShortArray", [](nlohmann::json& s) { s["phases"]["arc_error_um"].erase(0); },
                          "key 'phases.arc_error_um' has 11 entries, expected 12"},
        BrokenSummaryCase{"TextInArray", [](nlohmann::json& s) { s["axial"]["runout_um"][2] = "x"; },
                          "key 'axial.runout_um.2' is not a number"},
        BrokenSummaryCase{"MissingPhases", [](nlohmann::json& s) { s.erase("phases"); },
                          "key 'phases' is missing"},
        BrokenSummaryCase{"MissingProcessing", [](nlohmann::json& s) { s.erase("processing"); },
                          "key 'processing' is missing"},
        BrokenSummaryCase{"NegativeCount", [](nlohmann::json& s) { s["input"]["samples"] = -4; },
                          "key 'input.samples' is not a non-negative integer"},
        BrokenSummaryCase{"BadUsable", [](nlohmann::json& s) { s["phases"]["usable"][1] = 1; },
                          "key 'phases.usable.1' is not a boolean"},
        BrokenSummaryCase{"MissingModelKey", [](nlohmann::json& s) { s["model"].erase("residual_rms_um"); },
                          "key 'model.residual_rms_um' is missing"},
        BrokenSummaryCase{"TextInHarmonic",
                          [](nlohmann::json& s) { s["model"]["radius_harmonics"][1]["phase_deg"] = "x"; },
                          "key 'model.radius_harmonics.1.phase_deg' is not a number"},
        BrokenSummaryCase{"NumberForVerdict",
                          [](nlohmann::json& s) { s["model"]["radius_variation_significant"] = 1; },
                          "key 'model.radius_variation_significant' is not true or false (found 1)"},
        BrokenSummaryCase{"FractionalKnots", [](nlohmann::json& s) { s["model"]["radius_knots"] = 8.5; },
                          "key 'model.radius_knots' is not a non-negative integer (found 8.5)"},
        BrokenSummaryCase{"NotAnObject", [](nlohmann::json& s) { s = nlohmann::json::array(); },
                          "'out/summary.json' is not a JSON object"}),
    [](const ::testing::TestParamInfo<BrokenSummaryCase>& param_info) {
      return std::string(param_info.param.name);
    });

TEST(ReadWheelMap, RefusesAMissingFileNamingIt) {
  TempDir dir;
  const std::string message =
      ErrorMessageOf([&] { (void)ReadWheelMap(dir / "wheel_map.h5"); }, ErrorCode::kIo);
  EXPECT_THAT(message, HasSubstr((dir / "wheel_map.h5").string()));
}

// The message with which ReadWheelMap refuses dir/wheel_map.h5 as bad input.
std::string WheelMapRefusal(const TempDir& dir) {
  return ErrorMessageOf([&] { (void)ReadWheelMap(dir / "wheel_map.h5"); });
}

TEST(ReadWheelMap, RefusesAFileThatIsNotHdf5) {
  TempDir dir;
  std::ofstream(dir / "wheel_map.h5") << "not hdf5";
  const std::string message = WheelMapRefusal(dir);
  EXPECT_THAT(message, HasSubstr("not an HDF5 file"));
}

// Writes a 3 x 2 map; `rho_shape` may differ from it, and form_error_um may be left out. Without
// `schema_version`, the map is one written before versions were recorded.
// With `model_radius_shape`, the map also has /model/arc_radius_mm of that shape (and nothing else
// in /model).
void WriteMapWith(const std::filesystem::path& path, bool with_form_error, std::vector<hsize_t> rho_shape,
                  const std::string& schema_version = "", std::vector<hsize_t> model_radius_shape = {}) {
  hdf5::File file = hdf5::File::Create(path);
  if (!schema_version.empty()) file.WriteAttribute("/", "schema_version", schema_version);
  file.CreateGroup("/map");
  file.WriteDoubles("/map/phase_deg", {0.0, 120.0, 240.0}, {3});
  file.WriteDoubles("/map/y_mm", {0.0, 1.0}, {2});
  const std::vector<double> grid(rho_shape[0] * rho_shape[1], 1.0);
  file.WriteDoubles("/map/rho", grid, rho_shape);
  if (with_form_error) file.WriteDoubles("/map/form_error_um", std::vector<double>(6, 0.0), {3, 2});
  file.WriteInts("/map/sample_count", std::vector<int>(6, 1), {3, 2});
  file.WriteInts("/map/despiked_count", std::vector<int>(6, 0), {3, 2});
  if (model_radius_shape.empty()) return;
  file.CreateGroup("/model");
  file.WriteDoubles("/model/arc_radius_mm", std::vector<double>(model_radius_shape[0], 75.0),
                    model_radius_shape);
}

TEST(ReadWheelMap, RefusesAMissingDatasetNamingIt) {
  TempDir dir;
  WriteMapWith(dir / "wheel_map.h5", false, {3, 2});
  const std::string message = WheelMapRefusal(dir);
  EXPECT_THAT(message, HasSubstr("wheel_map.h5' dataset '/map/form_error_um' is missing"));
}

TEST(ReadWheelMap, RefusesAGridOfTheWrongShape) {
  TempDir dir;
  WriteMapWith(dir / "wheel_map.h5", true, {2, 3});
  const std::string message = WheelMapRefusal(dir);
  EXPECT_THAT(message, HasSubstr("dataset '/map/rho' has shape [2, 3], expected [3, 2]"));
}

TEST(ReadWheelMap, RefusesAModelCurveOfTheWrongShape) {
  TempDir dir;
  WriteMapWith(dir / "wheel_map.h5", true, {3, 2}, "1.1", {2});
  EXPECT_THAT(WheelMapRefusal(dir), HasSubstr("dataset '/model/arc_radius_mm' has shape [2], expected [3]"));
}

TEST(ReadWheelMap, RefusesAModelGroupMissingACurve) {
  TempDir dir;
  WriteMapWith(dir / "wheel_map.h5", true, {3, 2}, "1.1", {3});
  EXPECT_THAT(WheelMapRefusal(dir), HasSubstr("dataset '/model/arc_radius_sigma_mm' is missing"));
}

TEST(ReadWheelMap, ReadsAMapWrittenBeforeSchemaVersionsAndOneOfTheSameMajor) {
  TempDir dir;
  for (const std::string version : {"", "1.0", "1.4"}) {
    WriteMapWith(dir / "wheel_map.h5", true, {3, 2}, version);
    const WheelMapData map = ReadWheelMap(dir / "wheel_map.h5");
    EXPECT_EQ(map.n_phase(), 3u) << "schema_version '" << version << "'";
    EXPECT_EQ(map.n_y(), 2u);
  }
}

TEST(ReadWheelMap, RefusesANewerMajorVersionNamingTheFileAndBothVersions) {
  TempDir dir;
  WriteMapWith(dir / "wheel_map.h5", true, {3, 2}, "2.1");
  const std::string message = WheelMapRefusal(dir);
  EXPECT_THAT(message, HasSubstr("wheel_map.h5' attribute 'schema_version' = '2.1'"));
  EXPECT_THAT(message, HasSubstr("reads schema version 1.x only"));
}

TEST(ReadReportInputs, RefusesASummaryAndMapOfDifferentScans) {
  TempDir dir;
  const FixtureOptions options{.n_phase = 12, .n_y = 21};
  nlohmann::json summary = FixtureSummary(options);
  summary["input"]["sha256"] = std::string(64, 'a');
  WriteFixture(dir.path(), options, summary);
  const std::string message = ErrorMessageOf([&] { (void)ReadReportInputs(dir.path()); });
  EXPECT_THAT(message, HasSubstr("describe different scans"));
}

TEST(ReadReportInputs, RefusesAMapWithADifferentPhaseCount) {
  TempDir dir;
  WriteFixture(dir.path(), {.n_phase = 12, .n_y = 21}, FixtureSummary({.n_phase = 24, .n_y = 21}));
  const std::string message = ErrorMessageOf([&] { (void)ReadReportInputs(dir.path()); });
  EXPECT_THAT(message, HasSubstr("has 12 phases but"));
}

}  // namespace
}  // namespace arcwheel::reports
