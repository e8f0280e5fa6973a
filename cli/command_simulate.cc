// arcwheel simulate: a synthetic helical scan with known geometry, plus its truth JSON.

#include <fmt/core.h>

#include <filesystem>
#include <string>
#include <vector>

#include "acquisition/scan_format.h"
#include "acquisition/sensor_writer.h"
#include "acquisition/simulate.h"
#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"

namespace arcwheel::cli {
namespace {

struct SimulateArgs {
  acquisition::WheelModel wheel;
  acquisition::ScanSettings settings;
  std::string output;
  std::string truth;
  std::vector<std::string> radius_harmonics, axial_harmonics, radial_harmonics;
  bool float64 = false;
  int truth_phases = 360;
  std::string as;             // a sensor's layout (sensortool, keyence-lk); empty: by the extension
  std::string settings_file;  // the settings file beside a sensor's layout
};

// "ORDER:AMPLITUDE[:PHASE_DEG]"
std::vector<acquisition::Harmonic> ParseHarmonics(const std::vector<std::string>& specs, const char* option) {
  std::vector<acquisition::Harmonic> harmonics;
  for (const std::string& spec : specs) {
    acquisition::Harmonic h;
    char extra = 0;
    const int read = std::sscanf(spec.c_str(), "%d:%lf:%lf%c", &h.order, &h.amplitude, &h.phase_deg, &extra);
    if (read < 2 || read > 3 || h.order < 1) {
      throw Error(ErrorCode::kInvalidOption, "simulate",
                  std::string(option) + " '" + spec + "' is not ORDER:AMPLITUDE[:PHASE_DEG] with ORDER >= 1");
    }
    harmonics.push_back(h);
  }
  return harmonics;
}

void Run(SimulateArgs& args) {
  args.wheel.arc_radius_harmonics_mm = ParseHarmonics(args.radius_harmonics, "--radius-harmonic");
  args.wheel.center_axial_harmonics_mm = ParseHarmonics(args.axial_harmonics, "--axial-harmonic");
  args.wheel.radial_harmonics_um = ParseHarmonics(args.radial_harmonics, "--radial-harmonic");
  if (args.settings.sensor_zero_radius_mm <= 0) {
    args.settings.sensor_zero_radius_mm = args.wheel.wheel_diameter_mm / 2.0 - 0.5;
  }
  args.settings.float32 = !args.float64;
  const acquisition::SimulatedScan simulated = acquisition::SimulateScan(args.wheel, args.settings);
  const std::filesystem::path output(args.output);
  std::string settings_path;
  if (args.as.empty()) {
    acquisition::WriteScan(simulated.scan, args.settings.float32, output);
  } else {
    // What the sensor's software would write, and the settings it leaves out (formats.md 2.4).
    acquisition::WriteSensorScan(simulated.scan, acquisition::ScanFormatNamed(args.as, "simulate"), output);
    settings_path = args.settings_file.empty() ? output.string() + ".settings.json" : args.settings_file;
    WriteFileAtomically(settings_path, acquisition::SensorScanSettingsJson(simulated.scan));
  }
  const std::string truth_path = args.truth.empty() ? output.string() + ".truth.json" : args.truth;
  WriteFileAtomically(truth_path,
                      acquisition::TruthJson(args.wheel, args.settings, simulated.counts, args.truth_phases));
  fmt::print("scan:  {} ({} samples)\ntruth: {}\n", args.output, simulated.counts.samples, truth_path);
  if (!settings_path.empty()) fmt::print("settings: {}\n", settings_path);
}

}  // namespace

void AddSimulateCommand(CLI::App& app) {
  auto args = std::make_shared<SimulateArgs>();
  CLI::App* cmd =
      app.add_subcommand("simulate", "write a synthetic helical scan of a wheel with known geometry");
  cmd->footer(
      "The wheel: rim radius R(c,y) = Rb(c) + sqrt(Ra(c)^2 - (y - a(c))^2) + profile + grit.\n"
      "Harmonics are ORDER:AMPLITUDE[:PHASE_DEG] (amplitude in the option's unit), repeatable.\n"
      "The truth JSON (OUTPUT.truth.json unless --truth) holds the model, the settings and the\n"
      "per-phase arc radius and centre. Defaults are the paper's scan: 400 x 20 mm wheel, 500 rpm,\n"
      "100 mm/min, 100 us (about 1.3e5 samples).");
  cmd->add_option("OUTPUT", args->output, "scan file to write (.h5/.hdf5 or .csv/.txt)")->required();
  cmd->add_option("--truth", args->truth, "truth JSON path");
  cmd->add_option("--as", args->as,
                  "write what the sensor's software would, with the settings it lacks beside it: sensortool "
                  "(Micro-Epsilon CSV, decimal comma) or keyence-lk (LK-Navigator CSV)")
      ->check(CLI::IsMember({"sensortool", "keyence-lk"}));
  cmd->add_option("--settings", args->settings_file,
                  "with --as: settings JSON path (default OUTPUT.settings.json)");
  auto& w = args->wheel;
  auto& s = args->settings;
  cmd->add_option("--wheel-diameter-mm", w.wheel_diameter_mm, "wheel diameter at the arc apex")
      ->capture_default_str();
  cmd->add_option("--width-mm", w.width_mm, "rim width")->capture_default_str();
  cmd->add_option("--arc-radius-mm", w.arc_radius_mm, "mean arc radius Ra")->capture_default_str();
  cmd->add_option("--center-axial-mm", w.center_axial_mm, "axial position of the arc centre")
      ->capture_default_str();
  cmd->add_option("--radius-harmonic", args->radius_harmonics, "Ra(c) variation, amplitude in mm");
  cmd->add_option("--axial-harmonic", args->axial_harmonics,
                  "a(c) variation (axial wobble), amplitude in mm");
  cmd->add_option("--radial-harmonic", args->radial_harmonics,
                  "radial runout: order 1 eccentricity, >= 2 lobing; um");
  cmd->add_option("--profile-legendre-um", w.profile_legendre_um,
                  "profile error: coefficients of P0, P1, ... in um")
      ->delimiter(',');
  cmd->add_option("--profile-wave-um", w.profile_wave_um, "profile wave amplitude")->capture_default_str();
  cmd->add_option("--profile-wave-period-mm", w.profile_wave_period_mm, "profile wave period")
      ->capture_default_str();
  cmd->add_option("--edge-drop-um", w.edge_drop_um, "rim edge fall-off (4th power)")->capture_default_str();
  cmd->add_option("--edge-length-mm", w.edge_length_mm, "length of the falling edge")->capture_default_str();
  cmd->add_option("--grit-um", w.grit_sigma_um, "repeatable grit texture, 1 sigma")->capture_default_str();
  cmd->add_option("--grit-cell-mm", w.grit_cell_mm, "grit texture cell size")->capture_default_str();
  cmd->add_option("--rpm", s.spindle_rpm_nominal, "nominal spindle speed written to the file")
      ->capture_default_str();
  cmd->add_option("--true-rpm", s.spindle_rpm_true, "actual spindle speed (defaults to --rpm)");
  cmd->add_option("--feed-mm-per-min", s.feed_mm_per_min, "axial feed")->capture_default_str();
  cmd->add_option("--sample-period-s", s.sample_period_s, "sample period")->capture_default_str();
  cmd->add_option("--start-y-mm", s.start_y_mm, "axial position of the first sample")->capture_default_str();
  cmd->add_option("--end-y-mm", s.end_y_mm, "axial position where the scan stops")->capture_default_str();
  cmd->add_option("--start-phase-deg", s.start_phase_deg, "phase of the first sample")->capture_default_str();
  cmd->add_option("--sensor-zero-radius-mm", s.sensor_zero_radius_mm,
                  "radius read as 0 (default: wheel radius - 0.5)");
  cmd->add_option("--radius-sign", s.radius_sign, "+1: larger reading = larger radius; -1: the opposite")
      ->capture_default_str();
  cmd->add_option("--beam-offset-mm", s.beam_offset_mm, "lateral offset of the beam from the axis")
      ->capture_default_str();
  cmd->add_option("--noise-um", s.noise_um, "white sensor noise, 1 sigma")->capture_default_str();
  cmd->add_option("--spike-rate", s.spike_rate, "isolated spikes per sample")->capture_default_str();
  cmd->add_option("--spike-um", s.spike_amplitude_um, "spike amplitude")->capture_default_str();
  cmd->add_option("--burst-rate", s.burst_rate, "bursts of spikes per sample")->capture_default_str();
  cmd->add_option("--burst-length-max", s.burst_length_max, "longest burst, samples")->capture_default_str();
  cmd->add_option("--dropout-rate", s.dropout_rate, "dropouts per sample")->capture_default_str();
  cmd->add_option("--dropout-length-max", s.dropout_length_max, "longest dropout, samples")
      ->capture_default_str();
  cmd->add_flag("--encoder", s.write_encoder, "write an angle column (the true spindle angle)");
  cmd->add_flag("--time-column", s.write_time, "write a t column");
  cmd->add_flag("--axial-column", s.write_axial, "write a y column");
  cmd->add_flag("--float64", args->float64, "HDF5 z as float64 (default float32)");
  cmd->add_option("--seed", s.seed, "random seed")->capture_default_str();
  cmd->add_option("--wheel-id", s.wheel_id, "wheel id written to the file")->capture_default_str();
  cmd->add_option("--timestamp", s.timestamp, "scan date and time written to the file (ISO 8601)")
      ->capture_default_str();
  cmd->add_option("--truth-phases", args->truth_phases, "phases in the truth file")->capture_default_str();
  cmd->callback([args, cmd] {
    if (cmd->count("--true-rpm") == 0) args->settings.spindle_rpm_true = args->settings.spindle_rpm_nominal;
    Run(*args);
  });
}

}  // namespace arcwheel::cli
