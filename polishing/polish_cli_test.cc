// End-to-end tests of `arcwheel polish JOB -o OUTDIR`.
#include <fmt/core.h>
#include <gtest/gtest.h>
#include <hdf5.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <vector>

#include "core/testing/testing.h"

namespace arcwheel::polishing {
namespace {

using arcwheel::testing::RunArcwheel;
using arcwheel::testing::TempDir;
using arcwheel::testing::WriteText;

// Astigmatism plus a bump on a 1 mm grid over 64 x 64 mm, in micrometres.
void WriteMap(const std::filesystem::path& path, double x_offset_mm = 0.0) {
  std::ofstream out(path);
  out << "# simulated error map\nx_mm,y_mm,error_um\n";
  for (int j = -32; j <= 32; ++j) {
    for (int i = -32; i <= 32; ++i) {
      const double x = i + x_offset_mm, y = j;
      out << fmt::format(
          "{},{},{}\n", x, y,
          0.3 * (x * x - y * y) / 900.0 + 0.4 * std::exp(-((x - 8) * (x - 8) + y * y) / 150.0));
    }
  }
}

std::string Job(const std::string& extra_machine = "", const std::string& extra_root = "",
                double vertex_radius_mm = 400.0) {
  return fmt::format(R"({{
  "name": "cli test",
  "surface": {{"type": "even_asphere", "vertex_radius_mm": {}, "conic": -0.5, "form": "convex"}},
  "aperture": {{"shape": "circle", "diameter_mm": 60.0}},
  "error_map": {{"file": "map.csv"}},
  "removal_target": {{"uniform_layer_um": 1.0}},
  "removal_function": {{"peak_rate_um_per_s": 1.5, "fwhm_mm": 10.0}},
  "path": {{"line_spacing_mm": 2.0, "point_spacing_mm": 2.0, "extension_mm": 6.0}},
  "machine": {{"max_speed_mm_s": 150.0, "min_speed_mm_s": 0.5{}}},
  "solver": {{"max_iterations": 800}},
  "tool": {{"tcp_mm": [0, 0, 180], "removal_centre_offset_mm": [0.25, -0.1]}}{}
}})",
                     vertex_radius_mm, extra_machine, extra_root);
}

// Runs `arcwheel polish` on dir/job.json into dir/out.
arcwheel::testing::CommandResult PolishJobIn(const TempDir& dir) {
  return RunArcwheel(fmt::format("polish {} -o {}", (dir / "job.json").string(), (dir / "out").string()));
}

