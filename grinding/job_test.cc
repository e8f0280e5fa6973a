#include "grinding/job.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "core/error.h"
#include "core/testing/testing.h"
#include "core/version.h"
#include "grinding/toolpath_writer.h"

namespace arcwheel::grinding {

using surfaces::EvenAsphere;

namespace {

using arcwheel::testing::ErrorMessageOf;
using arcwheel::testing::ErrorOf;
using arcwheel::testing::WriteText;
using nlohmann::json;
using ::testing::AllOf;
using ::testing::HasSubstr;

json SmallJob() {
  return json::parse(R"({
    "surface": {"type": "even_asphere", "vertex_radius_mm": 800.0, "conic": -2.2,
                "off_axis_mm": [300.0, 0.0], "form": "concave"},
    "aperture": {"shape": "rectangle", "size_mm": [60.0, 40.0]},
    "wheel": {"arc_radius_mm": 50.0, "total_radius_mm": 200.0, "width_mm": 20.0},
    "path": {"step_over_mm": 4.0, "point_spacing_mm": 2.0, "feed_mm_per_min": 6000.0,
             "lead_in_mm": 3.0, "lead_out_mm": 3.0},
    "prediction": {"arc_radius_error_mm": 0.1, "map_nodes": [31, 21]}
  })");
}

// The message with which ParseJob refuses `job` as bad input; "accepted" if it does not.
std::string ExpectRefused(const json& job, const std::filesystem::path& source = "job.json",
                          std::optional<std::filesystem::path> summary = std::nullopt) {
  return ErrorMessageOf([&] { (void)ParseJob(job.dump(), source, summary); });
}

// The refusal of `job` with a circular aperture of `diameter_mm`, which the surface cannot hold.
std::string ApertureRefusal(json job, double diameter_mm) {
  job["aperture"] = {{"shape", "circle"}, {"diameter_mm", diameter_mm}};
  const std::string message = ExpectRefused(job);
  EXPECT_THAT(message, HasSubstr("key 'aperture' does not fit the surface"));
  return message;
}

TEST(ParseJob, ReadsTheShippedTrialPart) {
  const Job job = ReadJob(testing::SourceDir() / "grinding/examples/trial_part.json", std::nullopt);
  EXPECT_THAT(job.surface->Describe(), HasSubstr("R0 = 4066.172723 mm, k = -0.581986"));
  EXPECT_THAT(job.surface->Describe(), HasSubstr("(300, 300) mm off the parent axis"));
  EXPECT_DOUBLE_EQ(job.aperture.width_x_mm, 430.0);
  EXPECT_DOUBLE_EQ(job.wheel.arc_radius_mm, 55.4423);
  EXPECT_DOUBLE_EQ(job.wheel.base_radius_mm, 200.0 - 55.4423);
  EXPECT_DOUBLE_EQ(job.path.feed_mm_per_min, 6000.0);
  EXPECT_EQ(json::parse(job.resolved_json)["path"]["direction"], "zigzag");  // defaults are recorded
  EXPECT_EQ(job.prediction.runout_phase_deg.size(), 360u);
}

TEST(ParseJob, RefusesUnknownKeysByTheirDottedName) {
  json job = SmallJob();
  job["path"]["step_over"] = 1.0;
  job["colour"] = "red";
  EXPECT_THAT(ExpectRefused(job), HasSubstr("'job.json': unknown key 'path.step_over'"));
  job["path"].erase("step_over");
  EXPECT_THAT(ExpectRefused(job), HasSubstr("'job.json': unknown key 'colour'"));
  job = SmallJob();
  job["surface"]["coefficients"] = {{"A4", 1e-12}, {"A3", 1.0}};
  EXPECT_THAT(ExpectRefused(job), HasSubstr("unknown key 'surface.coefficients.A3'"));
}

TEST(ParseJob, RefusesWrongTypesAndValuesNamingTheKey) {
  json job = SmallJob();
  job["path"]["passes"] = 1.5;
  EXPECT_THAT(ExpectRefused(job), HasSubstr("key 'path.passes' expected an integer, got 1.5"));
  job = SmallJob();
  job["path"]["step_over_mm"] = -2.0;
  EXPECT_THAT(ExpectRefused(job), HasSubstr("path.step_over_mm = -2 violates > 0"));
  job = SmallJob();
  job["surface"]["form"] = "flat";
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("key 'surface.form' expected one of \"concave\", \"convex\", got \"flat\""));
  job = SmallJob();
  job["wheel"].erase("width_mm");
  EXPECT_THAT(ExpectRefused(job), HasSubstr("key 'wheel.width_mm' expected a finite number, got nothing"));
  job = SmallJob();
  job["wheel"]["total_radius_mm"] = 40.0;
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("wheel.total_radius_mm = 40 violates >= wheel.arc_radius_mm = 50"));
}

