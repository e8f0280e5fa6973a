#include "polishing/removal_function.h"

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>
#include <numbers>
#include <random>
#include <string>

#include "core/error.h"
#include "core/hdf5.h"
#include "core/testing/testing.h"
#include "polishing/job.h"
#include "polishing/testing.h"

namespace arcwheel::polishing {
namespace {

using testing::SampledGaussian;

std::string Csv(const TabulatedRemovalFunction& t) {
  std::string out = "# measured footprint\nx_mm,y_mm,rate_um_per_s\n";
  for (int j = t.ny - 1; j >= 0; --j) {  // any order
    for (int i = 0; i < t.nx; ++i) {
      out += fmt::format("{},{},{}\n", t.x0_mm + i * t.dx_mm, t.y0_mm + j * t.dy_mm,
                         t.rate_um_per_s[j * t.nx + i]);
    }
  }
  return out;
}

std::string KernelCsvError(const std::string& text) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "footprint.csv") << text;
  return arcwheel::testing::ErrorMessageOf([&dir] { (void)ReadRemovalFunction(dir / "footprint.csv"); });
}

TEST(TabulatedRemovalFunction, InterpolatesAGaussianWithinTheBilinearBound) {
  // Linear interpolation on a step h errs by at most h^2/8 max|f''| (the remainder of the linear
  // Lagrange interpolant); bilinear = x-interpolation of y-interpolants, and interpolation never
  // enlarges a maximum, so |f - I f| <= hx^2/8 max|f_xx| + hy^2/8 max|f_yy|. For a Gaussian of peak
  // P and width sigma, f_xx = P/sigma^2 (x^2/sigma^2 - 1) e^(-r^2/(2 sigma^2)), largest in magnitude
  // at the centre: P/sigma^2. Outside the table the rate is 0 where the Gaussian is at most
  // P e^(-W^2/(2 sigma^2)), W the table's half width.
  const double peak = 2.0, sigma = 12.0 / (2.0 * std::sqrt(2.0 * std::numbers::ln2)), h = 0.1;
  const int n = 2 * static_cast<int>(std::ceil(4.5 * sigma / h)) + 1;
  const double half_width = (n - 1) / 2 * h;
  const RemovalFunction table =
      SampledGaussian(peak, 0.0, 0.0, sigma, sigma, -half_width, -half_width, h, n, n);
  const double inside_bound = peak * (h * h + h * h) / (8.0 * sigma * sigma);
  const double outside_bound = peak * std::exp(-half_width * half_width / (2.0 * sigma * sigma));
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.3 * half_width, 1.3 * half_width);
  double worst_inside = 0.0;
  for (int k = 0; k < 20000; ++k) {
    const double x = u(rng), y = u(rng);
    const double exact = peak * std::exp(-(x * x + y * y) / (2.0 * sigma * sigma));
    const bool inside = std::abs(x) <= half_width && std::abs(y) <= half_width;
    const double error = std::abs(table.RateUmPerS(x, y) - exact);
    EXPECT_LE(error, inside ? inside_bound : outside_bound) << x << ", " << y;
    if (inside) worst_inside = std::max(worst_inside, error);
  }
  EXPECT_GT(worst_inside, 0.05 * inside_bound);  // the bound is not vacuous
  // The second-moment width of a Gaussian table is the Gaussian's (the tails cut at 4.5 sigma
  // take 1e-3 of it; the node sum is exact to far less at h = sigma/50).
  EXPECT_NEAR(table.EquivalentFwhmMm(), 12.0, 12.0 * 2e-3);
  EXPECT_DOUBLE_EQ(table.PeakRateUmPerS(), peak);
}

