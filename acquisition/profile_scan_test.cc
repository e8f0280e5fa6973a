#include "acquisition/profile_scan.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <variant>

#include "acquisition/scan_reader.h"
#include "acquisition/scan_settings.h"
#include "core/error.h"
#include "core/hdf5.h"

namespace arcwheel::acquisition {
namespace {

using ::testing::HasSubstr;

// A Gocator export as the user manual's "CSV" section shows it: sections closed by `End`, the Info
// header and value rows, the Profile attribute rows, the column row with one column per resampled
// X, CRLF line ends, an invalid point as an empty cell. 10 columns, encoder-triggered.
std::string GocatorFixture(const std::string& frame_rows) {
  return "Info\r\n"
         "CSV Version,Sensor Count,Trigger Mode,Trigger Rate,Trigger Delay Domain,Trigger Delay,Operation "
         "Mode,XResolution,YResolution,ZResolution,Yspeed,Layout\r\n"
         "2,1,1,0.00000,0,0.00000,1,0.10000,0.00000,0.00100,0.00000,0\r\n"
         "End\r\n"
         "DeviceInfo\r\n"
         "ID,Model,Version\r\n"
         "13434,2430,6.1.12.2\r\n"
         "End\r\n"
         "Profile\r\n"
         "Frame Count,Column Count,X Offset,Y Offset,Z Offset\r\n"
         "3,10,-0.45000,0.00000,0.00000\r\n"
         "Frame,Source,Time,Encoder,Z Encoder,Inputs,Exposure,Y(mm),Axis,-0.45000,-0.35000,-0.25000,-0.15000,"
         "-0.05000,0.05000,0.15000,0.25000,0.35000,0.45000\r\n" +
         frame_rows + "End\r\n";
}

std::string GocatorRow(int frame, long long encoder, const std::string& blank_at = "") {
  std::string row = std::to_string(frame) + ",0," + std::to_string(frame * 1024) + "," +
                    std::to_string(encoder) + ",0,0,300,0.00000,Z";
  for (int i = 0; i < 10; ++i) {
    row += ",";
    if (blank_at != std::to_string(i)) row += "1.2" + std::to_string(i) + "000";
  }
  return row + "\r\n";
}

ScanSettingsFile Settings(const std::string& json) { return ParseScanSettings(json, "settings.json"); }

TEST(GocatorReader, ReadsTheManualsLayoutWithEncoderPhases) {
  const ScanSettingsFile settings = Settings(R"({"encoder_counts_per_rev": 40})");
  const ProfileScan scan =
      ParseProfileScan(GocatorFixture(GocatorRow(0, 100) + GocatorRow(1, 101, "3") + GocatorRow(2, 102)),
                       "wheel.csv", ScanFormat::kGocator, &settings);
  ASSERT_EQ(scan.frames(), 3u);
  ASSERT_EQ(scan.points(), 10u);
  EXPECT_DOUBLE_EQ(scan.x_mm[0], -0.45);
  EXPECT_DOUBLE_EQ(scan.z_mm[2], 1.22);
  EXPECT_TRUE(std::isnan(scan.z_mm[10 + 3]));
  // 1 count of 40 a turn is 9 degrees; time stamps count 1/1.024 us.
  EXPECT_DOUBLE_EQ(scan.PhaseDeg(2) - scan.PhaseDeg(0), 18.0);
  EXPECT_DOUBLE_EQ(scan.t_s[1], 1e-3);
}

TEST(GocatorReader, IsSniffedByItsInfoSection) {
  EXPECT_EQ(SniffScanFormat(GocatorFixture("")), ScanFormat::kGocator);
}

TEST(GocatorReader, RefusesFramesOutOfOrderNamingFileLineAndColumn) {
  const ScanSettingsFile settings = Settings(R"({"encoder_counts_per_rev": 40})");
  try {
    (void)ParseProfileScan(GocatorFixture(GocatorRow(0, 100) + GocatorRow(2, 101) + GocatorRow(1, 102)),
                           "wheel.csv", ScanFormat::kGocator, &settings);
    FAIL() << "accepted frames out of order";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::kBadInput);
    EXPECT_THAT(e.what(), HasSubstr("'wheel.csv' line 15"));
    EXPECT_THAT(e.what(), HasSubstr("column 'Frame'"));
    EXPECT_THAT(e.what(), HasSubstr("out of order"));
  }
}

TEST(GocatorReader, RefusesAnEncoderThatGoesBackwards) {
  const ScanSettingsFile settings = Settings(R"({"encoder_counts_per_rev": 40})");
  try {
    (void)ParseProfileScan(GocatorFixture(GocatorRow(0, 100) + GocatorRow(1, 105) + GocatorRow(2, 103)),
                           "wheel.csv", ScanFormat::kGocator, &settings);
    FAIL() << "accepted an encoder going backwards";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("frame 2 column 'encoder'"));
  }
}