TEST(ParseJob, RefusesEveryValueOutOfRangeInOneErrorWithTheFileTheKeysAndTheValues) {
  json job = SmallJob();
  job["path"]["step_over_mm"] = -2.0;
  job["machine"] = {{"decimals", 12}};
  EXPECT_EQ(
      ExpectRefused(job),
      "grinding.job: 'job.json': path.step_over_mm = -2 violates > 0; machine.decimals = 12 violates 1 .. 9");
}

TEST(ParseJob, RefusesMapNodesThatAreNotWholeNumbers) {
  json job = SmallJob();
  job["prediction"]["map_nodes"] = {31.5, 21};
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("key 'prediction.map_nodes' expected two whole numbers, got [31.5,21]"));
  // A count beyond an int is a whole number, but no map that fits: the memory budget refuses it
  // before any cast (RefusesSizesBeyondTheMemoryBudget...).
  job["prediction"]["map_nodes"] = {31, 1e12};
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("prediction.map_nodes = [31, 1000000000000] violates the memory budget"));
}

TEST(ParseJob, RefusesAnApertureOffTheSurfacesDomainNamingThePoint) {
  json job = SmallJob();
  job["surface"] = {{"type", "even_asphere"}, {"vertex_radius_mm", 100.0}, {"conic", 0.0}};
  EXPECT_THAT(ApertureRefusal(job, 250.0), HasSubstr("point ("));
}

TEST(ParseJob, TakesTheWheelFromASummaryAndNeedsItsTotalRadius) {
  const testing::TempDir dir;
  WriteText(dir / "summary.json", R"({
    "mean_arc_radius_mm": 55.0, "mean_arc_radius_sigma_mm": 0.002, "max_runout_um": 1.5,
    "scan": {"wheel_diameter_mm": null},
    "mean_profile": {"u_mm": [-8.0, 0.0, 8.0], "error_um": [1.0, null, -1.0]}
  })");
  json job = SmallJob();
  job["wheel"].erase("arc_radius_mm");
  job["wheel"].erase("total_radius_mm");
  job["wheel"]["summary"] = "summary.json";
  job["prediction"] = {{"spindle_rpm", 1432.0}};
  EXPECT_THAT(ExpectRefused(job, dir / "job.json"),
              HasSubstr("key 'wheel.total_radius_mm' is missing and the summary"));
  job["wheel"]["total_radius_mm"] = 200.0;
  const Job parsed = ParseJob(job.dump(), dir / "job.json", std::nullopt);
  EXPECT_DOUBLE_EQ(parsed.wheel.arc_radius_mm, 55.0);
  EXPECT_DOUBLE_EQ(parsed.wheel.base_radius_mm, 145.0);
  EXPECT_EQ(parsed.wheel.profile_u_mm, (std::vector<double>{-8.0, 8.0}));  // the null node dropped
  EXPECT_DOUBLE_EQ(parsed.prediction.arc_radius_error_mm, 0.002);          // the summary's 1-sigma
  EXPECT_NEAR(parsed.prediction.runout_radial_um[0], 0.75, 1e-12);         // TIR / 2 at phase 0

  // A nominal radius in the job: the measured one wins, both are recorded.
  job["wheel"]["arc_radius_mm"] = 55.3;
  const Job dressed = ParseJob(job.dump(), dir / "job.json", std::nullopt);
  EXPECT_DOUBLE_EQ(dressed.wheel.arc_radius_mm, 55.0);
  ASSERT_TRUE(dressed.wheel_change.has_value());
  EXPECT_EQ(dressed.wheel_change->nominal_arc_radius_mm, 55.3);
  EXPECT_EQ(dressed.wheel_change->measured_sigma_mm, 0.002);
  EXPECT_NEAR(dressed.wheel_change->DifferenceMm(), -0.3, 1e-12);
  EXPECT_EQ(dressed.arc_radius_error_source, "the measured radius's 1-sigma");
  // Beyond the limit it is another wheel: refused with both radii and the limit.
  EXPECT_THAT(ErrorMessageOf([&] { (void)ParseJob(job.dump(), dir / "job.json", std::nullopt, 0.25); }),
              AllOf(HasSubstr("key 'wheel.arc_radius_mm' = 55.3 mm (the nominal wheel)"),
                    HasSubstr("mean_arc_radius_mm = 55 mm"), HasSubstr("differ by -0.3000 mm"),
                    HasSubstr("--max-wheel-change-mm = 0.25 mm")));
  job["wheel"]["arc_radius_mm"] = 50.0;
  EXPECT_THAT(ExpectRefused(job, dir / "job.json"),
              HasSubstr("more than the limit --max-wheel-change-mm = 0.5 mm"));
  EXPECT_EQ(ErrorOf([&] { (void)ParseJob(job.dump(), dir / "job.json", std::nullopt, 0.0); }).code(),
            ErrorCode::kInvalidOption);
  job["wheel"].erase("arc_radius_mm");
  job["wheel"]["summary"] = "missing.json";
  EXPECT_EQ(ErrorOf([&] { (void)ParseJob(job.dump(), dir / "job.json", std::nullopt); }).code(),
            ErrorCode::kIo);
  // --wheel replaces the job's summary.
  EXPECT_NO_THROW((void)ParseJob(job.dump(), dir / "job.json", dir / "summary.json"));
}

