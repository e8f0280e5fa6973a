// Known answers of the sensors' readers (formats.md 2.4) on text written here as each sensor's
// software writes it; the refusals through the CLI are in tests/sensor_files_test.cc.

#include <fmt/core.h>
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <charconv>
#include <cmath>
#include <string>

#include "acquisition/scan_format.h"
#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"
#include "core/error.h"

namespace arcwheel::acquisition {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Pair;

// 400 samples of 1 ms at 500 rpm: 3.3 turns, enough for the scan to be accepted.
const ScanSettingsFile& Settings() {
  static const ScanSettingsFile settings = ParseScanSettings(
      R"({"spindle_rpm": 500, "feed_mm_per_min": 100, "sample_period_s": 0.001, "encoder_counts_per_rev": 4096})",
      "settings.json");
  return settings;
}

ReadOptions WithSettings() {
  ReadOptions options;
  options.settings = &Settings();
  return options;
}

double FromPoint(const std::string& text) {
  double value = 0.0;
  std::from_chars(text.data(), text.data() + text.size(), value);
  return value;
}

TEST(SniffScanFormat, TellsEachLayoutFromItsFirstLines) {
  EXPECT_EQ(SniffScanFormat("# spindle_rpm: 500\nz_mm\n0.1\n"), ScanFormat::kCsv);
  EXPECT_EQ(SniffScanFormat("\xEF\xBB\xBFZ_MM,t_s\n0.1,0\n"), ScanFormat::kCsv);
  EXPECT_EQ(SniffScanFormat("\xEF\xBB\xBFsensorTOOL;1.9.0\r\nSensor;ILD2300\r\n"), ScanFormat::kSensorTool);
  EXPECT_EQ(SniffScanFormat("Epoch time (ms)\tDistance1 (mm)\n"), ScanFormat::kSensorTool);
  EXPECT_EQ(SniffScanFormat("LK-Navigator 2\r\nModel,LK-G5001\r\n"), ScanFormat::kKeyenceLk);
  EXPECT_EQ(SniffScanFormat("-------\r\n+01.2345\r\n"), ScanFormat::kKeyenceLk);
  EXPECT_EQ(SniffScanFormat("Zeit;Weg\n0;1,5\n"), std::nullopt);
}

TEST(IsKeyenceLkValue, TakesASignAndSevenCharactersAndTheMarkers) {
  for (const char* value : {"+01.2345", "-00.0120", "+1234.56", "-00001.2", "+FFFFFFF", "-FFFFFFF",
                            "XXXXXXXX", "-------", "--------"}) {
    EXPECT_TRUE(IsKeyenceLkValue(value)) << value;
  }
  for (const char* value :
       {"1.2345", "+1.2345", "+01.23456", "+0.1.234", "+FFFFFF", "XXXXXXX", "+ABCDEFG", ""}) {
    EXPECT_FALSE(IsKeyenceLkValue(value)) << value;
  }
}

TEST(SensorToolReader, ReadsADecimalCommaAsExactlyThePointsNumber) {
  std::string text =
      "sensorTOOL;1.9.0\r\nSensor;ILD2300\r\nMeasuring rate;1 kHz\r\nAcquisition time;Distance1 (mm)\r\n";
  std::vector<std::string> written;
  for (int i = 0; i < 400; ++i) {
    written.push_back(fmt::format("{:.6f}", 0.123456789 * std::sin(i * 0.37)));
    std::string cell = written.back();
    std::replace(cell.begin(), cell.end(), '.', ',');
    text += fmt::format("{},{:03d};{}\r\n", i / 1000, i % 1000, cell);
  }
  const Scan scan = ParseSensorScan(text, "export.csv", ScanFormat::kSensorTool, WithSettings());
  ASSERT_EQ(scan.z_mm.size(), 400u);
  for (std::size_t i = 0; i < written.size(); ++i) EXPECT_EQ(scan.z_mm[i], FromPoint(written[i])) << i;
  EXPECT_EQ(scan.metadata.sensor, "ILD2300");
  EXPECT_EQ(scan.metadata.sample_period_s, 0.001);
  EXPECT_EQ(scan.t_s[399], FromPoint("0.399"));
  EXPECT_THAT(scan.read.columns.front().name, "Distance1 (mm)");
}

TEST(SensorToolReader, ReadsATimeOfDayAsSecondsFromTheFirstSample) {
  std::string text = "sensorTOOL\r\nAcquisition time;Distance1 (mm)\r\n";
  for (int i = 0; i < 400; ++i) text += fmt::format("23:59:59,{:04d};0,5\r\n", i * 10);
  const Scan scan = ParseSensorScan(text, "export.csv", ScanFormat::kSensorTool, WithSettings());
  EXPECT_NEAR(scan.t_s[399], 0.399, 1e-9);
  EXPECT_EQ(scan.read.columns.back().unit, "hh:mm:ss");
}

TEST(SensorToolReader, DropsAnEpochTimeThatResolvesLessThanTheSampling) {
  std::string text = "sensorTOOL\r\nMeasuring rate;2 kHz\r\nEpoch time (ms);Distance1 (mm)\r\n";
  for (int i = 0; i < 800; ++i) text += fmt::format("{};0,5\r\n", 1505296800000 + i / 2);
  ReadOptions options;  // the file gives the period: no settings file needed but for the speed
  const ScanSettingsFile settings =
      ParseScanSettings(R"({"spindle_rpm": 500, "feed_mm_per_min": 100})", "s.json");
  options.settings = &settings;
  const Scan scan = ParseSensorScan(text, "export.csv", ScanFormat::kSensorTool, options);
  EXPECT_FALSE(scan.has_time());
  EXPECT_EQ(scan.metadata.sample_period_s, 0.0005);
  EXPECT_THAT(scan.metadata.notes,
              ::testing::Contains(HasSubstr("column 'Epoch time (ms)' repeats a time 400 times")));
}

TEST(KeyenceLkReader, CountsEveryMarkerByKindInTheOrderMet) {
  std::string text = "-------\r\n-------\r\n-FFFFFFF\r\n";
  for (int i = 0; i < 400; ++i) text += i == 200 ? "XXXXXXXX\r\n" : "+01.2345\r\n";
  text += "+FFFFFFF\r\n+FFFFFFF\r\n";
  const Scan scan = ParseSensorScan(text, "lk.txt", ScanFormat::kKeyenceLk, WithSettings());
  EXPECT_THAT(scan.read.invalid_markers, ElementsAre(Pair("waiting", 2u), Pair("out_of_range_low", 1u),
                                                     Pair("alarm", 1u), Pair("out_of_range_high", 2u)));
  EXPECT_EQ(scan.z_mm[3], 1.2345);
  EXPECT_TRUE(std::isnan(scan.z_mm[203]));
}

TEST(ColumnsReader, ScalesEachQuantityFromItsUnit) {
  std::string text = "Logger 3\nt [ms];z [um];angle\n";
  for (int i = 0; i < 400; ++i) text += fmt::format("{};{},5;{}\n", i, 500 + i % 3, i * 68 % 4096);
  ReadOptions options = WithSettings();
  options.columns = "z=z [um],t=t [ms],angle=angle:counts";
  const Scan scan = ParseSensorScan(text, "log.txt", ScanFormat::kColumns, options);
  EXPECT_EQ(scan.z_mm[1], 0.5015);
  EXPECT_EQ(scan.t_s[1], 0.001);
  EXPECT_DOUBLE_EQ(scan.angle_deg[1], 68 * 360.0 / 4096);
  EXPECT_THAT(scan.read.columns, ::testing::SizeIs(3));
}

TEST(ColumnsOption, NamesEveryProblem) {
  EXPECT_THAT(ColumnsOptionProblems("z=Weg:inch,q=x,t=Zeit"),
              ElementsAre("--columns = 'z=Weg:inch' violates a unit of z: mm, um or nm",
                          "--columns = 'q=x' violates QUANTITY=NAME[:UNIT] with QUANTITY z, t, angle or y"));
  EXPECT_THAT(ColumnsOptionProblems("t=Zeit"), ElementsAre("--columns names no z column (z=NAME[:UNIT])"));
  EXPECT_TRUE(ColumnsOptionProblems("z=Weg [\xC2\xB5m]:um,t=Zeit [ms]:ms").empty());
}

}  // namespace
}  // namespace arcwheel::acquisition