TEST(PolishCommand, WritesPathRapidResidualAndSummaryWithATenfoldRmsDrop) {
  TempDir dir;
  WriteMap(dir / "map.csv");
  WriteText(dir / "job.json", Job());
  const auto result = PolishJobIn(dir);
  ASSERT_EQ(result.exit_status, 0) << result.output;
  std::ifstream summary_file(dir / "out" / "polish_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_LT(summary["after"]["rms_um"].get<double>(), summary["before"]["rms_um"].get<double>() / 10.0)
      << summary.dump(2);
  EXPECT_EQ(summary["schema_version"], "1.0");
  EXPECT_LE(summary["speed_mm_s"]["max"].get<double>(), 150.0 * (1 + 1e-12));
  EXPECT_GE(summary["speed_mm_s"]["min"].get<double>(), 0.5 * (1 - 1e-12));
  std::ifstream csv(dir / "out" / "polishing_path.csv");
  std::string line;
  while (std::getline(csv, line) && line.rfind("# ", 0) == 0) {
  }
  EXPECT_EQ(line, "x,y,z,q1,q2,q3,q4,speed_mm_s,dwell_s");
  std::stringstream rapid;
  rapid << std::ifstream(dir / "out" / "polish.mod").rdbuf();
  EXPECT_NE(rapid.str().find("PERS tooldata tPolish := [TRUE,[[0.2500,-0.1000,180.0000]"), std::string::npos);
  EXPECT_TRUE(std::filesystem::exists(dir / "out" / "residual_map.csv"));
}

TEST(PolishCommand, RunsTheShippedExampleJob) {
  TempDir dir;
  const auto job = arcwheel::testing::SourceDir() / "polishing" / "examples" / "disc_job.json";
  const auto result = RunArcwheel(fmt::format("polish {} -o {}", job.string(), (dir / "out").string()));
  ASSERT_EQ(result.exit_status, 0) << result.output;
  std::ifstream summary_file(dir / "out" / "polish_summary.json");
  const nlohmann::json summary = nlohmann::json::parse(summary_file);
  EXPECT_LT(summary["after"]["rms_um"].get<double>(), summary["before"]["rms_um"].get<double>() / 10.0);
}

// The first `columns` numbers of each data row of dir/out/polishing_path.csv (after its comment
// lines and its header); a test failure for a row that has fewer.
std::vector<std::vector<double>> PathRows(const TempDir& dir, std::size_t columns) {
  std::ifstream csv(dir / "out" / "polishing_path.csv");
  std::string line;
  while (std::getline(csv, line) && line.rfind("# ", 0) == 0) {
  }
  std::vector<std::vector<double>> rows;
  while (std::getline(csv, line)) {
    std::vector<double> row;
    for (const char* at = line.c_str(); row.size() < columns;) {
      char* end = nullptr;
      row.push_back(std::strtod(at, &end));
      if (end == at) break;
      at = *end == ',' ? end + 1 : end;
    }
    if (row.size() != columns || !std::isfinite(row.back())) {
      ADD_FAILURE() << "path row '" << line << "'";
      continue;
    }
    rows.push_back(std::move(row));
  }
  return rows;
}

// Checks that `arcwheel polish` refuses `job` as bad input with `message` and writes nothing.
void ExpectRefused(const std::string& job, const std::string& message, bool shifted_map = false) {
  TempDir dir;
  WriteMap(dir / "map.csv", shifted_map ? 1000.0 : 0.0);
  WriteText(dir / "job.json", job);
  const auto result = PolishJobIn(dir);
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_NE(result.output.find(message), std::string::npos) << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out")) << "a refused run leaves no output folder";
}

std::string WithSurface(const std::string& surface) {
  std::string job = Job();
  const std::size_t begin = job.find("\"surface\"");
  const std::size_t end = job.find('\n', begin);
  return job.replace(begin, end - begin, "\"surface\": " + surface + ",");
}

TEST(PolishCommand, ReadsFreeformAndAsphereSurfacesInTheGrindingJobsForm) {
  TempDir dir;
  WriteMap(dir / "map.csv");
  WriteText(dir / "job.json", WithSurface(R"({"type": "xy_polynomial", "terms": [
      {"x_power": 2, "coefficient": -0.001}, {"y_power": 2, "coefficient": -0.0012}]})"));
  const auto result = PolishJobIn(dir);
  ASSERT_EQ(result.exit_status, 0) << result.output;
  // z = -0.001 x^2 - 0.0012 y^2: the CSV's z follows the freeform.
  const auto rows = PathRows(dir, 3);
  for (const std::vector<double>& row : rows) {
    const double x = row[0], y = row[1], z = row[2];
    EXPECT_NEAR(z, -0.001 * x * x - 0.0012 * y * y, 1e-12);
  }
  EXPECT_GT(rows.size(), 500U);
}

TEST(PolishCommand, RefusesAPowerThatIsNotAWholeNumberInRangeNamingItsValue) {
  // 2.5 was computed as 2 while 2.5 went into the summary; 3e110 was cast to int (undefined).
  for (const std::string power : {"2.5", "3e110", "-1"}) {
    ExpectRefused(WithSurface(R"({"type": "xy_polynomial", "terms": [
        {"x_power": 2, "coefficient": -0.001}, {"y_power": )" +
                              power + R"(, "coefficient": -0.0012}]})"),
                  "terms[1].y_power' expected a whole number within 0 .. 20, got");
  }
}