TEST(ParseJob, TheWheelModelProfileNeedsAModelAndItsWheelMap) {
  const testing::TempDir dir;
  WriteText(dir / "summary.json", R"({"mean_arc_radius_mm": 55.0, "mean_arc_radius_sigma_mm": 0.002,
    "scan": {"wheel_diameter_mm": 400.0}})");
  json job = SmallJob();
  job["wheel"].erase("arc_radius_mm");
  job["wheel"]["summary"] = "summary.json";
  job["prediction"] = {{"runout_um", 0.0}};
  EXPECT_THAT(ErrorMessageOf([&] {
                (void)ParseJob(job.dump(), dir / "job.json", std::nullopt, kDefaultMaxWheelChangeMm,
                               WheelProfileSource::kModel);
              }),
              HasSubstr("has no wheel model (model.mean_arc_radius_mm), which --wheel-profile model needs"));
  // A model in the summary but no wheel_map.h5 beside it: refused naming the map.
  WriteText(dir / "summary.json", R"({"mean_arc_radius_mm": 55.0, "mean_arc_radius_sigma_mm": 0.002,
    "scan": {"wheel_diameter_mm": 400.0}, "model": {"mean_arc_radius_mm": 55.01,
    "mean_arc_radius_sigma_mm": 0.0001}})");
  EXPECT_EQ(ErrorOf([&] {
              (void)ParseJob(job.dump(), dir / "job.json", std::nullopt, kDefaultMaxWheelChangeMm,
                             WheelProfileSource::kModel);
            }).code(),
            ErrorCode::kIo);
}

struct CsvPoint {
  double v[12];
};

std::vector<CsvPoint> ReadCsv(const std::filesystem::path& path, std::vector<std::string>& comments) {
  std::ifstream in(path);
  std::string line;
  std::vector<CsvPoint> points;
  bool header_seen = false;
  while (std::getline(in, line)) {
    if (line.rfind("# ", 0) == 0) {
      comments.push_back(line);
      continue;
    }
    if (!header_seen) {
      EXPECT_EQ(line, "xw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min,row,pass");
      header_seen = true;
      continue;
    }
    CsvPoint p{};
    std::stringstream cells(line);
    std::string cell;
    for (double& value : p.v) {
      std::getline(cells, cell, ',');
      value = std::stod(cell);
    }
    points.push_back(p);
  }
  return points;
}

