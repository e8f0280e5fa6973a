#pragma once
// A synthetic helical scan of an arc-profile wheel with known geometry (method.md A.1), for
// tests and for users who want to know what a scan setting can resolve.
//
// The wheel: at phase c (deg) and axial position y (mm) the rim lies at distance
//   R(c, y) = Rb(c) + sqrt(Ra(c)^2 - (y - a(c))^2) + profile(y - a(c)) + grit(c, y)
// from the spindle axis, where
//   Ra(c) = arc_radius_mm + sum of arc_radius_harmonics_mm,
//   a(c)  = center_axial_mm + sum of center_axial_harmonics_mm,
//   Rb(c) = wheel_diameter_mm / 2 - arc_radius_mm + sum of radial_harmonics_um / 1000
//           (order 1 is eccentricity, orders >= 2 are lobing),
//   profile(u) = sum_n profile_legendre_um[n] * P_n(u / (width_mm / 2)) / 1000 (non-circular profile
//           error, the same at every phase)
//           + profile_wave_um * cos(2 pi u / profile_wave_period_mm) / 1000 (a profile wave)
//           - edge_drop_um * ((|u| - (width_mm / 2 - edge_length_mm)) / edge_length_mm)^4 / 1000
//             over the last edge_length_mm of each side (a rim edge falling off as the 4th power),
//   grit(c, y) = a repeatable random texture, constant over cells of grit_cell_mm.
// The sensor's beam is parallel to the radial direction at lateral offset beam_offset_mm from the
// axis (method.md A.7), so it reads h = sqrt(R^2 - beam_offset^2); its reading is
//   z = radius_sign * (h - sensor_zero_radius_mm) + noise + spikes,
// invalid (off the rim, outside +-sensor_range_mm, or in a dropout) where the spot is not on the rim.
// The spindle turns at spindle_rpm_true; the file states spindle_rpm_nominal.

#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "acquisition/scan.h"

namespace arcwheel::acquisition {

// amplitude * cos(order * c + phase_deg); amplitude in the unit the owning field names.
struct Harmonic {
  int order = 1;
  double amplitude = 0.0;
  double phase_deg = 0.0;
};

struct WheelModel {
  double wheel_diameter_mm = 400.0;  // total diameter at the arc apex (nominal)
  double width_mm = 20.0;            // axial width of the rim; the arc spans a(c) +- width/2
  double arc_radius_mm = 55.4423;
  double center_axial_mm = 0.0;  // a0, in the scan's axial coordinate
  std::vector<Harmonic> arc_radius_harmonics_mm;
  std::vector<Harmonic> center_axial_harmonics_mm;
  std::vector<Harmonic> radial_harmonics_um;
  std::vector<double> profile_legendre_um;  // coefficient of P_n, n = 0, 1, 2, ...
  double profile_wave_um = 0.0;             // amplitude of the profile wave (0: none)
  double profile_wave_period_mm = 3.0;      // its period along the axis, > 0
  double edge_drop_um = 0.0;                // how far the rim falls at each edge (0: a sharp edge)
  double edge_length_mm = 5.0;              // over this much of each side, in (0, width_mm / 2]
  double grit_sigma_um = 0.0;
  double grit_cell_mm = 0.05;
  std::uint64_t grit_seed = 7;

