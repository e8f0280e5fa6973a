// Scans as other tools write them: h5py and pandas (tests/foreign/write_scans.py, run here at test
// time with Debian's python3-h5py and python3-pandas) write one simulated scan's samples in every
// layout formats.md 2 allows. Each must read to exactly the samples and numbers of the plain file,
// with its text metadata byte-exact; the bad ones must be refused naming the file and the reason.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <nlohmann/json.hpp>
#include <string>
#include <variant>

#include "acquisition/profile_scan.h"
#include "acquisition/scan_reader.h"
#include "core/error.h"
#include "core/sha256.h"
#include "core/testing/json_file.h"
#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using acquisition::Scan;
using nlohmann::json;
using testing::RunArcwheel;
using testing::TempDir;

using testing::ReadJson;

// One simulated scan with an encoder column (and dropouts, so that NaN samples travel through every
// writer) and its foreign copies, made once for the whole suite.
class ForeignFiles : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = std::make_unique<TempDir>();
    const auto sim = RunArcwheel("simulate " + Base().string() +
                                 " --seed 11 --noise-um 0.3 --dropout-rate 0.001 "
                                 "--radial-harmonic 1:3 --encoder");
    ASSERT_EQ(sim.exit_status, 0) << sim.output;
    const std::string command = "/usr/bin/python3 " +
                                (testing::SourceDir() / "tests/foreign/write_scans.py").string() + " " +
                                Base().string() + " " + (*dir_ / "foreign").string() + " > " +
                                (*dir_ / "writer.log").string() + " 2>&1";
    const int status = std::system(command.c_str());
    std::ifstream log(*dir_ / "writer.log");
    const std::string output((std::istreambuf_iterator<char>(log)), std::istreambuf_iterator<char>());
    ASSERT_EQ(status, 0) << command << "\n" << output;
    expected_ = ReadJson(*dir_ / "foreign" / "expected.json");
  }
  static void TearDownTestSuite() { dir_.reset(); }

  static std::filesystem::path Base() { return *dir_ / "plain.h5"; }
  static std::filesystem::path Good(const std::string& name) { return *dir_ / "foreign" / "good" / name; }
  static std::filesystem::path Bad(const std::string& name) { return *dir_ / "foreign" / "bad" / name; }

  static std::unique_ptr<TempDir> dir_;
  static json expected_;
};

std::unique_ptr<TempDir> ForeignFiles::dir_;
json ForeignFiles::expected_;

bool SameSample(double a, double b) { return (std::isnan(a) && std::isnan(b)) || a == b; }

void ExpectSameColumn(const std::vector<double>& got, const std::vector<double>& want,
                      const std::string& what) {
  ASSERT_EQ(got.size(), want.size()) << what;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < got.size(); ++i) differ += SameSample(got[i], want[i]) ? 0 : 1;
  EXPECT_EQ(differ, 0u) << what << ": samples that differ";
}

void ExpectSameNumbers(const acquisition::ScanMetadata& got, const acquisition::ScanMetadata& want,
                       const std::string& name) {
  EXPECT_EQ(got.spindle_rpm, want.spindle_rpm) << name;
  EXPECT_EQ(got.feed_mm_per_min, want.feed_mm_per_min) << name;
  EXPECT_EQ(got.sample_period_s, want.sample_period_s) << name;
  EXPECT_EQ(got.radius_sign, want.radius_sign) << name;
  EXPECT_EQ(got.start_y_mm, want.start_y_mm) << name;
  EXPECT_EQ(got.start_phase_deg, want.start_phase_deg) << name;
  EXPECT_EQ(got.range_min_mm, want.range_min_mm) << name;
  EXPECT_EQ(got.range_max_mm, want.range_max_mm) << name;
  EXPECT_EQ(got.wheel_diameter_mm, want.wheel_diameter_mm) << name;
  EXPECT_EQ(got.wheel_width_mm, want.wheel_width_mm) << name;
}

bool HasNote(const Scan& scan, const std::string& text) {
  for (const std::string& note : scan.metadata.notes) {
    if (note.find(text) != std::string::npos) return true;
  }
  return false;
}