TEST(PolishCommand, RefusesAnIterationCountThatIsNotAWholeNumberInRange) {
  for (const std::string count : {"800.5", "3e10", "0"}) {
    std::string job = Job();
    const std::string given = R"("max_iterations": 800)";
    job.replace(job.find(given), given.size(), R"("max_iterations": )" + count);
    ExpectRefused(job, "'solver.max_iterations' expected a whole number within 1 .. 10000000, got");
  }
}

TEST(PolishCommand, TiltsThePrecessingBonnetByTheJobsAngle) {
  TempDir dir;
  WriteMap(dir / "map.csv");
  WriteText(dir / "job.json", Job("", R"(,
  "precession": {"tilt_deg": 20.0, "precession_rate_rpm": 5.0, "bonnet_radius_mm": 40.0})"));
  const auto result = PolishJobIn(dir);
  ASSERT_EQ(result.exit_status, 0) << result.output;
  const auto rows = PathRows(dir, 7);
  for (const std::vector<double>& row : rows) {
    const double x = row[0], y = row[1], q1 = row[3], q2 = row[4], q3 = row[5], q4 = row[6];
    // Tool z of the quaternion (third column of its rotation matrix) against the inward normal
    // of the convex conic (R0 = 400, k = -0.5) at the contact under the bonnet centre.
    const double zx = 2 * (q2 * q4 + q1 * q3), zy = 2 * (q3 * q4 - q1 * q2), zz = 1 - 2 * (q2 * q2 + q3 * q3);
    EXPECT_NEAR(std::sqrt(zx * zx + zy * zy + zz * zz), 1.0, 1e-12);
    // Contact under the bonnet centre by fixed-point iteration (a contraction: 40 mm << R0), with
    // the conic's slope dz/dr = -c r / sqrt(1 - (1 + k) c^2 r^2) written out here.
    const double c = 1.0 / 400.0, k = -0.5;
    double cx = x, cy = y, ux = 0, uy = 0, uz = 1;
    for (int it = 0; it < 100; ++it) {
      const double r = std::hypot(cx, cy);
      const double slope = -c * r / std::sqrt(1.0 - (1.0 + k) * c * c * r * r);
      const double fx = r > 0 ? slope * cx / r : 0.0, fy = r > 0 ? slope * cy / r : 0.0;
      const double n = std::sqrt(fx * fx + fy * fy + 1.0);
      ux = -fx / n, uy = -fy / n, uz = 1.0 / n;
      cx = x - 40.0 * ux, cy = y - 40.0 * uy;
    }
    EXPECT_NEAR(std::acos(-(zx * ux + zy * uy + zz * uz)), 20.0 * std::acos(-1.0) / 180.0, 1e-9)
        << "point (" << x << ", " << y << ")";
  }
  EXPECT_GT(rows.size(), 500U);
}

TEST(PolishCommand, RefusesAnUnknownAsphereCoefficientByItsDottedName) {
  ExpectRefused(
      WithSurface(
          R"({"type": "even_asphere", "vertex_radius_mm": 400, "coefficients": {"A4": 1e-10, "A5": 1}})"),
      "unknown key 'surface.coefficients.A5'");
}

TEST(PolishCommand, RefusesAnUnknownKeyByItsDottedName) {
  ExpectRefused(Job(", \"max_sped_mm_s\": 3"), "unknown key 'machine.max_sped_mm_s'");
}

TEST(PolishCommand, RefusesUnreachableSpeeds) {
  ExpectRefused(Job().replace(Job().find("\"min_speed_mm_s\": 0.5"), 21, "\"min_speed_mm_s\": 500"),
                "machine.min_speed_mm_s = 500 violates 0 <= min_speed_mm_s <= max_speed_mm_s = 150");
}

TEST(PolishCommand, RefusesAMapOffTheSurface) {
  // A convex sphere of radius 25 mm cannot carry the 60 mm aperture.
  ExpectRefused(Job("", "", 25.0), "off the surface");
}

TEST(PolishCommand, RefusesAnEmptyAperture) { ExpectRefused(Job(), "empty aperture", /*shifted_map=*/true); }

TEST(PolishCommand, RefusesAPathSpacingBeyondTheMemoryBudgetUpFront) {
  // 1e-4 mm over the 72 mm grown disc: a raster bound of (72 / 1e-4 + 1)^2 = 5.18e11 dwell points
  // (this used to run a minute, take 17 GB and end in std::bad_alloc).
  std::string job = Job();
  const std::string spacing = R"("line_spacing_mm": 2.0, "point_spacing_mm": 2.0)";
  job.replace(job.find(spacing), spacing.size(), R"("line_spacing_mm": 1e-4, "point_spacing_mm": 1e-4)");
  ExpectRefused(
      job,
      "path.line_spacing_mm = 0.0001, path.point_spacing_mm = 0.0001 violates the memory budget: it "
      "implies 5.18e+11 dwell points");
  ExpectRefused(job, "over the 4 GiB (4294967296 B) of one run");
}

TEST(PolishCommand, RefusesAnInfinityInTheMapNamingItsLine) {
  TempDir dir;
  WriteMap(dir / "map.csv");
  std::string map = arcwheel::testing::ReadText(dir / "map.csv");
  // Row of node (0, 0): line 3 (comment, header) + 32 rows of 65 + 32 nodes.
  const std::size_t start = map.find("\n0,0,") + 1;
  map.replace(start, map.find('\n', start) - start, "0,0,inf");
  WriteText(dir / "map.csv", map);
  WriteText(dir / "job.json", Job());
  const auto result =
      RunArcwheel(fmt::format("polish {} -o {}", (dir / "job.json").string(), (dir / "out").string()));
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_NE(result.output.find("map.csv' line 2115: error_um = inf is not finite"), std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(PolishCommand, RefusesAnErrorMapGridBeyondTheMemoryBudgetBeforeReadingIt) {
  TempDir dir;
  {
    // 8192 x 8192 nodes declared, none stored: a chunked dataset that was never written takes no
    // room in the file, so only its declared shape can stop the read.
    const hid_t file = H5Fcreate((dir / "map.h5").c_str(), H5F_ACC_TRUNC, H5P_DEFAULT, H5P_DEFAULT);
    const hsize_t shape[2] = {8192, 8192}, chunk[2] = {256, 256};
    const hid_t space = H5Screate_simple(2, shape, nullptr);
    const hid_t creation = H5Pcreate(H5P_DATASET_CREATE);
    H5Pset_chunk(creation, 2, chunk);
    const hid_t data =
        H5Dcreate2(file, "error_um", H5T_IEEE_F64LE, space, H5P_DEFAULT, creation, H5P_DEFAULT);
    for (const char* key : {"x0_mm", "y0_mm", "dx_mm", "dy_mm"}) {
      const double value = key[1] == '0' ? -40.0 : 0.01;
      const hid_t scalar = H5Screate(H5S_SCALAR);
      const hid_t attribute = H5Acreate2(file, key, H5T_IEEE_F64LE, scalar, H5P_DEFAULT, H5P_DEFAULT);
      H5Awrite(attribute, H5T_NATIVE_DOUBLE, &value);
      H5Aclose(attribute);
      H5Sclose(scalar);
    }
    H5Dclose(data);
    H5Pclose(creation);
    H5Sclose(space);
    H5Fclose(file);
  }
  std::string job = Job();
  job.replace(job.find("map.csv"), 7, "map.h5");
  WriteText(dir / "job.json", job);
  const auto result =
      RunArcwheel(fmt::format("polish {} -o {}", (dir / "job.json").string(), (dir / "out").string()));
  EXPECT_EQ(result.exit_status, 3) << result.output;
  EXPECT_NE(
      result.output.find("map.h5': dataset 'error_um' [8192][8192] violates the memory budget: it implies "
                         "6.71e+07 map nodes x 160 B"),
      std::string::npos)
      << result.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

}  // namespace
}  // namespace arcwheel::polishing
