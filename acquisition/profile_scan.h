#pragma once
// A line-profile scan (docs/inputs.md, "Line-profile scans"): each frame is a whole axial section of
// the rim, `points` readings at fixed sensor X positions, taken at one phase of the wheel. Read from
// the contract's HDF5 layout (`/profile/z [frames, points]`, `/profile/x_mm`, per-frame `t` and
// `encoder`), an LMI Gocator CSV export or a Keyence LJ-V/LJ-X tab-separated save; written by the
// simulator in each of them.

#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "acquisition/scan.h"
#include "acquisition/scan_format.h"
#include "acquisition/simulate.h"

namespace arcwheel::acquisition {

struct ScanSettingsFile;  // acquisition/scan_settings.h

// Where the sensor's frame lies in the wheel's section plane: calibrated inputs from
// `--scan-settings` (sensor_tilt_deg, sensor_axial_offset_mm and their standard uncertainties
// sensor_tilt_u_deg, sensor_axial_offset_u_mm). A point (x, r = radius_sign * z) of the sensor is
// the wheel's (y, rho) = (offset + x cos(tilt) - r sin(tilt), x sin(tilt) + r cos(tilt)).
struct ProfilePlacement {
  double tilt_deg = 0.0;
  double tilt_u_deg = 0.0;
  double axial_offset_mm = 0.0;
  double axial_offset_u_mm = 0.0;
  // Encoder counts per turn of the spindle; 0: the phase comes from the time and the speed.
  double encoder_counts_per_rev = 0.0;
};

struct ProfileScan {
  std::string path;  // for messages and provenance
  ScanMetadata metadata;
  std::vector<double> x_mm;     // [points]: the sensor's X of each column
  std::vector<double> z_mm;     // [frames * points], row-major by frame; NaN where invalid
  std::vector<double> t_s;      // [frames] or empty: each frame's time, from the first
  std::vector<double> encoder;  // [frames] or empty: each frame's encoder count (unwrapped)
  ProfilePlacement placement;
  ScanReadRecord read;

  [[nodiscard]] std::size_t points() const { return x_mm.size(); }
  [[nodiscard]] std::size_t frames() const { return x_mm.empty() ? 0 : z_mm.size() / x_mm.size(); }
  // The unwrapped phase of frame f (deg): from the encoder when there is one, else from the time
  // (or the frame period) and the spindle speed.
  [[nodiscard]] double PhaseDeg(std::size_t frame) const;
};

// A frame needs at least this many valid points to be a section (the per-phase fit's default
// minimum, fitting::WheelFitOptions::min_points).
inline constexpr std::size_t kMinValidPointsPerFrame = 8;

[[nodiscard]] bool IsProfileFormat(ScanFormat format);

// Reads a line-profile scan in `format` (kProfileHdf5, kGocator or kKeyenceLj), merges `settings`
// (may be null: the keys of scan_settings.h plus the placement's) and validates it. Throws
// Error{kBadInput} naming the file, the frame and the column for: frames out of order, an encoder
// that goes backwards or wraps other than at encoder_counts_per_rev, a frame with fewer than
// kMinValidPointsPerFrame valid points, X columns that change between frames, a cell that is no
// number; Error{kIo} when it cannot be read; Error{kInvalidOption} for settings that contradict it.
[[nodiscard]] ProfileScan ReadProfileScan(const std::filesystem::path& path, ScanFormat format,
                                          const ScanSettingsFile* settings = nullptr);
// The same from text in memory (kGocator, kKeyenceLj); `name` stands for the file in messages.
[[nodiscard]] ProfileScan ParseProfileScan(std::string text, const std::string& name, ScanFormat format,
                                           const ScanSettingsFile* settings = nullptr);

// The checks of ReadProfileScan that need no file: sizes, order, valid points, the phase source.
void ValidateProfileScan(const ProfileScan& scan);

// Writes `scan` (atomically) in `format`'s layout, as docs/inputs.md shows it. Readings are
// written to 0.01 um (LJ's integer unit), which the simulator's readings already are, so every
// layout reads back the same numbers. Throws Error{kIo}, or kInvalidOption for a point format.
void WriteProfileScan(const ProfileScan& scan, ScanFormat format, const std::filesystem::path& path);

// The settings file (JSON) that supplies what a layout does not carry (spindle speed, frame
// period, encoder counts per turn, the placement, the wheel's names and size).
[[nodiscard]] std::string ProfileScanSettingsJson(const ProfileScan& scan);

struct ProfileScanSettings {
  int points = 1600;           // columns per frame
  double x_start_mm = -11.0;   // the sensor's X of the first column
  double x_end_mm = 11.0;      // ... and of the last
  int frames_per_turn = 2000;  // encoder-triggered: frames at fixed phases each turn
  double turns = 3.0;          // the scan's length in turns
  double spindle_rpm = 500.0;
  double start_phase_deg = 0.0;
  double encoder_counts_per_rev = 8000.0;  // frames_per_turn must divide it
  double sensor_zero_radius_mm = 199.5;    // wheel radius at which the sensor reads 0
  double radius_sign = 1.0;
  ProfilePlacement placement;  // the true tilt and offset the simulated sensor is mounted at
  double noise_um = 1.0;       // white noise per point, 1 sigma
  double dropout_rate = 0.0;   // fraction of points invalid
  std::uint64_t seed = 1;
  std::string wheel_id = "simulated";
  std::string timestamp = "2017-09-13T10:00:00Z";
};

// A profile scan of `wheel` by a sensor placed as settings.placement. Each reading is rounded to
// 0.01 um. Throws Error{kInvalidOption} naming the field for settings that make no scan.
[[nodiscard]] ProfileScan SimulateProfileScan(const WheelModel& wheel, const ProfileScanSettings& settings);

}  // namespace arcwheel::acquisition