// `arcwheel process` keeps float32 readings as float32 (half the memory): widened, they must be
// the very samples of a plain read, whatever the writer did (byte order, chunks, filters).
TEST_F(ForeignFiles, Float32ReadingsKeptAsFloatAreTheSamplesOfAPlainRead) {
  int kept_as_float = 0;
  for (const auto& [name, expected] : expected_.items()) {
    if (!expected.contains("text") || std::filesystem::path(name).extension() != ".h5") continue;
    SCOPED_TRACE(name);
    const Scan plain = acquisition::ReadScan(Good(name));
    acquisition::ReadOptions keep;
    keep.keep_float32 = true;
    Scan kept = acquisition::ReadScan(Good(name), keep);
    kept_as_float += kept.holds_float() ? 1 : 0;
    EXPECT_EQ(kept.CountValid(), plain.CountValid());
    kept.WidenToDouble();
    ExpectSameColumn(kept.z_mm, plain.z_mm, "z");
    ExpectSameColumn(kept.t_s, plain.t_s, "t");
  }
  EXPECT_GE(kept_as_float, 3) << "h5py's float32 variants (plain, big-endian, compressed) stay float32";
}

// Whether `path` is mapped into this process (/proc/self/maps names the file of each mapping).
bool MappedHere(const std::filesystem::path& path) {
  std::ifstream maps("/proc/self/maps");
  const std::string canonical = std::filesystem::canonical(path).string();
  for (std::string line; std::getline(maps, line);) {
    if (line.size() >= canonical.size() && line.ends_with(canonical)) return true;
  }
  return false;
}

// h5py's contiguous float32 readings are not copied: the reader maps the file's own pages, past a
// user block, and marks the sensor's invalid readings (its sentinel, readings beyond its range) in
// this process's copies of the pages it writes, never in the file.
TEST_F(ForeignFiles, ContiguousFloat32IsMappedFromTheFileWhichStaysAsItWas) {
  const Scan plain = acquisition::ReadScan(Base());
  for (const std::string name : {"user_block.h5", "float32_sentinel.h5", "fixed_utf8.h5"}) {
    SCOPED_TRACE(name);
    const std::string before = Sha256OfFile(Good(name));
    {
      acquisition::ReadOptions keep;
      keep.keep_float32 = true;
      Scan kept = acquisition::ReadScan(Good(name), keep);
      ASSERT_TRUE(kept.holds_float());
      EXPECT_TRUE(MappedHere(Good(name))) << "the readings were copied, not mapped";
      kept.WidenToDouble();
      ExpectSameColumn(kept.z_mm, plain.z_mm, "z");
    }
    EXPECT_FALSE(MappedHere(Good(name))) << "the mapping outlived the scan";
    EXPECT_EQ(Sha256OfFile(Good(name)), before) << "the reader wrote into the file";
  }
}

TEST_F(ForeignFiles, EveryVariantReadsToTheSamplesNumbersAndTextOfThePlainFile) {
  const Scan plain = acquisition::ReadScan(Base());
  ASSERT_GT(plain.size() - plain.CountValid(), 50u) << "the scan must carry invalid samples";
  ASSERT_TRUE(plain.has_encoder());
  int checked = 0;
  for (const auto& [name, expected] : expected_.items()) {
    if (!expected.contains("text")) continue;
    SCOPED_TRACE(name);
    const Scan scan = acquisition::ReadScan(Good(name));
    if (expected.contains("quantum_mm")) {
      // Integer counts: the samples within half a count of the plain ones, invalid ones the same.
      const double half = 0.5 * expected["quantum_mm"].get<double>() + 1e-12;
      ASSERT_EQ(scan.size(), plain.size());
      std::size_t off = 0;
      for (std::size_t i = 0; i < scan.size(); ++i) {
        off += (std::isnan(plain.z_mm[i]) ? std::isnan(scan.z_mm[i])
                                          : std::abs(scan.z_mm[i] - plain.z_mm[i]) <= half)
                   ? 0
                   : 1;
      }
      EXPECT_EQ(off, 0u);
    } else {
      ExpectSameColumn(scan.z_mm, plain.z_mm, "z");
    }
    if (!expected.contains("z_only")) {
      ExpectSameColumn(scan.t_s, plain.t_s, "t");
      ExpectSameColumn(scan.angle_deg, plain.angle_deg, "angle");
      ExpectSameColumn(scan.y_mm, plain.y_mm, "y");
    }
    ExpectSameNumbers(scan.metadata, plain.metadata, name);
    EXPECT_EQ(scan.metadata.wheel_id, expected["text"]["wheel_id"].get<std::string>());
    EXPECT_EQ(scan.metadata.sensor, expected["text"]["sensor"].get<std::string>());
    EXPECT_EQ(scan.metadata.operator_name, expected["text"]["operator"].get<std::string>());
    EXPECT_EQ(scan.metadata.timestamp, expected["text"]["timestamp"].get<std::string>());
    if (expected.contains("warning")) {
      EXPECT_TRUE(HasNote(scan, expected["warning"].get<std::string>())) << expected["warning"];
    } else if (name == "pandas_defaults.csv") {
      EXPECT_TRUE(HasNote(scan, "column 1 has no name"));
    } else {
      EXPECT_TRUE(scan.metadata.notes.empty()) << scan.metadata.notes.front();
    }
    ++checked;
  }
  EXPECT_GE(checked, 27);
}

