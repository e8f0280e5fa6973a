// `arcwheel regenerate` end to end: a simulated scan of a dressed wheel whose arc radius is a known
// amount off the shipped trial part's nominal one, the trial part's job, a polishing job; and
// the grid map that joins grinding's prediction to polishing.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/hdf5.h"
#include "core/testing/json_file.h"
#include "core/testing/testing.h"
#include "grinding/prediction.h"
#include "polishing/error_map_io.h"
#include "polishing/job.h"
#include "store/store.h"
#include "surfaces/surface.h"
#include "tests/trial_jobs.h"

namespace arcwheel {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;
using ::testing::HasSubstr;
using testing::ReadText;
using testing::RunArcwheel;
using testing::SmallTrialPart;
using testing::TempDir;
using testing::TrialPolishJob;
using testing::WriteText;

using testing::ReadJson;

// The shipped trial part (method.md A.9) and its nominal wheel.
const fs::path kTrialPart = testing::SourceDir() / "grinding/examples/trial_part.json";
constexpr double kNominalArcRadiusMm = 55.4423;
// The dressed wheel of the simulated scan: 0.1 mm larger than nominal.
constexpr double kDressedArcRadiusMm = 55.5423;

// Height of the trial part (even asphere, R0 4066.172723 mm, k -0.581986, 300 / 300 mm off axis,
// concave), written out here from method.md A.9 rather than taken from surfaces/.
double TrialSagMm(double x_mm, double y_mm) {
  const double c = 1.0 / 4066.172723, k = -0.581986;
  const auto sag = [&](double r) { return c * r * r / (1.0 + std::sqrt(1.0 - (1.0 + k) * c * c * r * r)); };
  return sag(std::hypot(x_mm + 300.0, y_mm + 300.0)) - sag(std::hypot(300.0, 300.0));
}

// The fig. 7 relation (method.md A.8): a path computed for arc radius Ra but ground with Ra + dRa
// (total radius kept) leaves a height error dRa (N2 - N3), N2 = sqrt(1 + fx^2),
// N3 = sqrt(1 + fx^2 + fy^2): first order in dRa, from eq. 5's offsets.
double Fig7ErrorUm(double d_ra_mm, double x_mm, double y_mm) {
  const double h = 1e-3;
  const double fx = (TrialSagMm(x_mm + h, y_mm) - TrialSagMm(x_mm - h, y_mm)) / (2 * h);
  const double fy = (TrialSagMm(x_mm, y_mm + h) - TrialSagMm(x_mm, y_mm - h)) / (2 * h);
  return 1e3 * d_ra_mm * (std::sqrt(1 + fx * fx) - std::sqrt(1 + fx * fx + fy * fy));
}

struct GridValues {
  double x0, y0, dx, dy;
  int nx, ny;
  std::vector<double> values;
};

GridValues ReadGrid(const fs::path& path, const std::string& dataset = "/error_um") {
  const hdf5::File file = hdf5::File::OpenReadOnly(path);
  const std::vector<hsize_t> shape = file.Shape(dataset);
  return {*file.ReadAttributeDouble("/", "x0_mm"),
          *file.ReadAttributeDouble("/", "y0_mm"),
          *file.ReadAttributeDouble("/", "dx_mm"),
          *file.ReadAttributeDouble("/", "dy_mm"),
          static_cast<int>(shape[1]),
          static_cast<int>(shape[0]),
          file.ReadDoubles(dataset)};
}

// One regeneration shared by the tests: simulate, then regenerate with a polishing job.
class Regenerate : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    const TempDir& dir = *dir_;
    const auto sim = RunArcwheel(Format("simulate {} --arc-radius-mm {} --noise-um 0.3 --seed 7",
                                        dir / "scan.h5", kDressedArcRadiusMm));
    ASSERT_EQ(sim.exit_status, 0) << sim.output;
    WriteText(dir / "part.json", SmallTrialPart().dump(2));
    WriteText(dir / "polish.json", TrialPolishJob().dump(2));
    run_ = RunArcwheel(Command(dir / "first", "polish.json", "--db " + (dir / "runs.sqlite").string()));
  }
  static void TearDownTestSuite() { dir_.reset(); }

  static std::string Format(const std::string& pattern, const fs::path& path, double value) {
    std::string text = pattern;
    text.replace(text.find("{}"), 2, path.string());
    std::ostringstream number;
    number.precision(17);
    number << value;
    return text.replace(text.find("{}"), 2, number.str());
  }
  static std::string Command(const fs::path& outdir, const std::string& polish = "polish.json",
                             const std::string& extra = "") {
    const TempDir& dir = *dir_;
    return "regenerate --scan " + (dir / "scan.h5").string() + " --job " + (dir / "part.json").string() +
           " --polish " + (dir / polish).string() + " --polish-map nominal-path -o " + outdir.string() + " " +
           extra;
  }
  static std::unique_ptr<TempDir> dir_;
  static testing::CommandResult run_;
};
std::unique_ptr<TempDir> Regenerate::dir_;
testing::CommandResult Regenerate::run_;