TEST(GocatorReader, UnwrapsAnEncoderThatWrapsAtItsCountsPerTurnAndRefusesAnotherWrap) {
  const ScanSettingsFile settings = Settings(R"({"encoder_counts_per_rev": 40})");
  const ProfileScan scan =
      ParseProfileScan(GocatorFixture(GocatorRow(0, 38) + GocatorRow(1, 39) + GocatorRow(2, 0)), "wheel.csv",
                       ScanFormat::kGocator, &settings);
  EXPECT_DOUBLE_EQ(scan.encoder[2], 40.0);
  EXPECT_THROW(
      (void)ParseProfileScan(GocatorFixture(GocatorRow(0, 18) + GocatorRow(1, 19) + GocatorRow(2, 0)),
                             "wheel.csv", ScanFormat::kGocator, &settings),
      Error);
}

TEST(GocatorReader, RefusesAReadingBeyondTheXColumns) {
  const ScanSettingsFile settings = Settings(R"({"encoder_counts_per_rev": 40})");
  std::string extra = GocatorRow(1, 101);
  extra.insert(extra.size() - 2, ",1.5");
  try {
    (void)ParseProfileScan(GocatorFixture(GocatorRow(0, 100) + extra + GocatorRow(2, 102)), "wheel.csv",
                           ScanFormat::kGocator, &settings);
    FAIL() << "accepted an extra column";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("frame 1"));
    EXPECT_THAT(e.what(), HasSubstr("column 20"));
  }
}

// A Keyence LJ save as its communication manual shows it: tab-separated, the X block first, then
// one profile a row, integers of 0.01 um, -2147483648 for an invalid point.
std::string LjFixture(const std::string& rows) {
  return "-45000\t-35000\t-25000\t-15000\t-5000\t5000\t15000\t25000\t35000\t45000\r\n" + rows;
}

std::string LjRow(int valid) {
  std::string row;
  for (int i = 0; i < 10; ++i)
    row += (i ? "\t" : "") + (i < valid ? std::to_string(120000 + i) : "-2147483648");
  return row + "\r\n";
}

TEST(KeyenceLjReader, ReadsTheXBlockAndOneProfileARow) {
  const ScanSettingsFile settings = Settings(R"({"spindle_rpm": 500, "sample_period_s": 0.001})");
  const ProfileScan scan =
      ParseProfileScan(LjFixture(LjRow(10) + LjRow(9)), "wheel.tsv", ScanFormat::kKeyenceLj, &settings);
  ASSERT_EQ(scan.frames(), 2u);
  EXPECT_DOUBLE_EQ(scan.x_mm[9], 0.45);
  EXPECT_DOUBLE_EQ(scan.z_mm[1], 1.20001);
  EXPECT_TRUE(std::isnan(scan.z_mm[19]));
  EXPECT_DOUBLE_EQ(scan.PhaseDeg(1), 3.0);  // 500 rpm for 1 ms
  EXPECT_EQ(SniffScanFormat(LjFixture(LjRow(10))), ScanFormat::kKeyenceLj);
}

TEST(KeyenceLjReader, RefusesAFrameWithFewerValidPointsThanASectionNeeds) {
  const ScanSettingsFile settings = Settings(R"({"spindle_rpm": 500, "sample_period_s": 0.001})");
  try {
    (void)ParseProfileScan(LjFixture(LjRow(10) + LjRow(5)), "wheel.tsv", ScanFormat::kKeyenceLj, &settings);
    FAIL() << "accepted a frame of 5 valid points";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("'wheel.tsv'"));
    EXPECT_THAT(e.what(), HasSubstr("frame 1 has 5 valid points"));
  }
}

TEST(KeyenceLjReader, RefusesAFrameWithFewerColumnsThanTheXBlock) {
  const ScanSettingsFile settings = Settings(R"({"spindle_rpm": 500, "sample_period_s": 0.001})");
  std::string short_row = LjRow(10);
  short_row = short_row.substr(0, short_row.rfind('\t')) + "\r\n";
  EXPECT_THROW((void)ParseProfileScan(LjFixture(LjRow(10) + short_row), "wheel.tsv", ScanFormat::kKeyenceLj,
                                      &settings),
               Error);
}

TEST(KeyenceLjReader, RefusesAScanWithoutAPhase) {
  EXPECT_THROW((void)ParseProfileScan(LjFixture(LjRow(10)), "wheel.tsv", ScanFormat::kKeyenceLj), Error);
}