// summary.json without what names the file it came from.
json Numbers(const std::filesystem::path& summary) {
  json s = ReadJson(summary);
  s.erase("input");
  s.erase("warnings");
  for (const char* key : {"wheel_id", "sensor", "operator", "timestamp"}) s["scan"].erase(key);
  return s;
}

TEST_F(ForeignFiles, H5pyDefaultsAndPandasProcessToExactlyTheNumbersOfThePlainFile) {
  TempDir out;
  ASSERT_EQ(RunArcwheel("process -q " + Base().string() + " -o " + (out / "plain").string()).exit_status, 0);
  const json plain = Numbers(out / "plain" / "summary.json");
  for (const std::string name : {"h5py_defaults.h5", "lzf.h5", "mixed_case_keys.h5", "pandas_defaults.csv",
                                 "excel_bom_crlf.csv", "quoted_tab_crlf.csv"}) {
    SCOPED_TRACE(name);
    const auto run = RunArcwheel("process -q " + Good(name).string() + " -o " + (out / name).string());
    ASSERT_EQ(run.exit_status, 0) << run.output;
    EXPECT_EQ(Numbers(out / name / "summary.json"), plain);
    const json summary = ReadJson(out / name / "summary.json");
    for (const char* key : {"wheel_id", "sensor", "operator", "timestamp"}) {
      EXPECT_EQ(summary["scan"][key].get<std::string>(), expected_[name]["text"][key].get<std::string>())
          << key;
    }
  }
  // The key arcwheel does not use is in the summary's warnings, not dropped unseen.
  const json mixed = ReadJson(out / "mixed_case_keys.h5" / "summary.json");
  ASSERT_FALSE(mixed["warnings"].empty());
  EXPECT_NE(mixed["warnings"][0].get<std::string>().find("'Comment'"), std::string::npos)
      << mixed["warnings"];
}

TEST_F(ForeignFiles, Latin1MetadataBecomesValidUtf8AndTheSummarySaysSo) {
  TempDir out;
  for (const std::string name : {"latin1_operator.h5", "latin1_metadata.csv"}) {
    const auto run = RunArcwheel("process -q " + Good(name).string() + " -o " + (out / name).string());
    ASSERT_EQ(run.exit_status, 0) << run.output;
    const json summary = ReadJson(out / name / "summary.json");  // parses: valid UTF-8
    EXPECT_EQ(summary["scan"]["operator"].get<std::string>(), "M\xC3\xBCller") << name;
    EXPECT_NE(summary["warnings"].dump().find("read as Latin-1"), std::string::npos) << name;
  }
}