TEST_F(Regenerate, WritesEachStepsFilesAndOneReport) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path out = *dir_ / "first";
  EXPECT_EQ(testing::ListFolder(out / "wheel"), "step_inputs.json\nsummary.json\nwheel_map.h5\n");
  EXPECT_EQ(testing::ListFolder(out / "toolpath"),
            "nominal_path_prediction.h5\nprediction.h5\nstep_inputs.json\ntoolpath.csv\ntoolpath.nc\n"
            "toolpath.pmc\ntoolpath_summary.json\n");
  EXPECT_EQ(testing::ListFolder(out / "polish"),
            "polish.mod\npolish_summary.json\npolishing_path.csv\nresidual_map.csv\nresidual_map.h5\n"
            "step_inputs.json\n");
  const std::string html = ReadText(out / "regenerate_report.html");
  for (const char* step : {"Wheel verdict", "Toolpath summary", "Predicted form error", "Polishing plan"})
    EXPECT_THAT(html, HasSubstr(step));
  EXPECT_GT(fs::file_size(out / "regenerate_report.pdf"), 1000u);
  EXPECT_THAT(testing::PdfText(out / "regenerate_report.pdf"), HasSubstr("Polishing plan"));
}

// Each step is recorded in the store as its own summary tells it: the command, run by
// `regenerate`, the step's folder, the version that wrote it and the options it ran with.
TEST_F(Regenerate, RecordsEachStepInTheStoreAsItsSummaryTellsIt) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path out = *dir_ / "first";
  store::Store db = store::Store::Open((*dir_ / "runs.sqlite").string());
  const std::vector<store::StoredRun> runs = db.Runs();
  ASSERT_EQ(runs.size(), 3u);
  struct Step {
    std::string command, folder, summary, options_key;
  };
  for (const Step& step : {Step{"process", "wheel", "summary.json", "processing"},
                           Step{"toolpath", "toolpath", "toolpath_summary.json", "job"},
                           Step{"polish", "polish", "polish_summary.json", "job"}}) {
    SCOPED_TRACE(step.command);
    const auto run = std::find_if(runs.begin(), runs.end(),
                                  [&](const store::StoredRun& r) { return r.command == step.command; });
    ASSERT_NE(run, runs.end());
    const nlohmann::json summary = nlohmann::json::parse(ReadText(out / step.folder / step.summary));
    EXPECT_EQ(run->via, "regenerate");
    EXPECT_EQ(fs::weakly_canonical(run->output_folder), fs::weakly_canonical(out / step.folder));
    EXPECT_EQ(run->arcwheel_version, summary.at("arcwheel_version").get<std::string>());
    EXPECT_EQ(nlohmann::json::parse(run->options), summary.at(step.options_key));
  }
}