TEST(TabulatedRemovalFunction, PutsAnOffsetFootprintWhereTheTableSays) {
  // Footprint centred 2 mm in +x and 1 mm in -y of the tool centre: the rate peaks there.
  const RemovalFunction table = SampledGaussian(3.0, 2.0, -1.0, 3.0, 1.5, -6.0, -6.0, 0.5, 33, 21);
  EXPECT_DOUBLE_EQ(table.RateUmPerS(2.0, -1.0), 3.0);
  EXPECT_NEAR(table.RateUmPerS(2.0 + 3.0, -1.0), 3.0 * std::exp(-0.5), 1e-12);  // on nodes: exact
  EXPECT_EQ(table.RateUmPerS(-6.01, 0.0), 0.0);
  EXPECT_EQ(table.RateUmPerS(0.0, 4.01), 0.0);
  const FootprintBox box = table.Footprint();
  EXPECT_DOUBLE_EQ(box.min_x_mm, -6.0);
  EXPECT_DOUBLE_EQ(box.max_x_mm, 10.0);
  EXPECT_DOUBLE_EQ(box.max_y_mm, 4.0);
}

TEST(ReadRemovalFunction, ReadsTheCsvAndHdf5FormsToTheSameTable) {
  const TabulatedRemovalFunction table = SampledGaussian(3.0, 2.0, -1.0, 3.0, 1.5, -6.0, -6.0, 0.5, 33, 21);
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "footprint.csv") << Csv(table);
  {
    hdf5::File file = hdf5::File::Create(dir / "footprint.h5");
    file.WriteDoubles("rate_um_per_s", table.rate_um_per_s, {21, 33});
    for (const auto& [name, value] :
         {std::pair{"x0_mm", -6.0}, {"y0_mm", -6.0}, {"dx_mm", 0.5}, {"dy_mm", 0.5}}) {
      file.WriteAttribute("rate_um_per_s", name, value);
    }
  }
  for (const std::string name : {"footprint.csv", "footprint.h5"}) {
    const TabulatedRemovalFunction read = ReadRemovalFunction(dir / name);
    EXPECT_EQ(read.nx, 33) << name;
    EXPECT_EQ(read.ny, 21) << name;
    EXPECT_DOUBLE_EQ(read.x0_mm, -6.0) << name;
    EXPECT_DOUBLE_EQ(read.y0_mm, -6.0) << name;
    EXPECT_DOUBLE_EQ(read.dx_mm, 0.5) << name;
    ASSERT_EQ(read.rate_um_per_s.size(), table.rate_um_per_s.size());
    for (std::size_t k = 0; k < table.rate_um_per_s.size(); ++k) {
      EXPECT_DOUBLE_EQ(read.rate_um_per_s[k], table.rate_um_per_s[k]) << name << " node " << k;
    }
  }
}