TEST(ToolpathCommand, WritesTheFilesAndTheCsvIsRightToTheNanometre) {
  const testing::TempDir dir;
  json job = SmallJob();
  job["path"]["passes"] = 2;
  job["path"]["depth_per_pass_um"] = 10.0;
  WriteText(dir / "job.json", job.dump());
  const testing::CommandResult run =
      testing::RunArcwheel("toolpath " + (dir / "job.json").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  for (const char* name :
       {"toolpath.csv", "toolpath.nc", "toolpath.pmc", "prediction.h5", "toolpath_summary.json"}) {
    EXPECT_TRUE(std::filesystem::exists(dir / "out" / name)) << name;
  }
  std::vector<std::string> comments;
  const std::vector<CsvPoint> points = ReadCsv(dir / "out/toolpath.csv", comments);
  ASSERT_GE(comments.size(), 4u);
  EXPECT_THAT(comments[0], HasSubstr(std::string("arcwheel ") + kVersion));
  EXPECT_THAT(comments[1], HasSubstr("surface: even asphere, concave, R0 = 800 mm"));
  EXPECT_THAT(comments[3], HasSubstr("wheel: wheel Ra = 50 mm, Rb = 150 mm"));
  std::ifstream summary_in(dir / "out/toolpath_summary.json");
  const json summary = json::parse(summary_in);
  ASSERT_EQ(points.size(), summary["toolpath"]["control_points"].get<size_t>());
  const double first_yw = summary["toolpath"]["first_row_yw_mm"], pitch = summary["toolpath"]["row_pitch_mm"];
  const EvenAsphere surface({.vertex_radius_mm = 800.0, .conic = -2.2, .off_axis_x_mm = 300.0});
  for (const CsvPoint& p : points) {
    const double* v = p.v;
    const int pass = static_cast<int>(v[11]);
    const double stock = (1 - pass) * 0.010;
    // The contact on the (stock-raised) surface, the torus through it, rows straight: all to 1 nm
    // from the numbers as written.
    EXPECT_NEAR(v[5] - stock, surface.Evaluate(v[3], v[4]).z_mm, 1e-9);
    const double rho = std::hypot(v[3] - v[0], v[5] - v[2]);
    EXPECT_NEAR(std::hypot(rho - 150.0, v[4] - v[1]), 50.0, 1e-9);
    EXPECT_NEAR(v[1], first_yw + v[10] * pitch, 1e-9);
    EXPECT_NEAR(std::hypot(v[6], std::hypot(v[7], v[8])), 1.0, 1e-12);
    EXPECT_EQ(v[9], 6000.0);
  }
  std::ifstream nc(dir / "out/toolpath.nc"), pmc(dir / "out/toolpath.pmc");
  const std::string gcode((std::istreambuf_iterator<char>(nc)), {}),
      pmac((std::istreambuf_iterator<char>(pmc)), {});
  EXPECT_THAT(gcode, HasSubstr("G90 G21\n"));
  EXPECT_THAT(gcode, HasSubstr(" F6000\n"));
  EXPECT_THAT(gcode, HasSubstr("(surface: even asphere"));
  EXPECT_THAT(pmac, HasSubstr("OPEN PROG 1 CLEAR\nABS\nLINEAR\n"));
  EXPECT_THAT(pmac, HasSubstr("\nF6000\n"));
  EXPECT_TRUE(pmac.size() > 6 && pmac.substr(pmac.size() - 6) == "CLOSE\n");
  EXPECT_GT(summary["prediction"]["pv_um"].get<double>(), 0.0);
}

TEST(ToolpathCommand, RefusesAWheelThatCannotReachTheCurvatureAndWritesNothing) {
  const testing::TempDir dir;
  json job = SmallJob();
  job["surface"] = {{"type", "even_asphere"}, {"vertex_radius_mm", 150.0}, {"conic", 0.0}};
  WriteText(dir / "job.json", job.dump());
  const testing::CommandResult run =
      testing::RunArcwheel("toolpath " + (dir / "job.json").string() + " -o " + (dir / "out").string());
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_THAT(run.output, HasSubstr("cannot reach the curvature at contact ("));
  // The run fails while the rows are written: the output folder it made goes too.
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ParseJob, RefusesSizesBeyondTheMemoryBudgetAndAStepOverWiderThanTheWheel) {
  json job = SmallJob();
  job["path"]["point_spacing_mm"] = 1e-6;
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("path.point_spacing_mm = 1e-06 violates the memory budget: it implies"));
  EXPECT_THAT(ExpectRefused(job), HasSubstr("control points held at once"));
  EXPECT_THAT(ExpectRefused(job), HasSubstr("over the 4 GiB (4294967296 B) of one run"));
  job = SmallJob();
  job["path"]["step_over_mm"] = 1e-9;
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("path.step_over_mm = 1e-09 violates the memory budget: it implies"));
  job = SmallJob();
  job["path"]["step_over_mm"] = 1e308;
  EXPECT_THAT(ExpectRefused(job), HasSubstr("path.step_over_mm = 1e+308 violates <= wheel.width_mm = 20"));
  job["path"]["step_over_mm"] = 20.0;  // the wheel's width: the widest step that leaves no band
  EXPECT_NO_THROW((void)ParseJob(job.dump(), "job.json", std::nullopt));
  job = SmallJob();
  job["prediction"]["map_nodes"] = {1e10, 1e10};
  EXPECT_THAT(ExpectRefused(job),
              HasSubstr("prediction.map_nodes = [10000000000, 10000000000] violates the memory "
                        "budget: it implies 1e+20 map nodes"));
}