// The toolpath's own geometry: eq. 5 gives Yw = Y + Ra ny (n the upward unit normal), so every
// control point of toolpath.csv states the arc radius it was computed with.
TEST_F(Regenerate, TheToolpathUsesTheMeasuredRadius) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path out = *dir_ / "first";
  const json summary = ReadJson(out / "wheel" / "summary.json");
  const double measured = summary["mean_arc_radius_mm"];
  const double sigma = summary["mean_arc_radius_sigma_mm"];
  EXPECT_NEAR(measured, kDressedArcRadiusMm, 5 * sigma + 1e-4);
  const json toolpath = ReadJson(out / "toolpath" / "toolpath_summary.json");
  EXPECT_EQ(toolpath["arc_radius"]["measured_mm"], measured);
  EXPECT_EQ(toolpath["arc_radius"]["nominal_mm"], kNominalArcRadiusMm);
  EXPECT_DOUBLE_EQ(toolpath["arc_radius"]["difference_mm"].get<double>(), measured - kNominalArcRadiusMm);
  EXPECT_EQ(toolpath["arc_radius"]["measured_sigma_mm"], sigma);

  std::ifstream csv(out / "toolpath" / "toolpath.csv");
  std::string line;
  int checked = 0;
  bool header_named_nominal = false;
  while (std::getline(csv, line)) {
    if (line.rfind("# arc radius: measured", 0) == 0)
      header_named_nominal = line.find("nominal 55.4423 mm") != std::string::npos;
    if (line.empty() || line[0] == '#' || line[0] == 'x') continue;
    std::vector<double> v;
    std::stringstream fields(line);
    for (std::string field; std::getline(fields, field, ',');) v.push_back(std::stod(field));
    const double yw = v[1], y = v[4], ny = v[7];
    if (std::abs(ny) < 0.05) continue;  // Ra from a tiny slope is ill-conditioned
    // The measured profile error (noise of a wheel without one) moves the contact's Ra by < 1 um.
    EXPECT_NEAR((yw - y) / ny, measured, 2e-3) << line;
    ++checked;
  }
  EXPECT_TRUE(header_named_nominal);
  EXPECT_GT(checked, 100);
}

TEST_F(Regenerate, PredictsTheFig7ErrorOfTheRadiusDifference) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path out = *dir_ / "first";
  const double measured = ReadJson(out / "wheel" / "summary.json")["mean_arc_radius_mm"];
  const double d_ra = measured - kNominalArcRadiusMm;
  const GridValues nominal = ReadGrid(out / "toolpath" / "nominal_path_prediction.h5");
  double largest = 0.0, worst = 0.0;
  for (int j = 0; j < nominal.ny; ++j) {
    for (int i = 0; i < nominal.nx; ++i) {
      const double want = Fig7ErrorUm(d_ra, nominal.x0 + i * nominal.dx, nominal.y0 + j * nominal.dy);
      const double got = nominal.values[static_cast<size_t>(j * nominal.nx + i)];
      largest = std::max(largest, std::abs(want));
      worst = std::max(worst, std::abs(got - want));
    }
  }
  EXPECT_GT(largest, 0.5);  // 0.1 mm on slopes up to 0.13: about 0.8 um
  EXPECT_LT(worst, 1e-3);   // second-order terms only (2e-5 um seen)
  // The regenerated path uses the measured radius: its arc-radius part is that of the radius's
  // 1-sigma, no longer that of the 0.1 mm difference.
  const GridValues regenerated = ReadGrid(out / "toolpath" / "prediction.h5", "/low_order_um");
  const double sigma = ReadJson(out / "wheel" / "summary.json")["mean_arc_radius_sigma_mm"];
  for (const double v : regenerated.values)
    EXPECT_LE(std::abs(v), largest * sigma / std::abs(d_ra) * 1.05 + 1e-9);
}

TEST_F(Regenerate, ThePolishingProgramRemovesThePredictedErrorTenfold) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const json polish = ReadJson(*dir_ / "first" / "polish" / "polish_summary.json");
  const double before_rms = polish["before"]["rms_um"], after_rms = polish["after"]["rms_um"];
  const double before_pv = polish["before"]["pv_um"], after_pv = polish["after"]["pv_um"];
  EXPECT_GT(before_rms, 0.1);
  EXPECT_LE(10.0 * after_rms, before_rms) << polish.dump(2);
  EXPECT_LE(10.0 * after_pv, before_pv) << polish.dump(2);
  // The map polished is the chain's prediction, by its path.
  EXPECT_THAT(polish["job"]["error_map"]["file"].get<std::string>(), HasSubstr("nominal_path_prediction.h5"));
}

