#include "acquisition/simulate.h"

#include <cmath>
#include <limits>
#include <numbers>
#include <random>

#include "core/error.h"
#include "core/nan.h"

namespace arcwheel::acquisition {
namespace {

constexpr double kDegToRad = std::numbers::pi / 180.0;

double SumHarmonics(const std::vector<Harmonic>& harmonics, double phase_deg) {
  double sum = 0.0;
  for (const Harmonic& h : harmonics)
    sum += h.amplitude * std::cos((h.order * phase_deg + h.phase_deg) * kDegToRad);
  return sum;
}

// Legendre P_n(x) by the three-term recurrence.
double Legendre(std::size_t n, double x) {
  if (n == 0) return 1.0;
  double p_prev = 1.0;
  double p = x;
  for (std::size_t k = 1; k < n; ++k) {
    const double next = ((2.0 * static_cast<double>(k) + 1.0) * x * p - static_cast<double>(k) * p_prev) /
                        (static_cast<double>(k) + 1.0);
    p_prev = p;
    p = next;
  }
  return p;
}

// SplitMix64: a stateless hash, so that the grit at a spot is the same on every turn.
std::uint64_t Mix(std::uint64_t x) {
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

double UnitFromHash(std::uint64_t h) { return (static_cast<double>(h >> 11) + 0.5) * 0x1.0p-53; }

void Require(bool condition, const std::string& problem) {
  if (!condition) throw Error(ErrorCode::kInvalidOption, "acquisition.simulate", problem);
}

}  // namespace

double WheelModel::ArcRadiusMm(double phase_deg) const {
  return arc_radius_mm + SumHarmonics(arc_radius_harmonics_mm, phase_deg);
}

double WheelModel::CenterAxialMm(double phase_deg) const {
  return center_axial_mm + SumHarmonics(center_axial_harmonics_mm, phase_deg);
}

double WheelModel::CenterDistanceMm(double phase_deg) const {
  return wheel_diameter_mm / 2.0 - arc_radius_mm + SumHarmonics(radial_harmonics_um, phase_deg) / 1000.0;
}

double WheelModel::ProfileErrorMm(double u_mm) const {
  const double x = u_mm / (width_mm / 2.0);
  double sum = 0.0;
  for (std::size_t n = 0; n < profile_legendre_um.size(); ++n) sum += profile_legendre_um[n] * Legendre(n, x);
  if (profile_wave_um != 0.0)
    sum += profile_wave_um * std::cos(2.0 * std::numbers::pi * u_mm / profile_wave_period_mm);
  const double edge_start_mm = width_mm / 2.0 - edge_length_mm;
  if (edge_drop_um != 0.0 && std::abs(u_mm) > edge_start_mm) {
    const double s = (std::abs(u_mm) - edge_start_mm) / edge_length_mm;
    sum -= edge_drop_um * (s * s) * (s * s);
  }
  return sum / 1000.0;
}

double WheelModel::SmoothRadiusMm(double phase_deg, double y_mm) const {
  const double u = y_mm - CenterAxialMm(phase_deg);
  const double ra = ArcRadiusMm(phase_deg);
  if (std::abs(u) > width_mm / 2.0 || std::abs(u) >= ra) return kNaN;
  return CenterDistanceMm(phase_deg) + std::sqrt(ra * ra - u * u) + ProfileErrorMm(u);
}

double WheelModel::RadiusMm(double phase_deg, double y_mm) const {
  const double smooth = SmoothRadiusMm(phase_deg, y_mm);
  if (grit_sigma_um <= 0.0 || !std::isfinite(smooth)) return smooth;
  // Grit cells tile the rim surface: arc length along the circumference by axial position.
  const double circumference_mm = std::numbers::pi * wheel_diameter_mm;
  const double along = std::fmod(std::fmod(phase_deg, 360.0) + 360.0, 360.0) / 360.0 * circumference_mm;
  const auto i = static_cast<std::int64_t>(std::floor(along / grit_cell_mm));
  const auto j = static_cast<std::int64_t>(std::floor(y_mm / grit_cell_mm));
  const std::uint64_t h = Mix(
      grit_seed ^ Mix(static_cast<std::uint64_t>(i) * 0x100000001b3ULL ^ Mix(static_cast<std::uint64_t>(j))));
  // Box-Muller from two hashed uniforms.
  const double u1 = UnitFromHash(h);
  const double u2 = UnitFromHash(Mix(h));
  const double gaussian = std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * std::numbers::pi * u2);
  return smooth + grit_sigma_um * gaussian / 1000.0;
}

WheelModel LobedTestWheel() {
  WheelModel w;
  w.radial_harmonics_um = {{1, 5.0, 30.0}, {3, 1.5, 10.0}, {5, 0.8, 100.0}};
  w.center_axial_harmonics_mm = {{1, 0.004, 60.0}};
  w.arc_radius_harmonics_mm = {{2, 0.010, 45.0}};
  return w;
}

WheelModel PaperTestWheel() {
  WheelModel w;
  w.arc_radius_harmonics_mm = {{2, 0.020, 0.0}, {3, 0.010, 40.0}, {5, 0.005, 110.0}};
  w.profile_wave_um = 1.0;
  w.profile_wave_period_mm = 3.0;
  w.edge_drop_um = 20.0;
  w.edge_length_mm = 5.0;
  w.grit_sigma_um = 0.2;
  return w;
}

ScanSettings PaperTestScan(std::uint64_t seed) {
  ScanSettings s;
  s.noise_um = 0.2;
  // 0.2 % of the samples spiked: 0.15 % isolated, 0.05 % in bursts of 2-5 (3.5 on average).
  s.spike_rate = 1.5e-3;
  s.burst_rate = 0.5e-3 / 3.5;
  s.spike_amplitude_um = 50.0;
  // 0.1 % of the samples in dropouts of 1-40 (20.5 on average).
  s.dropout_rate = 1e-3 / 20.5;
  s.seed = seed;
  s.wheel_id = "paper-test-wheel";
  return s;
}

SimulatedScan SimulateScan(const WheelModel& wheel, const ScanSettings& s) {
  Require(s.spindle_rpm_true > 0 && s.spindle_rpm_nominal > 0, "spindle speeds must be positive");
  Require(s.feed_mm_per_min > 0, "feed_mm_per_min must be positive");
  Require(s.sample_period_s > 0, "sample_period_s must be positive");
  Require(s.end_y_mm > s.start_y_mm, "end_y_mm must exceed start_y_mm");
  Require(s.radius_sign == 1.0 || s.radius_sign == -1.0, "radius_sign must be +1 or -1");
  Require(wheel.arc_radius_mm > wheel.width_mm / 2.0, "arc_radius_mm must exceed half the width");
  Require(wheel.profile_wave_period_mm > 0, "profile_wave_period_mm must be positive");
  Require(wheel.edge_length_mm > 0 && wheel.edge_length_mm <= wheel.width_mm / 2.0,
          "edge_length_mm must lie in (0, width_mm / 2]");
  Require(s.burst_length_max >= 2 && s.dropout_length_max >= 1,
          "burst and dropout lengths must be >= 2 and >= 1");
  const double duration_s = (s.end_y_mm - s.start_y_mm) / s.feed_mm_per_min * 60.0;
  const auto n = static_cast<std::size_t>(std::floor(duration_s / s.sample_period_s)) + 1;
  Require(n <= 2'000'000'000ULL, "the scan would have more than 2e9 samples");

  SimulatedScan result;
  Scan& scan = result.scan;
  scan.path = "simulated";
  ScanMetadata& meta = scan.metadata;
  meta.spindle_rpm = s.spindle_rpm_nominal;
  meta.feed_mm_per_min = s.feed_mm_per_min;
  meta.sample_period_s = s.sample_period_s;
  meta.radius_sign = s.radius_sign;
  meta.start_y_mm = s.start_y_mm;
  meta.start_phase_deg = s.start_phase_deg;
  meta.range_min_mm = -s.sensor_range_mm;
  meta.range_max_mm = s.sensor_range_mm;
  meta.wheel_diameter_mm = wheel.wheel_diameter_mm;
  meta.wheel_width_mm = wheel.width_mm;
  meta.wheel_id = s.wheel_id;
  meta.sensor = "simulated laser triangulation sensor";
  meta.timestamp = s.timestamp;

  scan.z_mm.resize(n);
  if (s.write_time) scan.t_s.resize(n);
  if (s.write_encoder) scan.angle_deg.resize(n);
  if (s.write_axial) scan.y_mm.resize(n);

  // Noise and defects come from separate streams, so that a scan with spikes and dropouts carries
  // the same noise as the clean scan of the same seed: tests compare the two sample for sample.
  std::mt19937_64 rng(s.seed);
  std::mt19937_64 events(s.seed ^ 0x9e3779b97f4a7c15ULL);
  std::normal_distribution<double> noise(0.0, s.noise_um / 1000.0);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  int burst_left = 0;
  double burst_offset_mm = 0.0;
  int dropout_left = 0;
  const double beam2 = s.beam_offset_mm * s.beam_offset_mm;
  SimulationCounts& counts = result.counts;
  counts.samples = n;

  for (std::size_t i = 0; i < n; ++i) {
    const double t = static_cast<double>(i) * s.sample_period_s;
    const double phase_deg = s.start_phase_deg + 6.0 * s.spindle_rpm_true * t;
    const double y = s.start_y_mm + s.feed_mm_per_min * t / 60.0;
    if (s.write_time) scan.t_s[i] = t;
    if (s.write_encoder) scan.angle_deg[i] = std::fmod(phase_deg, 360.0);
    if (s.write_axial) scan.y_mm[i] = y;

    const double radius = wheel.RadiusMm(phase_deg, y);
    double z = kNaN;
    if (std::isfinite(radius)) {
      const double height = std::sqrt(radius * radius - beam2);
      z = s.radius_sign * (height - s.sensor_zero_radius_mm);
      if (s.noise_um > 0) z += noise(rng);
      if (burst_left == 0 && s.burst_rate > 0 && unit(events) < s.burst_rate) {
        burst_left = 2 + static_cast<int>(unit(events) * (s.burst_length_max - 1));
        burst_offset_mm =
            (unit(events) < 0.5 ? -1.0 : 1.0) * s.spike_amplitude_um * (0.5 + 0.5 * unit(events)) / 1000.0;
      }
      if (burst_left > 0) {
        z += burst_offset_mm * (0.8 + 0.4 * unit(events));
        --burst_left;
        ++counts.spikes;
      } else if (s.spike_rate > 0 && unit(events) < s.spike_rate) {
        z += (unit(events) < 0.5 ? -1.0 : 1.0) * s.spike_amplitude_um * (0.5 + 0.5 * unit(events)) / 1000.0;
        ++counts.spikes;
      }
      if (std::abs(z) > s.sensor_range_mm) z = kNaN;
    }
    if (!std::isfinite(z)) {
      ++counts.off_rim;
    } else {
      if (dropout_left == 0 && s.dropout_rate > 0 && unit(events) < s.dropout_rate) {
        dropout_left = 1 + static_cast<int>(unit(events) * s.dropout_length_max);
      }
      if (dropout_left > 0) {
        z = kNaN;
        --dropout_left;
        ++counts.dropouts;
      }
    }
    scan.z_mm[i] = z;
  }
  return result;
}

}  // namespace arcwheel::acquisition
