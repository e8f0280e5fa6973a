#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <nlohmann/json.hpp>
#include <utility>
#include <vector>

#include "acquisition/scan_format.h"
#include "acquisition/scan_reader.h"
#include "acquisition/simulate.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/testing/testing.h"

namespace arcwheel::acquisition {
namespace {

using testing::ErrorMessageOf;
using testing::ErrorOf;
using ::testing::HasSubstr;
using testing::TempDir;
using testing::WriteText;

// A float32 scan of the contract's layout at `path`: the settings every test here gives, and the
// attributes in `more` (the invalid value, the range).
void WriteFloatScan(const std::filesystem::path& path, const std::vector<float>& z,
                    std::initializer_list<std::pair<const char*, double>> more = {}) {
  auto file = hdf5::File::Create(path);
  file.CreateGroup("/scan");
  file.WriteFloats("/scan/z", z, {z.size()});
  file.WriteAttribute("/scan", "spindle_rpm", 500.0);
  file.WriteAttribute("/scan", "feed_mm_per_min", 100.0);
  file.WriteAttribute("/scan", "sample_period_s", 0.001);
  for (const auto& [name, value] : more) file.WriteAttribute("/scan", name, value);
}

const char* kSettings = "# spindle_rpm: 500\n# feed_mm_per_min: 100\n# sample_period_s: 0.001\n";

// 3 turns at 500 rpm with 1 ms samples: 360 samples; the reader needs them to accept the file.
std::string Rows(const std::string& first_rows, char separator = ',') {
  std::string text = first_rows;
  for (int i = 0; i < 400; ++i)
    text += "0.5" + std::string(1, separator) + std::to_string(0.01 + i * 0.001) + "\n";
  return text;
}

// formats.md section 2 names two layouts and their extensions; case does not matter.
TEST(ScanFormat, TheExtensionSelectsTheFormatInAnyCase) {
  EXPECT_EQ(ScanFormatOfName("a/scan.h5"), ScanFormat::kHdf5);
  EXPECT_EQ(ScanFormatOfName("SCAN.H5"), ScanFormat::kHdf5);
  EXPECT_EQ(ScanFormatOfName("scan.Hdf5"), ScanFormat::kHdf5);
  EXPECT_EQ(ScanFormatOfName("scan.CSV"), ScanFormat::kCsv);
  EXPECT_EQ(ScanFormatOfName("scan.txt"), ScanFormat::kCsv);
  EXPECT_EQ(ScanFormatOfName("scan.dat"), std::nullopt);
  EXPECT_EQ(ScanFormatOfName("h5"), std::nullopt);
  EXPECT_EQ(InfoOf(ScanFormat::kHdf5).name, "hdf5");
  EXPECT_EQ(InfoOf(ScanFormat::kCsv).name, "csv");
  EXPECT_EQ(ScanExtensionsText(), ".h5, .hdf5, .csv or .txt");
}

TEST(ScanFormat, AFileOfNoFormatIsRefusedNamingTheFileAndTheExtensions) {
  const std::string message = ErrorMessageOf([] { (void)ScanFormatOfFile("dir/scan.dat", "acquisition"); });
  EXPECT_THAT(message,
              HasSubstr("'dir/scan.dat': unknown scan file type '.dat' (expected .h5, .hdf5, .csv or .txt)"));
}

TEST(CsvReader, FoldsAlarmWordsNanAndEmptyCellsIntoInvalidSamples) {
  TempDir dir;
  std::string text =
      std::string(kSettings) +
      "# wheel_id: W-17\n# note without a key\nz_mm\n0.25\n-FFFFFFF\n+FFFF\nalarm\nNaN\n\n0.125\n";
  for (int i = 0; i < 400; ++i) text += "0.5\n";
  WriteText(dir / "scan.csv", text);
  const Scan scan = ReadCsvScan(dir / "scan.csv");
  ASSERT_EQ(scan.size(), 407u);
  EXPECT_EQ(scan.z_mm[0], 0.25);
  for (int i = 1; i <= 5; ++i) EXPECT_TRUE(std::isnan(scan.z_mm[i])) << i;
  EXPECT_EQ(scan.z_mm[6], 0.125);
  EXPECT_EQ(scan.metadata.wheel_id, "W-17");
  EXPECT_EQ(*scan.metadata.spindle_rpm, 500.0);
  EXPECT_EQ(scan.CountValid(), 402u);
}

TEST(CsvReader, AcceptsSemicolonAndTabSeparators) {
  TempDir dir;
  for (const char separator : {';', '\t'}) {
    WriteText(dir / "scan.csv", Rows(std::string(kSettings) + "z_mm" + separator + "y_mm\n", separator));
    const Scan scan = ReadCsvScan(dir / "scan.csv");
    EXPECT_EQ(scan.size(), 400u);
    EXPECT_NEAR(scan.y_mm[399], 0.01 + 399 * 0.001, 1e-12);
  }
}

TEST(CsvReader, NamesTheLineOfAValueThatDoesNotParse) {
  TempDir dir;
  WriteText(dir / "scan.csv", std::string(kSettings) + "z_mm,y_mm\n0.5,0.1\n0.5,0.1x\n");
  const std::string message = ErrorMessageOf([&] { (void)ReadCsvScan(dir / "scan.csv"); });
  EXPECT_THAT(message, HasSubstr("line 6"));
  EXPECT_THAT(message, HasSubstr("0.1x"));
}

TEST(Hdf5Reader, ComparesTheInvalidValueInTheFilesOwnType) {
  TempDir dir;
  std::vector<float> z(400, 0.5f);
  z[3] = 0.1f;  // not exactly representable: only a float comparison finds it
  WriteFloatScan(dir / "scan.h5", z, {{"invalid_value", 0.1}, {"range_max_mm", 3.0}});
  const Scan scan = ReadHdf5Scan(dir / "scan.h5");
  EXPECT_TRUE(std::isnan(scan.z_mm[3]));
  EXPECT_EQ(scan.CountValid(), 399u);
}

// Kept float32 readings of a scan larger than a few blocks get their marks wherever they lie, the
// last reading included (the sentinel compared as float, the range limits, an infinity), and no
// other reading changes.
TEST(Hdf5Reader, MarksKeptFloat32ReadingsWhereverTheyLie) {
  TempDir dir;
  const std::size_t n = 3 * 65536 + 123;
  std::vector<float> z(n);
  for (std::size_t i = 0; i < n; ++i) z[i] = 0.5f + static_cast<float>(i % 1000) / 1024.0f;
  std::vector<std::size_t> invalid;
  for (const std::size_t block_start :
       {std::size_t{0}, std::size_t{65536}, std::size_t{131072}, std::size_t{196608}}) {
    const std::size_t i = block_start + 7;
    z[i] = 0.1f;      // the sentinel
    z[i + 1] = 4.0f;  // above range_max_mm
    z[i + 2] = std::numeric_limits<float>::infinity();
    invalid.insert(invalid.end(), {i, i + 1, i + 2});
  }
  z[n - 1] = -5.0f;  // below range_min_mm, the last reading of the short block
  invalid.push_back(n - 1);
  WriteFloatScan(dir / "scan.h5", z, {{"invalid_value", 0.1}, {"range_min_mm", -3.0}, {"range_max_mm", 3.0}});
  ReadOptions options;
  options.keep_float32 = true;
  const Scan scan = ReadHdf5Scan(dir / "scan.h5", options);
  ASSERT_TRUE(scan.holds_float());
  ASSERT_EQ(scan.z_float_mm.size(), n);
  for (std::size_t i = 0; i < n; ++i) {
    if (std::find(invalid.begin(), invalid.end(), i) != invalid.end()) {
      EXPECT_TRUE(std::isnan(scan.z_float_mm[i])) << i;
    } else {
      ASSERT_EQ(scan.z_float_mm[i], z[i]) << i;
    }
  }
  EXPECT_EQ(scan.CountValid(), n - invalid.size());
}

// The range's limits are doubles and the kept readings floats: a reading is in range when its
// value is, compared exactly (0.1f lies above 0.1, -0.3f below -0.3), and limits beyond float's
// range take every finite reading in.
TEST(Hdf5Reader, ComparesKeptFloat32ReadingsWithTheRangeExactly) {
  const auto next_toward_zero = [](float z) { return std::nextafter(z, 0.0f); };
  const std::vector<float> near_limits = {0.1f,
                                          next_toward_zero(0.1f),
                                          -0.3f,
                                          next_toward_zero(-0.3f),
                                          0.0f,
                                          -std::numeric_limits<float>::max(),
                                          std::numeric_limits<float>::max()};
  for (const auto& [low, high] : {std::pair{-0.3, 0.1}, std::pair{-1e300, 1e300}}) {
    TempDir dir;
    std::vector<float> z(4000, 0.05f);
    for (std::size_t k = 0; k < near_limits.size(); ++k) z[100 + k] = near_limits[k];
    WriteFloatScan(dir / "scan.h5", z, {{"range_min_mm", low}, {"range_max_mm", high}});
    ReadOptions options;
    options.keep_float32 = true;
    const Scan scan = ReadHdf5Scan(dir / "scan.h5", options);
    ASSERT_TRUE(scan.holds_float());
    for (std::size_t k = 0; k < near_limits.size(); ++k) {
      const double value = near_limits[k];
      const bool in_range = value >= low && value <= high;
      if (in_range) {
        EXPECT_EQ(scan.z_float_mm[100 + k], near_limits[k]) << value << " in [" << low << ", " << high << "]";
      } else {
        EXPECT_TRUE(std::isnan(scan.z_float_mm[100 + k]))
            << value << " outside [" << low << ", " << high << "]";
      }
    }
  }
}

TEST(Hdf5Reader, KeepsFloat32ReadingsInTheChildsPagesAndCopiesThemAsValues) {
  TempDir dir;
  std::vector<float> z(5000);
  for (std::size_t i = 0; i < z.size(); ++i) z[i] = 0.5f + static_cast<float>(i) / 1024.0f;
  z[10] = std::numeric_limits<float>::quiet_NaN();
  WriteFloatScan(dir / "scan.h5", z);
  ReadOptions options;
  options.keep_float32 = true;
  Scan scan = ReadHdf5Scan(dir / "scan.h5", options);
  ASSERT_TRUE(scan.holds_float());
  ASSERT_EQ(scan.z_float_mm.size(), z.size());
  for (std::size_t i = 0; i < z.size(); ++i) {
    if (i == 10) {
      EXPECT_TRUE(std::isnan(scan.z_float_mm[i]));
    } else {
      ASSERT_EQ(scan.z_float_mm[i], z[i]) << i;
    }
  }
  // A copy is the copy's own: writing to the scan's readings leaves it as read.
  const Scan copy = scan;
  scan.z_float_mm[0] = -2.0f;
  EXPECT_EQ(copy.z_float_mm[0], z[0]);
  Scan moved = std::move(scan);
  EXPECT_EQ(moved.z_float_mm[0], -2.0f);
  EXPECT_EQ(moved.z_float_mm.size(), z.size());
}

TEST(Hdf5Reader, RefusesColumnsOfDifferentLengths) {
  TempDir dir;
  {
    auto file = hdf5::File::Create(dir / "scan.h5");
    file.CreateGroup("/scan");
    file.WriteDoubles("/scan/z", std::vector<double>(400, 0.5), {400});
    file.WriteDoubles("/scan/t", std::vector<double>(399, 0.5), {399});
    file.WriteAttribute("/scan", "spindle_rpm", 500.0);
    file.WriteAttribute("/scan", "feed_mm_per_min", 100.0);
  }
  EXPECT_THAT(ErrorMessageOf([&] { (void)ReadHdf5Scan(dir / "scan.h5"); }),
              HasSubstr("column 't' has 399 values but 'z' has 400"));
}

TEST(Hdf5Reader, RefusesAFileWithoutTheScanGroup) {
  TempDir dir;
  { auto file = hdf5::File::Create(dir / "scan.h5"); }
  EXPECT_THROW((void)ReadHdf5Scan(dir / "scan.h5"), Error);
}

// Found by fuzzing (scripts/fuzz.sh): a header declaring ~2e14 values made the reader try to
// allocate them.
TEST(Hdf5Reader, RefusesADatasetLargerThanTheFileCanHold) {
  const auto path = testing::SourceDir() / "testdata" / "fuzz_regressions" / "scan_hdf5_huge_dataset.h5";
  std::ifstream in(path, std::ios::binary);
  const std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  ASSERT_FALSE(bytes.empty());
  const Error error = ErrorOf(
      [&] { (void)ReadHdf5Scan(hdf5::File::OpenImage(bytes.data(), bytes.size(), "regression.h5")); });
  EXPECT_EQ(error.code(), ErrorCode::kBadInput) << error.what();
}

// Golden file: the shipped scan and its truth (testdata/README.md says how they were made).
TEST(Readers, ShippedPaperScanMatchesItsTruthFile) {
  const auto folder = testing::SourceDir() / "testdata";
  const Scan scan = ReadScan(folder / "paper_wheel_scan.h5");
  std::ifstream in(folder / "paper_wheel_scan.h5.truth.json");
  const auto truth = nlohmann::json::parse(in);
  EXPECT_EQ(scan.size(), truth["counts"]["samples"].get<std::size_t>());
  EXPECT_EQ(scan.size() - scan.CountValid(),
            truth["counts"]["off_rim"].get<std::size_t>() + truth["counts"]["dropouts"].get<std::size_t>());
  EXPECT_EQ(*scan.metadata.spindle_rpm, truth["settings"]["spindle_rpm_nominal"].get<double>());
  EXPECT_EQ(*scan.metadata.sample_period_s, truth["settings"]["sample_period_s"].get<double>());
  EXPECT_EQ(*scan.metadata.feed_mm_per_min, truth["settings"]["feed_mm_per_min"].get<double>());
}

TEST(Scan, WideningToDoubleKeepsTheReadingsAndFreesTheFloats) {
  Scan scan;
  scan.z_float_mm = {1.5f, std::numeric_limits<float>::quiet_NaN(), -0.25f, 1e-7f};
  const std::vector<float> floats(scan.z_float_mm.begin(), scan.z_float_mm.end());
  scan.WidenToDouble();
  ASSERT_EQ(scan.z_mm.size(), floats.size());
  for (std::size_t i = 0; i < floats.size(); ++i) {
    if (std::isnan(floats[i])) {
      EXPECT_TRUE(std::isnan(scan.z_mm[i]));
    } else {
      EXPECT_EQ(scan.z_mm[i], static_cast<double>(floats[i]));
    }
  }
  EXPECT_FALSE(scan.holds_float());
  EXPECT_EQ(scan.z_float_mm.data(), nullptr);  // the float copy's memory is given back
}

}  // namespace
}  // namespace arcwheel::acquisition