TEST(ReadRemovalFunction, NamesTheFileAndLineOfAMalformedCsv) {
  const std::string head = "x_mm,y_mm,rate_um_per_s\n";
  EXPECT_NE(KernelCsvError("x,y,r\n").find("footprint.csv' line 1: header 'x,y,r'"), std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,1\n1,0,-0.5\n0,1,1\n1,1,1\n")
                .find("line 3: rate_um_per_s = -0.5 must be finite and >= 0"),
            std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,1\n1,0,nan\n0,1,1\n1,1,1\n").find("line 3: rate_um_per_s = nan"),
            std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,1\n1,0,abc\n").find("line 3: 'abc' is not a number"),
            std::string::npos);
  std::string grid = head;
  for (int j = 0; j < 2; ++j) {
    for (int i = 0; i < 5; ++i) grid += fmt::format("{},{},1\n", i, j);
  }
  EXPECT_NE(KernelCsvError(grid + "1.4,1,1\n").find("line 12: (1.4, 1) mm is not on the regular grid"),
            std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,1\n1,0,1\n0,1,1\n0,1,1\n").find("line 5: (0, 1) mm appears twice"),
            std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,1\n1,0,1\n0,1,1\n")
                .find("node (1, 1) mm of the 2 x 2 footprint grid is missing"),
            std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,0\n1,0,0\n0,1,0\n1,1,0\n").find("removes nothing"), std::string::npos);
  EXPECT_NE(KernelCsvError(head + "0,0,1\n1,0,1\n").find("needs 2 x 2 or more"), std::string::npos);
}

TEST(ReadRemovalFunction, NamesTheDatasetOfAMalformedHdf5Table) {
  auto error_of = [](auto&& write) {
    arcwheel::testing::TempDir dir;
    {
      hdf5::File file = hdf5::File::Create(dir / "footprint.h5");
      write(file);
    }
    try {
      (void)ReadRemovalFunction(dir / "footprint.h5");
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::kBadInput) << e.what();
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  auto attributes = [](hdf5::File& f) {
    for (const auto& [name, value] :
         {std::pair{"x0_mm", 0.0}, {"y0_mm", 0.0}, {"dx_mm", 1.0}, {"dy_mm", 1.0}}) {
      f.WriteAttribute("rate_um_per_s", name, value);
    }
  };
  EXPECT_NE(error_of([](hdf5::File& f) {
              f.WriteDoubles("rate", {1, 2, 3, 4}, {2, 2});
            }).find("dataset '/rate_um_per_s': is missing"),
            std::string::npos);
  EXPECT_NE(error_of([&](hdf5::File& f) {
              f.WriteDoubles("rate_um_per_s", {1, 2, 3, 4}, {4});
              attributes(f);
            }).find("has rank 1"),
            std::string::npos);
  EXPECT_NE(error_of([](hdf5::File& f) {
              f.WriteDoubles("rate_um_per_s", {1, 2, 3, 4}, {2, 2});
            }).find("attribute 'x0_mm' is missing"),
            std::string::npos);
  EXPECT_NE(error_of([&](hdf5::File& f) {
              f.WriteDoubles("rate_um_per_s", {1, 2, 3, -4, 5, 6}, {2, 3});
              attributes(f);
            }).find("'/rate_um_per_s': [1][0] = -4 um/s must be finite and >= 0"),
            std::string::npos);
  EXPECT_NE(error_of([&](hdf5::File& f) {
              f.WriteDoubles("rate_um_per_s", {1, 2, 3, 4}, {2, 2});
              for (const auto& [name, value] :
                   {std::pair{"x0_mm", 0.0}, {"y0_mm", 0.0}, {"dx_mm", 1.0}, {"dy_mm", 0.0}}) {
                f.WriteAttribute("rate_um_per_s", name, value);
              }
            }).find("must be > 0"),
            std::string::npos);
}

// A job file as the example's, with `removal_function` replaced.
std::filesystem::path WriteJob(const arcwheel::testing::TempDir& dir,
                               const nlohmann::json& removal_function) {
  const std::filesystem::path examples = arcwheel::testing::SourceDir() / "polishing" / "examples";
  std::ifstream in(examples / "disc_job.json");
  nlohmann::json job = nlohmann::json::parse(in);
  job["error_map"]["file"] = (examples / "disc_map.csv").string();
  job["removal_function"] = removal_function;
  job.erase("path");  // the defaults follow the removal function's width
  std::ofstream(dir / "job.json") << job.dump(2);
  return dir / "job.json";
}

TEST(ReadPolishJob, TakesAMeasuredRemovalFunctionAndDerivesThePathFromItsWidth) {
  const double sigma = 10.0 / (2.0 * std::sqrt(2.0 * std::numbers::ln2));
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "footprint.csv")
      << Csv(SampledGaussian(1.5, 0.0, 0.0, sigma, sigma, -20.0, -20.0, 0.25, 161, 161));
  const PolishJob job = ReadPolishJob(WriteJob(dir, {{"file", "footprint.csv"}}));  // relative to the job
  ASSERT_TRUE(std::holds_alternative<TabulatedRemovalFunction>(job.removal.model()));
  // The equivalent sigma of a Gaussian table is the Gaussian's: the same defaults as fwhm_mm = 10.
  EXPECT_NEAR(job.path.line_spacing_mm, 10.0 / 5.0, 2e-3);
  EXPECT_NEAR(job.path.extension_mm, 1.75 * sigma, 2e-3);
  EXPECT_NE(job.removal.Describe().find("footprint.csv"), std::string::npos);
}

TEST(ReadPolishJob, RefusesAMeasuredAndAGaussianRemovalFunctionTogetherOrABadTable) {
  arcwheel::testing::TempDir dir;
  std::ofstream(dir / "footprint.csv") << "x_mm,y_mm,rate_um_per_s\n0,0,1\n1,0,1\n0,1,1\n1,1,inf\n";
  try {
    (void)ReadPolishJob(WriteJob(dir, {{"file", "footprint.csv"}, {"fwhm_mm", 10.0}}));
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find(
                  "'removal_function.file' is an alternative to peak_rate_um_per_s and fwhm_mm"),
              std::string::npos)
        << e.what();
  }
  try {
    (void)ReadPolishJob(WriteJob(dir, {{"file", "footprint.csv"}}));
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_NE(
        std::string(e.what()).find("polishing.removal: '" + (dir / "footprint.csv").string() + "' line 5"),
        std::string::npos)
        << e.what();
  }
}