TEST_F(ForeignFiles, APathInALegacyEncodingStillGivesAValidUtf8Summary) {
  TempDir out;
  const std::filesystem::path latin1 = out / "M\xFCller.csv";  // as a Latin-1 file system names it
  std::filesystem::copy_file(Good("pandas_no_index.csv"), latin1);
  const auto run = RunArcwheel("process -q '" + latin1.string() + "' -o " + (out / "x").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const json summary = ReadJson(out / "x" / "summary.json");
  EXPECT_EQ(summary["input"]["path"].get<std::string>(), (out / "M\xC3\xBCller.csv").string());
}

TEST_F(ForeignFiles, BadVariantsAreRefusedNamingTheFileAndTheReasonAndWriteNothing) {
  TempDir out;
  int refused = 0;
  for (const auto& [name, expected] : expected_.items()) {
    if (!expected.contains("refusal")) continue;
    SCOPED_TRACE(name);
    const auto run = RunArcwheel("process -q " + Bad(name).string() + " -o " + (out / name).string());
    EXPECT_EQ(run.exit_status, 3) << run.output;
    EXPECT_NE(run.output.find(Bad(name).string()), std::string::npos) << run.output;
    EXPECT_NE(run.output.find(expected["refusal"].get<std::string>()), std::string::npos) << run.output;
    EXPECT_FALSE(std::filesystem::exists(out / name / "summary.json"));
    ++refused;
  }
  EXPECT_EQ(refused, 4);
}

TEST_F(ForeignFiles, AFilterThisHdf5CannotDecodeIsNamed) {
  TempDir out, no_plugins;
  ::setenv("HDF5_PLUGIN_PATH", no_plugins.path().c_str(), 1);  // as on a machine without hdf5-plugin-lzf
  const auto run = RunArcwheel("process -q " + Good("lzf.h5").string() + " -o " + (out / "x").string());
  ::unsetenv("HDF5_PLUGIN_PATH");
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_NE(run.output.find(Good("lzf.h5").string() + "' /scan/z is compressed with HDF5 filter 32000 'lzf'"),
            std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("hdf5-plugin-lzf"), std::string::npos) << run.output;
  EXPECT_FALSE(std::filesystem::exists(out / "x"));
}

// A line-profile scan as h5py writes it (gzip-chunked /profile/z, variable-length UTF-8 text):
// `process` tells it by its /profile group in the one child that reads it, and the values come back
// exactly as the script made them (z = (p - f) / 8 mm, exact in binary; frame 3 point 5 NaN).
TEST(ForeignProfileFiles, AnH5pyProfileScanIsToldByItsGroupAndReadExactly) {
  TempDir dir;
  const std::filesystem::path path = dir / "profile_h5py.h5";
  constexpr int kFrames = 40, kPoints = 24;
  const std::string script =
      "import h5py, numpy as np\n"
      "f, p = np.meshgrid(np.arange(" +
      std::to_string(kFrames) + "), np.arange(" + std::to_string(kPoints) +
      "), indexing='ij')\n"
      "z = (p - f) / 8.0\n"
      "z[3, 5] = np.nan\n"
      "with h5py.File('" +
      path.string() +
      "', 'w') as h:\n"
      "    g = h.create_group('profile')\n"
      "    g.create_dataset('z', data=z, compression='gzip', chunks=True)\n"
      "    g.create_dataset('x_mm', data=np.arange(" +
      std::to_string(kPoints) +
      ") * 0.5 - 6.0)\n"
      "    g.create_dataset('t', data=np.arange(" +
      std::to_string(kFrames) +
      ") * 0.001)\n"
      "    g.attrs['spindle_rpm'] = 500.0\n"
      "    g.attrs['wheel_id'] = 'R\u00e4d 7'\n";
  { std::ofstream(dir / "write.py") << script; }
  const std::string command = "/usr/bin/python3 " + (dir / "write.py").string() + " 2>&1";
  ASSERT_EQ(std::system(command.c_str()), 0) << script;

  std::variant<Scan, acquisition::ProfileScan> found = acquisition::ReadAnyScan(path);
  ASSERT_TRUE(std::holds_alternative<acquisition::ProfileScan>(found));
  const acquisition::ProfileScan& scan = std::get<acquisition::ProfileScan>(found);
  ASSERT_EQ(scan.frames(), static_cast<std::size_t>(kFrames));
  ASSERT_EQ(scan.points(), static_cast<std::size_t>(kPoints));
  for (int p = 0; p < kPoints; ++p) EXPECT_EQ(scan.x_mm[static_cast<std::size_t>(p)], p * 0.5 - 6.0) << p;
  for (int f = 0; f < kFrames; ++f) {
    for (int p = 0; p < kPoints; ++p) {
      const double z = scan.z_mm[static_cast<std::size_t>(f * kPoints + p)];
      if (f == 3 && p == 5) {
        EXPECT_TRUE(std::isnan(z));
      } else {
        EXPECT_EQ(z, (p - f) / 8.0) << f << ", " << p;
      }
    }
  }
  EXPECT_EQ(scan.metadata.spindle_rpm, 500.0);
  EXPECT_EQ(scan.metadata.wheel_id, "R\u00e4d 7");
}

}  // namespace
}  // namespace arcwheel