TEST(ToolpathCommand, RefusesATinyStepUpFrontAndWritesNothing) {
  // A 1e-6 mm step used to end in std::bad_alloc and leave an empty output folder.
  const testing::TempDir dir;
  json job = SmallJob();
  job["path"]["point_spacing_mm"] = 1e-6;
  WriteText(dir / "job.json", job.dump());
  const testing::CommandResult run =
      testing::RunArcwheel("toolpath " + (dir / "job.json").string() + " -o " + (dir / "out").string());
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_THAT(run.output, HasSubstr("path.point_spacing_mm = 1e-06 violates the memory budget"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ToolpathCommand, RefusesAnUnknownKeyWithExitStatusThree) {
  const testing::TempDir dir;
  json job = SmallJob();
  job["machine"] = {{"pmac_prog", 2}};
  WriteText(dir / "job.json", job.dump());
  const testing::CommandResult run =
      testing::RunArcwheel("toolpath " + (dir / "job.json").string() + " -o " + (dir / "out").string());
  EXPECT_EQ(run.exit_status, 3);
  EXPECT_THAT(run.output, HasSubstr("unknown key 'machine.pmac_prog'"));
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ParseJob, ReadsFreeformAndGridSurfacesAndGrindsTheGrid) {
  json job = SmallJob();
  job["surface"] = json::parse(R"({"type": "xy_polynomial", "terms": [
      {"x_power": 2, "y_power": 0, "coefficient": 1e-3}, {"x_power": 1, "y_power": 1, "coefficient": 2e-4}]})");
  const Job poly = ParseJob(job.dump(), "job.json", std::nullopt);
  EXPECT_NEAR(poly.surface->Evaluate(3.0, -2.0).z_mm, 1e-3 * 9.0 + 2e-4 * -6.0, 1e-15);

  // z = 1e-3 x^2 + 5e-4 y^2 on a 5 mm grid: a spline reproduces it exactly.
  json rows = json::array();
  for (int j = 0; j < 25; ++j) {
    json row = json::array();
    for (int i = 0; i < 25; ++i) {
      const double x = -60.0 + 5.0 * i, y = -60.0 + 5.0 * j;
      row.push_back(1e-3 * x * x + 5e-4 * y * y);
    }
    rows.push_back(row);
  }
  job["surface"] = {{"type", "height_grid"}, {"x0_mm", -60.0}, {"y0_mm", -60.0},
                    {"dx_mm", 5.0},          {"dy_mm", 5.0},   {"heights_mm", rows}};
  job["aperture"] = {{"shape", "circle"}, {"diameter_mm", 40.0}};
  const Job grid = ParseJob(job.dump(), "job.json", std::nullopt);
  EXPECT_NEAR(grid.surface->Evaluate(7.3, -11.1).z_mm, 1e-3 * 7.3 * 7.3 + 5e-4 * 11.1 * 11.1, 1e-12);
  std::vector<ControlPoint> points;
  const ToolpathSummary summary =
      GenerateToolpath(*grid.surface, grid.aperture, grid.wheel, grid.path,
                       {.prepare = nullptr, .consume = [&points](ToolpathRow& r) {
                          points.insert(points.end(), r.points.begin(), r.points.end());
                        }});
  EXPECT_LT(summary.max_row_deviation_mm, 1e-9);
  for (const ControlPoint& p : points) {
    // Eq. 5 on the exact paraboloid, written out here.
    const double fx = 2e-3 * p.contact_mm.x(), fy = 1e-3 * p.contact_mm.y();
    const double n3 = std::sqrt(1 + fx * fx + fy * fy), n2 = std::sqrt(1 + fx * fx);
    EXPECT_NEAR(p.wheel_centre_mm.x(), p.contact_mm.x() - 50 * fx / n3 - 150 * fx / n2, 1e-9);
    EXPECT_NEAR(p.wheel_centre_mm.z(), p.contact_mm.z() + 50 / n3 + 150 / n2, 1e-9);
  }

  EXPECT_THAT(ApertureRefusal(job, 110.0), HasSubstr("lies outside the surface's domain"));
}