ProfileScan SmallSimulatedScan() {
  ProfileScanSettings settings;
  settings.points = 40;
  settings.frames_per_turn = 16;
  settings.encoder_counts_per_rev = 64;
  settings.turns = 2;
  settings.dropout_rate = 0.05;
  settings.start_phase_deg = 0.05;
  return SimulateProfileScan(PaperTestWheel(), settings);
}

void ExpectReadBackExactly(const ProfileScan& read, const ProfileScan& simulated) {
  ASSERT_EQ(read.frames(), simulated.frames());
  EXPECT_EQ(read.x_mm, simulated.x_mm);
  for (std::size_t i = 0; i < read.z_mm.size(); ++i) {
    if (std::isnan(simulated.z_mm[i])) {
      EXPECT_TRUE(std::isnan(read.z_mm[i])) << i;
    } else {
      EXPECT_EQ(read.z_mm[i], simulated.z_mm[i]) << i;
    }
  }
  for (std::size_t f = 0; f < read.frames(); ++f)
    EXPECT_NEAR(read.PhaseDeg(f), simulated.PhaseDeg(f), 1e-9) << f;
  EXPECT_DOUBLE_EQ(read.placement.encoder_counts_per_rev, 64.0);
}

class ProfileLayouts : public ::testing::TestWithParam<ScanFormat> {};

TEST_P(ProfileLayouts, ReadBackTheSimulatedReadingsExactly) {
  const ProfileScan simulated = SmallSimulatedScan();
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) /
                                     (std::string("profile_") + std::string(InfoOf(GetParam()).name) +
                                      (GetParam() == ScanFormat::kProfileHdf5 ? ".h5" : ".csv"));
  WriteProfileScan(simulated, GetParam(), path);
  const ScanSettingsFile settings = Settings(ProfileScanSettingsJson(simulated));
  // Read by its named layout, and by what `process` finds in the file (ReadAnyScan).
  ReadOptions options;
  options.settings = &settings;
  std::variant<Scan, ProfileScan> found = ReadAnyScan(path, options);
  ASSERT_TRUE(std::holds_alternative<ProfileScan>(found));
  for (const ProfileScan& read :
       {ReadProfileScan(path, GetParam(), &settings), std::get<ProfileScan>(found)}) {
    ExpectReadBackExactly(read, simulated);
  }
  std::filesystem::remove(path);
}

TEST(ReadAnyScan, ReadsAHelicalScanAsOne) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / "any_helix.h5";
  ScanSettings settings;
  settings.sample_period_s = 1e-3;
  settings.feed_mm_per_min = 600.0;
  const Scan simulated = SimulateScan(PaperTestWheel(), settings).scan;
  WriteScan(simulated, /*float32=*/false, path);
  std::variant<Scan, ProfileScan> found = ReadAnyScan(path);
  ASSERT_TRUE(std::holds_alternative<Scan>(found));
  const std::vector<double>& z_mm = std::get<Scan>(found).z_mm;
  ASSERT_EQ(z_mm.size(), simulated.z_mm.size());
  for (std::size_t i = 0; i < z_mm.size(); ++i) {
    if (std::isnan(simulated.z_mm[i])) {
      EXPECT_TRUE(std::isnan(z_mm[i])) << i;
    } else {
      EXPECT_EQ(z_mm[i], simulated.z_mm[i]) << i;
    }
  }
  std::filesystem::remove(path);
}

INSTANTIATE_TEST_SUITE_P(AllLayouts, ProfileLayouts,
                         ::testing::Values(ScanFormat::kProfileHdf5, ScanFormat::kGocator,
                                           ScanFormat::kKeyenceLj));

TEST(ProfileHdf5Reader, RefusesXColumnsThatChangeBetweenFrames) {
  const std::filesystem::path path = std::filesystem::path(::testing::TempDir()) / "profile_x_changes.h5";
  {
    hdf5::File file = hdf5::File::Create(path);
    file.CreateGroup("/profile");
    std::vector<double> z(3 * 10, 1.0), x(3 * 10);
    for (std::size_t i = 0; i < x.size(); ++i) x[i] = static_cast<double>(i % 10);
    x[2 * 10 + 4] = 4.5;
    file.WriteDoubles("/profile/z", z, {3, 10});
    file.WriteDoubles("/profile/x_mm", x, {3, 10});
    file.WriteAttribute("/profile", "spindle_rpm", 500.0);
    file.WriteAttribute("/profile", "sample_period_s", 0.001);
  }
  try {
    (void)ReadProfileScan(path, ScanFormat::kProfileHdf5);
    FAIL() << "accepted X columns that change";
  } catch (const Error& e) {
    EXPECT_THAT(e.what(), HasSubstr("frame 2 column 4"));
  }
  std::filesystem::remove(path);
}

}  // namespace
}  // namespace arcwheel::acquisition