  [[nodiscard]] double ArcRadiusMm(double phase_deg) const;
  [[nodiscard]] double CenterAxialMm(double phase_deg) const;
  // Distance of the arc centre from the spindle axis.
  [[nodiscard]] double CenterDistanceMm(double phase_deg) const;
  // Profile error (mm) at axial offset u_mm from the arc centre.
  [[nodiscard]] double ProfileErrorMm(double u_mm) const;
  // R(c, y) without grit; NaN where y is off the rim.
  [[nodiscard]] double SmoothRadiusMm(double phase_deg, double y_mm) const;
  // R(c, y) with grit; NaN where y is off the rim.
  [[nodiscard]] double RadiusMm(double phase_deg, double y_mm) const;
};

// A wheel with each phase-dependent error of method.md A, for tests and benchmarks: 5 um of
// eccentricity, lobes of orders 3 and 5, a 4 um axial wobble of the arc centre and a 10 um
// second-order variation of the arc radius; no profile error.
[[nodiscard]] WheelModel LobedTestWheel();

// The wheel of issue 29 (method.md A, the paper's geometry): 400 x 20 mm, Ra 55.4423 mm whose
// arc radius varies by lobes of 20, 10 and 5 um of orders 2, 3 and 5; a profile wave of 1 um
// amplitude and 3 mm period; a rim edge that falls 20 um as the 4th power over the last 5 mm of
// each side; a fixed 0.2 um rms grit texture (the same for every scan of it).
[[nodiscard]] WheelModel PaperTestWheel();

struct ScanSettings {
  double spindle_rpm_nominal = 500.0;
  double spindle_rpm_true = 500.0;
  double feed_mm_per_min = 100.0;
  double sample_period_s = 100e-6;
  double start_y_mm = -11.0;  // first sample's axial position
  double end_y_mm = 11.0;     // the scan stops here
  double start_phase_deg = 0.0;
  double sensor_zero_radius_mm = 199.5;  // wheel radius at which the sensor reads 0
  double sensor_range_mm = 3.0;          // readings beyond +- this are over-range (invalid)
  double radius_sign = 1.0;
  double beam_offset_mm = 0.0;
  double noise_um = 0.0;    // white sensor noise, 1 sigma
  double spike_rate = 0.0;  // isolated spikes per sample
  double spike_amplitude_um = 50.0;
  double burst_rate = 0.0;      // bursts of spikes per sample
  int burst_length_max = 5;     // samples in a burst, 2..max
  double dropout_rate = 0.0;    // dropouts per sample
  int dropout_length_max = 40;  // samples in a dropout, 1..max
  bool write_time = false;      // a t column
  bool write_encoder = false;   // an angle column (true spindle angle, wrapped)
  bool write_axial = false;     // a y column
  bool float32 = true;          // HDF5 z as float32 (else float64)
  std::uint64_t seed = 1;
  std::string wheel_id = "simulated";
  std::string timestamp = "2017-09-13T10:00:00Z";  // ISO 8601, written as the scan's timestamp
};

// The scan of PaperTestWheel that issue 29 measures: 500 rpm, 100 mm/min, 100 us (132,001
// samples over 22 mm), 0.2 um white noise, 0.2 % of the samples spiked (a quarter of them in
// bursts), 0.1 % of them in dropouts, with noise and defects from `seed`.
[[nodiscard]] ScanSettings PaperTestScan(std::uint64_t seed);

// What the simulator injected, for the truth file.
struct SimulationCounts {
  std::size_t samples = 0;
  std::size_t off_rim = 0;
  std::size_t dropouts = 0;
  std::size_t spikes = 0;  // samples carrying a spike (isolated or in a burst)
};

struct SimulatedScan {
  Scan scan;
  SimulationCounts counts;
};

// Throws Error{kInvalidOption} naming the field for settings that make no scan.
[[nodiscard]] SimulatedScan SimulateScan(const WheelModel& wheel, const ScanSettings& settings);

// Writers for the formats.md section 2 layouts (atomically). CSV marks off-rim samples with the
// sensor alarm word -FFFFFFF and dropouts with `nan`.
void WriteHdf5Scan(const Scan& scan, bool float32, const std::string& path);
void WriteCsvScan(const Scan& scan, const std::string& path);
// The writer of the format the file name selects (scan_format.h); Error{kInvalidOption} naming the
// extensions when no format claims it. `float32` applies to HDF5.
void WriteScan(const Scan& scan, bool float32, const std::filesystem::path& path);

// The truth JSON: the model, the settings, the injected counts and per-phase truth at
// `phases` equally spaced phases (arc radius, arc-centre axial and radial position in the rho frame).
[[nodiscard]] std::string TruthJson(const WheelModel& wheel, const ScanSettings& settings,
                                    const SimulationCounts& counts, int phases);

}  // namespace arcwheel::acquisition