TEST_F(Regenerate, RedoesNothingWhoseInputsAreUnchangedAndComparesWithThePrevious) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path first = *dir_ / "first", second = *dir_ / "second";
  fs::copy(first, second, fs::copy_options::recursive);
  const auto mtime = fs::last_write_time(second / "toolpath" / "toolpath.csv");
  const auto run = RunArcwheel(Command(second));
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("step 1/4 wheel: inputs unchanged"));
  EXPECT_THAT(run.output, HasSubstr("step 2/4 toolpath: inputs unchanged"));
  EXPECT_THAT(run.output, HasSubstr("step 3/4 polish: inputs unchanged"));
  EXPECT_EQ(fs::last_write_time(second / "toolpath" / "toolpath.csv"), mtime);
  // `first` lies beside it: found as the previous regeneration, nothing changed since.
  const std::string html = ReadText(second / "regenerate_report.html");
  EXPECT_THAT(html, HasSubstr(first.string()));
  // No change: a change that rounds to zero is "+0.00000" (core/number_format.h, ShowSigned).
  EXPECT_THAT(html, HasSubstr("<td class=\"number\">+0.00000 mm</td>"));
  EXPECT_EQ(ReadJson(second / "regenerate.json")["previous"], first.string());
  // A --previous that is no regeneration is refused before any step runs.
  const auto refused = RunArcwheel(
      Command(*dir_ / "third", "polish.json", "--previous " + (*dir_ / "first" / "wheel").string()));
  EXPECT_EQ(refused.exit_status, 2) << refused.output;
  EXPECT_THAT(refused.output, HasSubstr("holds no regenerate.json"));
  EXPECT_FALSE(fs::exists(*dir_ / "third"));
}

TEST_F(Regenerate, AFailedPolishStepLeavesTheWheelAndToolpathAndNamesTheStep) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path first = *dir_ / "first", failed = *dir_ / "failed";
  fs::copy(first, failed, fs::copy_options::recursive);
  json bad = TrialPolishJob();
  bad["machine"]["max_sped_mm_s"] = 1.0;
  WriteText(*dir_ / "bad_polish.json", bad.dump(2));
  const std::string toolpath_before = ReadText(failed / "toolpath" / "toolpath.csv");
  const auto run = RunArcwheel(Command(failed, "bad_polish.json"));
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_THAT(run.output, HasSubstr("step 3/4 'polish' failed"));
  EXPECT_THAT(run.output, HasSubstr("machine.max_sped_mm_s"));
  EXPECT_EQ(testing::ListFolder(failed / "wheel"), "step_inputs.json\nsummary.json\nwheel_map.h5\n");
  EXPECT_EQ(ReadText(failed / "toolpath" / "toolpath.csv"), toolpath_before);
  EXPECT_FALSE(fs::exists(failed / "polish"));
  EXPECT_FALSE(fs::exists(failed / "regenerate_report.html"));
  EXPECT_FALSE(fs::exists(failed / "regenerate.json"));
}