TEST(ReadPolishJob, TakesTheSpiralPathTypeAndRefusesAnUnknownOne) {
  arcwheel::testing::TempDir dir;
  const std::filesystem::path examples = arcwheel::testing::SourceDir() / "polishing" / "examples";
  std::ifstream in(examples / "disc_job.json");
  nlohmann::json job = nlohmann::json::parse(in);
  job["error_map"]["file"] = (examples / "disc_map.csv").string();
  job["path"]["type"] = "spiral";
  std::ofstream(dir / "spiral.json") << job.dump(2);
  EXPECT_EQ(ReadPolishJob(dir / "spiral.json").path_pattern, PathPattern::kSpiral);
  job["path"]["type"] = "helix";
  std::ofstream(dir / "helix.json") << job.dump(2);
  try {
    (void)ReadPolishJob(dir / "helix.json");
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_NE(
        std::string(e.what()).find("key 'path.type' expected one of \"raster\", \"spiral\", got \"helix\""),
        std::string::npos)
        << e.what();
  }
}

TEST(RunPolishJob, SolvesWithAMeasuredRemovalFunctionUnderAnAccelerationLimit) {
  const double sigma = 10.0 / (2.0 * std::sqrt(2.0 * std::numbers::ln2));
  arcwheel::testing::TempDir dir;
  {
    hdf5::File file = hdf5::File::Create(dir / "footprint.h5");
    const TabulatedRemovalFunction table =
        SampledGaussian(1.5, 0.0, 0.0, sigma, sigma, -16.0, -16.0, 0.25, 129, 129);
    file.WriteDoubles("rate_um_per_s", table.rate_um_per_s, {129, 129});
    for (const auto& [name, value] :
         {std::pair{"x0_mm", -16.0}, {"y0_mm", -16.0}, {"dx_mm", 0.25}, {"dy_mm", 0.25}}) {
      file.WriteAttribute("rate_um_per_s", name, value);
    }
  }
  const std::filesystem::path job_file = WriteJob(dir, {{"file", "footprint.h5"}});
  nlohmann::json job_json = nlohmann::json::parse(std::ifstream(job_file));
  job_json["machine"]["max_acceleration_mm_s2"] = 1000.0;
  std::ofstream(job_file) << job_json.dump(2);
  const PolishJob job = ReadPolishJob(job_file);
  const PolishRunReport report = RunPolishJob(job, dir / "out");
  const nlohmann::json summary = nlohmann::json::parse(std::ifstream(dir / "out" / "polish_summary.json"));
  EXPECT_LE(summary["max_acceleration_mm_s2"].get<double>(), 1000.0 * (1.0 + 1e-9));
  EXPECT_EQ(summary["solver"]["shaping_rounds"].get<int>(), report.dwell.shaping_rounds);
  EXPECT_LT(summary["after"]["rms_um"].get<double>(), summary["before"]["rms_um"].get<double>() / 10.0);
  std::ifstream path_csv(dir / "out" / "polishing_path.csv");
  const std::string text((std::istreambuf_iterator<char>(path_csv)), std::istreambuf_iterator<char>());
  EXPECT_NE(text.find("removal function: measured '" + (dir / "footprint.h5").string() + "'"),
            std::string::npos);
}

}  // namespace
}  // namespace arcwheel::polishing
