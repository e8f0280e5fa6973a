// Scans as the sensors' software writes them (formats.md 2.4): the settings the files lack, given
// from outside (`--scan-settings`), and the refusals, through the binary as a user runs it.

#include <fmt/core.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "acquisition/simulate.h"
#include "core/testing/json_file.h"
#include "core/testing/testing.h"

namespace arcwheel {
namespace {

using testing::RunArcwheel;
using testing::TempDir;
using testing::WriteText;

using testing::ReadJson;

// A contract CSV of a simulated wheel whose `# key: value` lines lack `drop` (one or more keys).
std::filesystem::path CsvWithout(const TempDir& dir, const std::string& name, const std::string& drop) {
  const std::filesystem::path full = dir / (name + ".full.csv");
  EXPECT_EQ(RunArcwheel("simulate " + full.string() + " --feed-mm-per-min 400").exit_status, 0);
  std::ifstream in(full);
  std::string text, line;
  while (std::getline(in, line)) {
    if (line.starts_with('#') && drop.find(line.substr(2, line.find(':') - 2)) != std::string::npos) continue;
    text += line + "\n";
  }
  const std::filesystem::path path = dir / (name + ".csv");
  WriteText(path, text);
  return path;
}

TEST(ScanSettings, FillWhatTheFileLacksAndTheSummarySaysWhereEachCameFrom) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "spindle_rpm sample_period_s");
  WriteText(dir / "settings.json",
            R"({"spindle_rpm": 500, "sample_period_s": 0.0001, "operator": "E. Abbe"})");
  const auto run = RunArcwheel("process -q --no-model " + scan.string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto s = ReadJson(dir / "out" / "summary.json");
  const auto& input = s["input"];
  EXPECT_EQ(input["scan_settings"], (dir / "settings.json").string());
  EXPECT_EQ(input["sources"]["spindle_rpm"], "settings");
  EXPECT_EQ(input["sources"]["sample_period_s"], "settings");
  EXPECT_EQ(input["sources"]["operator"], "settings");
  EXPECT_EQ(input["sources"]["feed_mm_per_min"], "file");
  EXPECT_EQ(s["scan"]["operator"], "E. Abbe");
  EXPECT_NEAR(s["mean_arc_radius_mm"].get<double>(), 55.4423, 1e-6);  // no noise: the text's 1 nm digits
}

TEST(ScanSettings, AMissingSettingIsNamedWithTheKeyThatSuppliesIt) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "spindle_rpm");
  const auto run = RunArcwheel("process -q " + scan.string() + " -o " + (dir / "out").string());
  EXPECT_EQ(run.exit_status, 3) << run.output;
  EXPECT_NE(run.output.find("lacks spindle_rpm (and has no angle column): give \"spindle_rpm\" in the file's "
                            "metadata or in --scan-settings"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ScanSettings, AValueThatContradictsTheFileIsRefusedNamingBoth) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "sample_period_s");
  WriteText(dir / "settings.json", R"({"spindle_rpm": 600, "sample_period_s": 0.0001})");
  const auto run = RunArcwheel("process -q " + scan.string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_NE(run.output.find("spindle_rpm contradicts the scan: '" + (dir / "settings.json").string() +
                            "' gives spindle_rpm = 600, '" + scan.string() + "' gives spindle_rpm = 500"),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

TEST(ScanSettings, TheSameValueAsTheFileIsNoContradiction) {
  TempDir dir;
  const auto scan = CsvWithout(dir, "scan", "sample_period_s");
  WriteText(dir / "settings.json", R"({"spindle_rpm": 500.0, "sample_period_s": 1e-4})");
  const auto run = RunArcwheel("process -q --no-model " + scan.string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  EXPECT_EQ(ReadJson(dir / "out" / "summary.json")["input"]["sources"]["spindle_rpm"], "file");
}

TEST(ScanSettings, AnUnknownKeyOrAWrongTypeIsRefusedBeforeTheScanIsRead) {
  TempDir dir;
  WriteText(dir / "scan.csv", "never read\n");
  WriteText(dir / "settings.json", R"({"spindle_speed": 500, "feed_mm_per_min": "100"})");
  const auto run = RunArcwheel("process -q " + (dir / "scan.csv").string() + " -o " + (dir / "out").string() +
                               " --scan-settings " + (dir / "settings.json").string());
  EXPECT_EQ(run.exit_status, 2) << run.output;
  EXPECT_NE(run.output.find("'feed_mm_per_min' must be a number, got \"100\""), std::string::npos)
      << run.output;
  EXPECT_NE(run.output.find("'spindle_speed' is not a scan setting (expected spindle_rpm, "),
            std::string::npos)
      << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

// --- Each sensor's layout, written here as its documentation shows it ---------------------------
//
// A simulated wheel with known truth; its readings written by this test in the sensor's own layout
// (literal header lines, the sensor's separators, decimal comma, markers, CRLF, BOM), and the very
// same samples (the text's digits, the markers' samples NaN) written to the contract's HDF5.
// `process` must find the truth within its U from the sensor's file with --scan-settings, and the
// same numbers, to 1e-9 relative, from the HDF5.

struct SimulatedWheel {
  acquisition::WheelModel wheel = acquisition::LobedTestWheel();
  acquisition::ScanSettings settings;
  acquisition::SimulatedScan simulated;
  double mean_arc_radius_mm = 0.0;  // the truth: Ra(c) averaged over the turn

  SimulatedWheel() {
    settings.feed_mm_per_min = 400.0;  // 33001 samples
    settings.noise_um = 0.3;
    settings.dropout_rate = 2e-4;  // dropouts inside the rim: the sensors' alarm markers
    settings.dropout_length_max = 5;
    settings.seed = 20261205;  // fixed: a failure must reproduce
    simulated = acquisition::SimulateScan(wheel, settings);
    for (int k = 0; k < 3600; ++k) mean_arc_radius_mm += wheel.ArcRadiusMm(k * 0.1) / 3600.0;
  }
  [[nodiscard]] const std::vector<double>& z() const { return simulated.scan.z_mm; }
  // The first and the last valid sample: the sensor sees no rim outside them.
  [[nodiscard]] std::pair<std::size_t, std::size_t> RimSpan() const {
    std::size_t first = z().size(), last = 0;
    for (std::size_t i = 0; i < z().size(); ++i) {
      if (std::isfinite(z()[i])) {
        first = std::min(first, i);
        last = i;
      }
    }
    return {first, last};
  }
};

const SimulatedWheel& Wheel() {
  static const SimulatedWheel wheel;
  return wheel;
}

// What the file lacks, as a user writes it.
std::string SettingsJson(bool with_period) {
  const auto& s = Wheel().settings;
  std::string json = fmt::format(
      "{{\n  \"spindle_rpm\": {},\n  \"feed_mm_per_min\": {},\n  \"start_y_mm\": {},\n  \"start_phase_deg\": "
      "0,\n"
      "  \"radius_sign\": 1,\n  \"wheel_id\": \"W-0815\"",
      s.spindle_rpm_nominal, s.feed_mm_per_min, s.start_y_mm);
  if (with_period) json += fmt::format(",\n  \"sample_period_s\": {}", s.sample_period_s);
  return json + "\n}\n";
}

double Parse(std::string text) {
  std::replace(text.begin(), text.end(), ',', '.');
  return std::strtod(text.c_str(), nullptr);
}

// The samples as the contract's HDF5 holds them: the text's values, NaN for every marker.
void WriteContractHdf5(const std::filesystem::path& path, const std::vector<double>& z,
                       const std::vector<double>& t) {
  acquisition::Scan scan;
  scan.metadata = Wheel().simulated.scan.metadata;
  scan.z_mm = z;
  scan.t_s = t;
  acquisition::WriteHdf5Scan(scan, /*float32=*/false, path.string());
}

struct Layout {
  std::string name;
  std::string format;  // summary.json's input.format
  std::string file;
  bool settings_with_period = false;
  std::string period_source;  // summary.json's input.sources.sample_period_s ("none": a time column)
  std::string extra_options;
  // Writes the file; returns the samples as the contract holds them (z, and t when the file's time
  // column is used) and the markers written, by kind.
  std::function<void(const std::filesystem::path&, std::vector<double>&, std::vector<double>&,
                     std::map<std::string, std::size_t>&)>
      write;
};

void WriteSensorTool(const std::filesystem::path& path, std::vector<double>& z, std::vector<double>& t,
                     std::map<std::string, std::size_t>& markers) {
  // sensorTOOL's CSV export in a German locale: BOM, header lines, `;`, decimal comma, CRLF; a
  // sample without a valid distance is an empty cell.
  std::string text =
      "\xEF\xBB\xBFsensorTOOL;1.9.0\r\n"
      "Sensor;ILD2300\r\n"
      "Serial number;1234567\r\n"
      "Date;13.09.2017 10:00:00\r\n"
      "Measuring rate;10 kHz\r\n"
      "Acquisition time;Epoch time (ms);Distance1 (mm)\r\n";
  for (std::size_t i = 0; i < Wheel().z().size(); ++i) {
    std::string time = fmt::format("{:.4f}", static_cast<double>(i) * 1e-4);
    std::string distance = std::isfinite(Wheel().z()[i]) ? fmt::format("{:.6f}", Wheel().z()[i]) : "";
    t.push_back(Parse(time));
    z.push_back(distance.empty() ? NAN : Parse(distance));
    if (distance.empty()) ++markers["empty"];
    std::replace(time.begin(), time.end(), '.', ',');
    std::replace(distance.begin(), distance.end(), '.', ',');
    text += fmt::format("{};{};{}\r\n", time, 1505296800000 + i / 10, distance);
  }
  WriteText(path, text);
}

// A Keyence LK value: a sign and 7 characters; the markers as the controller sends them.
std::string LkValue(std::size_t i, std::vector<double>& z, std::map<std::string, std::size_t>& markers) {
  const auto [first, last] = Wheel().RimSpan();
  const double reading = Wheel().z()[i];
  std::string value;
  if (std::isfinite(reading)) {
    value = fmt::format("{:+08.4f}", reading);
    z.push_back(Parse(value));
    return value;
  }
  z.push_back(NAN);
  const auto mark = [&](const char* kind, const char* text) {
    ++markers[kind];
    return std::string(text);
  };
  if (i < 3) return mark("waiting", "-------");
  if (i < first) return mark("out_of_range_low", "-FFFFFFF");
  if (i > last) return mark("out_of_range_high", "+FFFFFFF");
  return mark("alarm", "XXXXXXXX");
}

void WriteKeyenceStream(const std::filesystem::path& path, std::vector<double>& z, std::vector<double>&,
                        std::map<std::string, std::size_t>& markers) {
  // The controller's RS-232C output as logged: one fixed-width value a line, CR LF.
  std::string text;
  for (std::size_t i = 0; i < Wheel().z().size(); ++i) text += LkValue(i, z, markers) + "\r\n";
  WriteText(path, text);
}

void WriteLkNavigator(const std::filesystem::path& path, std::vector<double>& z, std::vector<double>&,
                      std::map<std::string, std::size_t>& markers) {
  // LK-Navigator's CSV export: header lines, the column row, the values as the controller sends them.
  std::string text =
      "LK-Navigator 2\r\n"
      "Model,LK-G5001\r\n"
      "Sampling cycle,100us\r\n"
      "Date,2017/09/13 10:00:00\r\n"
      "No.,OUT1(mm)\r\n";
  for (std::size_t i = 0; i < Wheel().z().size(); ++i)
    text += fmt::format("{},{}\r\n", i + 1, LkValue(i, z, markers));
  WriteText(path, text);
}

void WriteLabLogger(const std::filesystem::path& path, std::vector<double>& z, std::vector<double>& t,
                    std::map<std::string, std::size_t>& markers) {
  // Any other program: a title line, tab separators with a trailing tab, decimal comma, um and ms.
  std::string text = "Messung 7 Schleifscheibe\nZeit [ms]\tWeg [\xC2\xB5m]\t\n";
  for (std::size_t i = 0; i < Wheel().z().size(); ++i) {
    std::string time = fmt::format("{:.1f}", static_cast<double>(i) * 0.1);
    std::string distance = std::isfinite(Wheel().z()[i]) ? fmt::format("{:.3f}", Wheel().z()[i] * 1e3) : "";
    t.push_back(Parse(time) / 1e3);
    z.push_back(distance.empty() ? NAN : Parse(distance) / 1e3);
    if (distance.empty()) ++markers["empty"];
    std::replace(time.begin(), time.end(), '.', ',');
    std::replace(distance.begin(), distance.end(), '.', ',');
    text += time + "\t" + distance + "\t\n";
  }
  WriteText(path, text);
}

class SensorLayout : public ::testing::TestWithParam<Layout> {};

TEST_P(SensorLayout, ProcessRecoversTheTruthAndTheContractHdf5GivesTheSameNumbers) {
  const Layout& layout = GetParam();
  TempDir dir;
  std::vector<double> z, t;
  std::map<std::string, std::size_t> markers;
  layout.write(dir / layout.file, z, t, markers);
  WriteText(dir / "settings.json", SettingsJson(layout.settings_with_period));
  WriteContractHdf5(dir / "contract.h5", z, t);

  const auto sensor =
      RunArcwheel("process -q " + (dir / layout.file).string() + " -o " + (dir / "sensor").string() +
                  " --scan-settings " + (dir / "settings.json").string() + layout.extra_options);
  ASSERT_EQ(sensor.exit_status, 0) << sensor.output;
  const auto contract =
      RunArcwheel("process -q " + (dir / "contract.h5").string() + " -o " + (dir / "contract").string());
  ASSERT_EQ(contract.exit_status, 0) << contract.output;
  const auto s = ReadJson(dir / "sensor" / "summary.json");
  const auto c = ReadJson(dir / "contract" / "summary.json");

  // What the reader read.
  EXPECT_EQ(s["input"]["format"], layout.format);
  EXPECT_EQ(s["input"]["samples"], Wheel().z().size());
  nlohmann::json expected_markers = nlohmann::json::object();
  for (const auto& [kind, count] : markers) expected_markers[kind] = count;
  EXPECT_EQ(s["input"]["invalid_markers"], expected_markers);
  EXPECT_EQ(s["input"]["sources"]["spindle_rpm"], "settings");
  EXPECT_EQ(s["input"]["sources"].value("sample_period_s", "none"), layout.period_source);
  EXPECT_EQ(s["scan"]["wheel_id"], "W-0815");

  // The truth within U (k = 2, the summary's own expanded uncertainty).
  const double mean = s["mean_arc_radius_mm"].get<double>();
  const double u = s["uncertainty"]["quantities"]["mean_arc_radius_mm"]["U"].get<double>();
  EXPECT_LE(std::abs(mean - Wheel().mean_arc_radius_mm), u) << "mean arc radius " << mean << " +- " << u;

  // The same samples from the contract's HDF5: the same numbers.
  EXPECT_EQ(s["input"]["valid_samples"], c["input"]["valid_samples"]);
  const auto same = [](double a, double b) {
    return std::abs(a - b) <= 1e-9 * std::max(std::abs(a), std::abs(b)) + 1e-300;
  };
  for (const char* key : {"mean_arc_radius_mm", "mean_arc_radius_sigma_mm", "arc_radius_range_mm",
                          "mean_center_axial_mm", "center_axial_deviation_mm", "max_arc_error_um",
                          "max_runout_um", "max_roundness_um", "spindle_rpm_estimated"}) {
    EXPECT_PRED2(same, s[key].get<double>(), c[key].get<double>()) << key;
  }
  const auto& sr = s["phases"]["arc_radius_mm"];
  const auto& cr = c["phases"]["arc_radius_mm"];
  ASSERT_EQ(sr.size(), cr.size());
  for (std::size_t k = 0; k < sr.size(); ++k)
    EXPECT_PRED2(same, sr[k].get<double>(), cr[k].get<double>()) << k;
}

INSTANTIATE_TEST_SUITE_P(
    AsTheirSoftwareWritesThem, SensorLayout,
    ::testing::Values(
        Layout{"SensorTool", "sensortool", "scan_export.csv", false, "file", "", WriteSensorTool},
        Layout{"KeyenceLkStream", "keyence-lk", "lk_log.txt", true, "settings", "", WriteKeyenceStream},
        Layout{"LkNavigator", "keyence-lk", "lk_navigator.csv", false, "file", "", WriteLkNavigator},
        Layout{"AnyDelimitedFile", "columns", "logger.txt", false, "none",
               " --columns 'z=Weg [\xC2\xB5m]:um,t=Zeit [ms]:ms'", WriteLabLogger}),
    [](const ::testing::TestParamInfo<Layout>& param_info) { return param_info.param.name; });

// The simulator writes the same layouts, with the settings they lack, for demonstrations.
TEST(SensorLayout, SimulateAsEachSensorThenProcessWithItsSettingsRecoversTheTruth) {
  TempDir dir;
  for (const std::string layout : {"sensortool", "keyence-lk"}) {
    const auto scan = dir / (layout + ".csv");
    const auto sim = RunArcwheel("simulate " + scan.string() + " --as " + layout +
                                 " --feed-mm-per-min 400 --noise-um 0.3");
    ASSERT_EQ(sim.exit_status, 0) << sim.output;
    const auto run = RunArcwheel("process -q --no-model " + scan.string() + " -o " + (dir / layout).string() +
                                 " --scan-settings " + scan.string() + ".settings.json");
    ASSERT_EQ(run.exit_status, 0) << run.output;
    const auto s = ReadJson(dir / layout / "summary.json");
    EXPECT_EQ(s["input"]["format"], layout);
    EXPECT_LE(std::abs(s["mean_arc_radius_mm"].get<double>() - 55.4423),
              s["uncertainty"]["quantities"]["mean_arc_radius_mm"]["U"].get<double>());
  }
}

// `batch` passes --scan-settings to every scan, and reuses a finished scan only while the settings
// file is unchanged.
TEST(ScanSettings, BatchPassesThemToEveryScanAndAnEditedFileRunsThemAgain) {
  TempDir dir;
  for (const std::string name : {"wheel_a", "wheel_b"}) {
    ASSERT_EQ(
        RunArcwheel("simulate " + (dir / (name + ".csv")).string() +
                    " --as keyence-lk --feed-mm-per-min 400 --settings " + (dir / "settings.json").string())
            .exit_status,
        0);
  }
  const std::string batch = "batch " + (dir / "wheel_a.csv").string() + " " + (dir / "wheel_b.csv").string() +
                            " -o " + (dir / "out").string() + " -- --no-model --scan-settings " +
                            (dir / "settings.json").string();
  const auto first = RunArcwheel(batch);
  ASSERT_EQ(first.exit_status, 0) << first.output;
  EXPECT_NE(first.output.find("2 done, 0 reused, 0 failed"), std::string::npos) << first.output;
  EXPECT_EQ(ReadJson(dir / "out" / "wheel_a" / "summary.json")["input"]["sources"]["spindle_rpm"],
            "settings");
  const auto again = RunArcwheel(batch);
  EXPECT_NE(again.output.find("0 done, 2 reused, 0 failed"), std::string::npos) << again.output;
  std::string edited = testing::ReadText(dir / "settings.json");
  const std::string simulated = "\"simulated\"";  // the wheel id the simulator writes
  ASSERT_NE(edited.find(simulated), std::string::npos) << edited;
  edited.replace(edited.find(simulated), simulated.size(), "\"edited\"");
  WriteText(dir / "settings.json", edited);
  const auto edited_run = RunArcwheel(batch);
  EXPECT_NE(edited_run.output.find("2 done, 0 reused, 0 failed"), std::string::npos) << edited_run.output;
  EXPECT_EQ(ReadJson(dir / "out" / "wheel_b" / "summary.json")["scan"]["wheel_id"], "edited");
}

// `regenerate` reads the scan as `process` does, and redoes the wheel when the settings change.
TEST(ScanSettings, RegenerateReadsASensorsFileWithThem) {
  TempDir dir;
  const auto scan = dir / "dressed.csv";
  ASSERT_EQ(RunArcwheel("simulate " + scan.string() + " --as sensortool --feed-mm-per-min 400").exit_status,
            0);
  const std::string regenerate =
      "regenerate --scan " + scan.string() + " --scan-settings " + scan.string() + ".settings.json --job " +
      (testing::SourceDir() / "grinding" / "examples" / "trial_part.json").string() + " -o " +
      (dir / "out").string();
  const auto run = RunArcwheel(regenerate);
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto s = ReadJson(dir / "out" / "wheel" / "summary.json");
  EXPECT_EQ(s["input"]["format"], "sensortool");
  EXPECT_EQ(s["input"]["sources"]["spindle_rpm"], "settings");
  EXPECT_NE(RunArcwheel(regenerate).output.find("step 1/4 wheel: inputs unchanged"), std::string::npos);
  WriteText(scan.string() + ".settings.json",
            R"({"spindle_rpm": 500, "feed_mm_per_min": 400, "start_y_mm": -11})");
  const auto again = RunArcwheel(regenerate);
  ASSERT_EQ(again.exit_status, 0) << again.output;
  EXPECT_EQ(again.output.find("step 1/4 wheel: inputs unchanged"), std::string::npos) << again.output;
}

// --- Refusals: the file, the line and the column (or the key) named; nothing written -------------

struct SensorFileRefusal {
  std::string name;
  std::string file;
  std::string text;
  std::string settings;  // settings JSON; empty: none given
  std::string options;
  int exit_status;
  std::string message;  // with {file} standing for the scan's path, {settings} for the settings'
};

class SensorRefusal : public ::testing::TestWithParam<SensorFileRefusal> {};

TEST_P(SensorRefusal, NamesTheProblemExitsAndWritesNothing) {
  const SensorFileRefusal& r = GetParam();
  TempDir dir;
  const auto scan = dir / r.file;
  WriteText(scan, r.text);
  std::string options = r.options;
  if (!r.settings.empty()) {
    WriteText(dir / "settings.json", r.settings);
    options += " --scan-settings " + (dir / "settings.json").string();
  }
  const auto run =
      RunArcwheel("process -q " + scan.string() + " -o " + (dir / "out").string() + " " + options);
  EXPECT_EQ(run.exit_status, r.exit_status) << run.output;
  std::string message = r.message;
  for (const auto& [placeholder, value] :
       {std::pair<std::string, std::string>{"{file}", scan.string()},
        std::pair<std::string, std::string>{"{settings}", (dir / "settings.json").string()}}) {
    if (const std::size_t at = message.find(placeholder); at != std::string::npos)
      message.replace(at, placeholder.size(), value);
  }
  EXPECT_NE(run.output.find(message), std::string::npos)
      << "expected: " << message << "\ngot: " << run.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "out"));
}

const char* kSensorToolHead =
    "sensorTOOL;1.9.0\r\nSensor;ILD2300\r\nMeasuring rate;10 kHz\r\nAcquisition time;Epoch time "
    "(ms);Distance1 (mm)\r\n";
const char* kSettings = R"({"spindle_rpm": 500, "feed_mm_per_min": 400})";

INSTANTIATE_TEST_SUITE_P(
    Cli, SensorRefusal,
    ::testing::Values(
        SensorFileRefusal{
            "AHeaderNoSniffClaims", "logger.txt", "Zeit;Weg\n0;1,5\n", kSettings, "", 3,
            "'{file}': its header is no format arcwheel knows; tried csv ('# key: value' lines or a z_mm "
            "column); sensortool (a 'sensorTOOL' line or a column row starting 'Acquisition time' or 'Epoch "
            "time (ms)'); gocator (a first section 'Info' whose header row starts 'CSV Version'); keyence-lj "
            "(a "
            "first row of at least 8 tab-separated numbers (the X block)); keyence-lk (an 'LK-Navigator' "
            "line "
            "or fixed-width values such as +01.2345 or -FFFFFFF). Force a reader with --format NAME (hdf5, "
            "csv, "
            "sensortool, gocator, keyence-lj, keyence-lk, columns or profile-hdf5)"},
        SensorFileRefusal{"AMissingColumn", "logger.txt", "Messung 7\nZeit;Weg\n0;1,5\n", kSettings,
                          "--columns z=Abstand", 3,
                          "acquisition.columns: '{file}': no line names the columns 'Abstand' (--columns)"},
        SensorFileRefusal{
            "AMissingColumnOverASensorsOwn", "export.csv", std::string(kSensorToolHead) + "0,0000;1;1,5\r\n",
            kSettings, "--format sensortool --columns z=Distance2", 3,
            "'{file}' line 4: no column 'Distance2' (--columns z=...); the column row names 'Acquisition "
            "time', "
            "'Epoch time (ms)', 'Distance1 (mm)'"},
        SensorFileRefusal{
            "AUnitThatDoesNotParse", "export.csv",
            "sensorTOOL;1.9.0\r\nAcquisition time;Distance1 (furlong)\r\n0,0000;1,5\r\n", kSettings, "", 3,
            "'{file}' line 2: column 'Distance1 (furlong)': unit 'furlong' is not one of z (mm, um or nm)"},
        SensorFileRefusal{"AUnitOfTheOptionThatDoesNotParse", "logger.txt", "Zeit;Weg\n0;1,5\n", kSettings,
                          "--columns z=Weg:inch", 2,
                          "--columns = 'z=Weg:inch' violates a unit of z: mm, um or nm"},
        SensorFileRefusal{
            "AnUnknownMarkerInSensorTool", "export.csv",
            std::string(kSensorToolHead) + "0,0000;1;1,5\r\n0,0001;1;n/a\r\n", kSettings, "", 3,
            "'{file}' line 6: column 'Distance1 (mm)': 'n/a' is neither a number nor an invalid marker this "
            "format knows (an empty cell or nan)"},
        SensorFileRefusal{
            "AnUnknownMarkerFromKeyence", "lk.txt", "+01.2345\r\n-FFFFFFF\r\n+0?.2345\r\n", kSettings, "", 3,
            "'{file}' line 3: column 'OUT1': '+0?.2345' is neither a number nor an invalid marker this "
            "format "
            "knows (an empty cell, nan, +FFFFFFF, -FFFFFFF, XXXXXXXX or -------)"},
        SensorFileRefusal{"ATimeThatGoesBackwards", "export.csv",
                          std::string(kSensorToolHead) + "0,0000;1;1,5\r\n0,0002;1;1,5\r\n0,0001;1;1,5\r\n",
                          kSettings, "", 3,
                          "'{file}' line 7: column 'Acquisition time': the time goes backwards"},
        SensorFileRefusal{
            "SettingsThatLeaveTheSamplePeriodUnknown", "lk.txt", "+01.2345\r\n+01.2346\r\n", kSettings, "", 3,
            "'{file}': lacks sample_period_s (and has no t column): give \"sample_period_s\" in the file's "
            "metadata or in --scan-settings SETTINGS.json"},
        SensorFileRefusal{"SettingsThatLeaveTheSpindleSpeedUnknown", "lk.txt", "+01.2345\r\n+01.2346\r\n",
                          R"({"sample_period_s": 1e-4, "feed_mm_per_min": 400})", "", 3,
                          "lacks spindle_rpm (and has no angle column): give \"spindle_rpm\""},
        SensorFileRefusal{
            "ASamplePeriodThatContradictsTheMeasuringRate", "export.csv",
            std::string(kSensorToolHead) + "0,0000;1;1,5\r\n",
            R"({"spindle_rpm": 500, "feed_mm_per_min": 400, "sample_period_s": 0.0002})", "", 2,
            "sample_period_s contradicts the scan: '{settings}' gives sample_period_s = 0.0002, '{file}' "
            "gives "
            "sample_period_s = 0.0001"},
        SensorFileRefusal{
            "ASensorThatContradictsTheFile", "export.csv", std::string(kSensorToolHead) + "0,0000;1;1,5\r\n",
            R"({"spindle_rpm": 500, "feed_mm_per_min": 400, "sensor": "ILD1750"})", "", 2,
            "sensor contradicts the scan: '{settings}' gives sensor = 'ILD1750', '{file}' gives sensor = "
            "'ILD2300'"},
        SensorFileRefusal{
            "AnAngleInCountsWithoutCountsPerTurn", "logger.txt", "Zeit;Weg;Winkel\n0;1,5;10\n", kSettings,
            "--columns z=Weg,angle=Winkel:counts", 3,
            "'{file}' line 1: column 'Winkel' holds encoder counts: give \"encoder_counts_per_rev\" in "
            "--scan-settings"},
        SensorFileRefusal{
            "AnUnknownFormatName", "export.csv", "never read\n", kSettings, "--format gocator-xyz", 2,
            "--format = gocator-xyz violates hdf5, csv, sensortool, gocator, keyence-lj, keyence-lk, "
            "columns or "
            "profile-hdf5"}),
    [](const ::testing::TestParamInfo<SensorFileRefusal>& param_info) { return param_info.param.name; });

// A line-profile scan as a user runs it: simulated as a Gocator export, processed with its settings
// file; the same file with two frames swapped is refused naming the file, the line and the column,
// exit 3, nothing written.
TEST(ProfileScanCli, AGocatorExportIsProcessedAndOneWithFramesOutOfOrderRefused) {
  TempDir dir;
  const auto scan = dir / "gocator.csv";
  const auto sim =
      RunArcwheel("simulate " + scan.string() +
                  " --as gocator --points 200 --frames-per-turn 100 --turns 2 --encoder-counts-per-rev 1000 "
                  "--noise-um 1 --start-phase-deg 0.05");
  ASSERT_EQ(sim.exit_status, 0) << sim.output;
  const std::string settings = " --scan-settings " + scan.string() + ".settings.json --phases 50";
  const auto run = RunArcwheel("process -q " + scan.string() + settings + " -o " + (dir / "out").string());
  ASSERT_EQ(run.exit_status, 0) << run.output;
  const auto s = ReadJson(dir / "out" / "summary.json");
  EXPECT_EQ(s["input"]["format"], "gocator");
  EXPECT_EQ(s["phases"]["phase_deg"].size(), 50u);
  std::ifstream in(scan, std::ios::binary);
  std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const std::size_t frame1 = text.find("\r\n1,0,");
  ASSERT_NE(frame1, std::string::npos);
  text.replace(frame1 + 2, 1, "7");  // frame 7 before frame 2
  const auto bad = dir / "bad.csv";
  WriteText(bad, text);
  const auto refused =
      RunArcwheel("process -q " + bad.string() + settings + " -o " + (dir / "bad_out").string());
  EXPECT_EQ(refused.exit_status, 3) << refused.output;
  EXPECT_NE(refused.output.find("'" + bad.string() + "' line 15: column 'Frame': frame 2 after frame 7"),
            std::string::npos)
      << refused.output;
  EXPECT_FALSE(std::filesystem::exists(dir / "bad_out"));
}

}  // namespace
}  // namespace arcwheel