// The shipped job names its nominal wheel; --wheel replaces it within the limit and is refused
// beyond it, naming both radii and the limit.
TEST_F(Regenerate, TheShippedTrialPartTakesTheMeasuredWheelWithinTheLimit) {
  ASSERT_EQ(run_.exit_status, 0) << run_.output;
  const fs::path summary = *dir_ / "first" / "wheel" / "summary.json";
  const auto refused = RunArcwheel("toolpath " + kTrialPart.string() + " --wheel " + summary.string() +
                                   " --max-wheel-change-mm 0.05 -o " + (*dir_ / "refused").string());
  EXPECT_EQ(refused.exit_status, 3) << refused.output;
  EXPECT_THAT(refused.output, HasSubstr("= 55.4423 mm (the nominal wheel)"));
  EXPECT_THAT(refused.output, HasSubstr("--max-wheel-change-mm = 0.05 mm"));
  EXPECT_FALSE(fs::exists(*dir_ / "refused"));
  // Within the default limit the shipped file runs as it is.
  const auto run = RunArcwheel("toolpath " + kTrialPart.string() + " --wheel " + summary.string() + " -o " +
                               (*dir_ / "trial").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_THAT(run.output, HasSubstr("arc radius: measured"));
  EXPECT_THAT(run.output, HasSubstr("nominal 55.4423 mm (job)"));
  EXPECT_THAT(run.output, HasSubstr("the measured radius's 1-sigma"));
  // Rounded: the sigma at full precision (as summary.json holds it) is not printed.
  const json sigma = ReadJson(summary)["mean_arc_radius_sigma_mm"];
  ASSERT_GT(sigma.dump().size(), 8u);
  EXPECT_THAT(run.output, ::testing::Not(HasSubstr(sigma.dump())));
}

// ------------------------------------------------------------------------------------------------
// --wheel-profile model: the wheel model's radius and profile error p(u).

// Linear interpolation of a profile, its end values beyond it (as a table would be read).
double Interpolate(const std::vector<double>& u, const std::vector<double>& v, double at) {
  if (at <= u.front()) return v.front();
  if (at >= u.back()) return v.back();
  size_t k = 1;
  while (u[k] < at) ++k;
  return v[k - 1] + (at - u[k - 1]) / (u[k] - u[k - 1]) * (v[k] - v[k - 1]);
}

// A wheel with a known profile error (Legendre P3 and P4, which the model's p(u) keeps: it has
// no mean, slope or curvature at the arc centre to trade with Ra, a, b). A pure-arc path ground
// with it prints p at each contact, u = Ra fy / N3 from the arc centre, as a height error
// -p(u) N3; a path that follows p(u) prints none. The two predictions differ by exactly that.
TEST(WheelProfileModel, ThePredictionOfAPureArcPathCarriesTheModelsProfileErrorMappedThroughEq5) {
  const TempDir dir;
  ASSERT_EQ(RunArcwheel("simulate " + (dir / "scan.h5").string() +
                        " --profile-legendre-um 0,0,0,1.5,1 --noise-um 0.1 --seed 3")
                .exit_status,
            0);
  const auto process =
      RunArcwheel("process " + (dir / "scan.h5").string() + " -q -o " + (dir / "wheel").string());
  ASSERT_EQ(process.exit_status, 0) << process.output;
  json job = SmallTrialPart();
  job["wheel"].erase("arc_radius_mm");  // no nominal: only the profile differs between the runs
  job["prediction"]["runout_um"] = 0.0;
  WriteText(dir / "follow.json", job.dump(2));
  job["wheel"]["use_profile"] = false;
  WriteText(dir / "arc.json", job.dump(2));
  const std::string wheel =
      " --wheel " + (dir / "wheel" / "summary.json").string() + " --wheel-profile model -o ";
  for (const char* name : {"follow", "arc"}) {
    const auto run = RunArcwheel("toolpath " + (dir / (std::string(name) + ".json")).string() + wheel +
                                 (dir / name).string());
    ASSERT_EQ(run.exit_status, 0) << run.output;
  }
  const json summary = ReadJson(dir / "wheel" / "summary.json");
  const double ra = summary["model"]["mean_arc_radius_mm"];
  const json follow = ReadJson(dir / "follow" / "toolpath_summary.json");
  EXPECT_EQ(follow["wheel_profile"], "model");
  EXPECT_EQ(follow["job"]["wheel"]["arc_radius_mm"], ra);
  EXPECT_THAT(follow["wheel"].get<std::string>(), HasSubstr("wheel model"));
  EXPECT_THAT(ReadText(dir / "arc" / "toolpath.csv"), HasSubstr("a pure arc (p(u) left to the prediction)"));

  const hdf5::File map = hdf5::File::OpenReadOnly(dir / "wheel" / "wheel_map.h5");
  std::vector<double> u, p;
  const std::vector<double> u_all = map.ReadDoubles("/model/profile_u_mm");
  const std::vector<double> p_all = map.ReadDoubles("/model/profile_error_um");
  for (size_t k = 0; k < u_all.size(); ++k) {
    if (std::isfinite(u_all[k]) && std::isfinite(p_all[k])) u.push_back(u_all[k]), p.push_back(p_all[k]);
  }
  ASSERT_GE(u.size(), 2u);
  const GridValues a = ReadGrid(dir / "arc" / "prediction.h5");
  const GridValues f = ReadGrid(dir / "follow" / "prediction.h5");
  double largest = 0.0;
  for (int j = 0; j < a.ny; ++j) {
    for (int i = 0; i < a.nx; ++i) {
      const double x = a.x0 + i * a.dx, y = a.y0 + j * a.dy, h = 1e-3;
      const double fx = (TrialSagMm(x + h, y) - TrialSagMm(x - h, y)) / (2 * h);
      const double fy = (TrialSagMm(x, y + h) - TrialSagMm(x, y - h)) / (2 * h);
      const double n3 = std::sqrt(1 + fx * fx + fy * fy);
      const double want = -Interpolate(u, p, ra * fy / n3) * n3;
      const size_t k = static_cast<size_t>(j * a.nx + i);
      EXPECT_NEAR(a.values[k] - f.values[k], want, 1e-6) << x << ", " << y;
      largest = std::max(largest, std::abs(want));
    }
  }
  EXPECT_GT(largest, 0.3);  // P3 and P4 sampled by the contacts u = 1 .. 7 mm: 0.47 um seen
}

// ------------------------------------------------------------------------------------------------
// The grid map between grinding and polishing.

TEST(GridMap, APolishJobReadsAPredictionDirectly) {
  const TempDir dir;
  const surfaces::EvenAsphere surface({.vertex_radius_mm = 800.0, .conic = -2.2});
  const surfaces::Aperture aperture{.width_x_mm = 60.0, .width_y_mm = 40.0};
  grinding::Wheel wheel{.arc_radius_mm = 50.0, .base_radius_mm = 150.0, .half_width_mm = 10.0};
  const grinding::FormPrediction p = grinding::PredictFormError(
      surface, aperture, wheel, {.arc_radius_error_mm = 0.2, .nodes_x = 13, .nodes_y = 9});
  grinding::WritePredictionHdf5(p, dir / "prediction.h5", surface.Describe(), "wheel");
  WriteText(dir / "polish.json", R"({
    "surface": {"type": "even_asphere", "vertex_radius_mm": 800.0, "conic": -2.2},
    "aperture": {"size_mm": [60.0, 40.0]},
    "error_map": {"file": "prediction.h5"},
    "removal_function": {"peak_rate_um_per_s": 1.0, "fwhm_mm": 10.0},
    "machine": {"max_speed_mm_s": 100.0}
  })");
  const polishing::PolishJob job = polishing::ReadPolishJob(dir / "polish.json");
  ASSERT_EQ(job.error_map.grid.nx, 13);
  ASSERT_EQ(job.error_map.grid.ny, 9);
  for (int j = 0; j < 9; ++j) {
    for (int i = 0; i < 13; ++i) {
      EXPECT_NEAR(job.error_map.grid.X(i), p.x_mm[static_cast<size_t>(i)], 1e-12);
      EXPECT_NEAR(job.error_map.grid.Y(j), p.y_mm[static_cast<size_t>(j)], 1e-12);
      const double want = p.error_um[static_cast<size_t>(j * 13 + i)];
      const double got = job.error_map.At(i, j);
      if (std::isnan(want)) {
        EXPECT_TRUE(std::isnan(got));
      } else {
        EXPECT_EQ(got, want);
      }
    }
  }
}