TEST(ToolpathCommand, MeasuredWheelProfileMovesTheControlPoints) {
  const testing::TempDir dir;
  WriteText(dir / "summary.json", R"({
    "mean_arc_radius_mm": 50.0, "mean_arc_radius_sigma_mm": 0.001, "max_runout_um": 0.0,
    "scan": {"wheel_diameter_mm": 400.0, "wheel_id": "W7"},
    "mean_profile": {"u_mm": [-10.0, 0.0, 10.0], "error_um": [4.0, 0.0, 2.0]}
  })");
  json job = SmallJob();
  job["wheel"].erase("arc_radius_mm");
  job["wheel"].erase("total_radius_mm");
  job["outputs"] = {{"gcode", false}, {"pmac", false}};
  WriteText(dir / "job.json", job.dump());
  const testing::CommandResult run =
      testing::RunArcwheel("toolpath " + (dir / "job.json").string() + " --wheel " +
                           (dir / "summary.json").string() + " -o " + (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(testing::ListFolder(dir / "out"), "prediction.h5\ntoolpath.csv\ntoolpath_summary.json\n");
  std::vector<std::string> comments;
  const std::vector<CsvPoint> points = ReadCsv(dir / "out/toolpath.csv", comments);
  EXPECT_THAT(comments[3], HasSubstr("measured wheel 'summary.json' (W7): Ra = 50"));
  ASSERT_FALSE(points.empty());
  for (const CsvPoint& p : points) {
    const double* v = p.v;
    // Arc radius at the contact's axial offset u = Ra fy / N3 = -50 ny, by the profile.
    const double u = -50.0 * v[7];
    const double error_um = u < 0 ? 4.0 * (-u / 10.0) : 2.0 * (u / 10.0);
    const double ra = 50.0 + 1e-3 * error_um;
    const double n2 = std::hypot(v[6], v[8]);
    EXPECT_NEAR(v[0], v[3] + ra * v[6] + 150.0 * v[6] / n2, 1e-9);
    EXPECT_NEAR(v[1], v[4] + ra * v[7], 1e-9);
    EXPECT_NEAR(v[2], v[5] + ra * v[8] + 150.0 * v[8] / n2, 1e-9);
  }
}

TEST(ToolpathCommand, RunsTheShippedTrialPart) {
  const testing::TempDir dir;
  const testing::CommandResult run = testing::RunArcwheel(
      "toolpath " + (testing::SourceDir() / "grinding/examples/trial_part.json").string() + " -o " +
      (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  std::ifstream in(dir / "out/toolpath_summary.json");
  const json summary = json::parse(in);
  EXPECT_LT(summary["toolpath"]["max_row_deviation_mm"].get<double>(), 1e-9);
  EXPECT_GT(summary["toolpath"]["min_gouge_gap_um"].get<double>(), -1e-3);
  // 2 um runout (TIR) with 4.19 mm per turn on a 200 mm wheel: a ripple close to 2 um.
  EXPECT_NEAR(summary["prediction"]["ripple_pv_um"].get<double>(), 2.0, 0.2);
}

}  // namespace
}  // namespace arcwheel::grinding