TEST(GridMap, ReadsTheLayoutsOfBeforeAndAMapH5pyWrote) {
  const TempDir dir;
  // h5py, as another tool would write a grid map.
  const std::string command = "/usr/bin/python3 " +
                              (testing::SourceDir() / "tests/foreign/write_grid_map.py").string() + " " +
                              dir.path().string() + " > " + (dir / "writer.log").string() + " 2>&1";
  ASSERT_EQ(testing::Shell(command), 0) << ReadText(dir / "writer.log");
  const json expected = ReadJson(dir / "expected.json");
  const polishing::ErrorMap map = polishing::ReadErrorMapHdf5(dir / "grid_map.h5");
  ASSERT_EQ(map.grid.nx, expected["nx"]);
  ASSERT_EQ(map.grid.ny, expected["ny"]);
  for (int j = 0; j < map.grid.ny; ++j) {
    for (int i = 0; i < map.grid.nx; ++i) {
      const json& node = expected["nodes"][static_cast<size_t>(j * map.grid.nx + i)];
      EXPECT_DOUBLE_EQ(map.grid.X(i), node["x_mm"].get<double>());
      EXPECT_DOUBLE_EQ(map.grid.Y(j), node["y_mm"].get<double>());
      if (node["error_um"].is_null()) {
        EXPECT_TRUE(std::isnan(map.At(i, j)));
      } else {
        EXPECT_EQ(map.At(i, j), node["error_um"].get<double>());
      }
    }
  }
  // The prediction layout written before the grid map, /prediction/...
  {
    hdf5::File file = hdf5::File::Create(dir / "old_prediction.h5");
    file.CreateGroup("/prediction");
    file.WriteDoubles("/prediction/x_mm", {-1.0, 0.0, 1.0}, {3});
    file.WriteDoubles("/prediction/y_mm", {-2.0, 2.0}, {2});
    file.WriteDoubles("/prediction/error_um", {1, 2, 3, 4, 5, 6}, {2, 3});
  }
  const polishing::ErrorMap old = polishing::ReadErrorMapHdf5(dir / "old_prediction.h5");
  EXPECT_EQ(old.grid.nx, 3);
  EXPECT_DOUBLE_EQ(old.grid.dy_mm, 4.0);
  EXPECT_EQ(old.At(2, 1), 6.0);
}

}  // namespace
}  // namespace arcwheel
