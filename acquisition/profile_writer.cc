// Writers of line-profile scans in the layouts the readers take (docs/inputs.md), and the simulated
// profile scan (profile_scan.h).

#include <fmt/core.h>

#include <cmath>
#include <nlohmann/json.hpp>
#include <random>

#include "acquisition/profile_scan.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/json_text.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kProfileWriterStage = "acquisition.write";
constexpr double kUnitsPerMm = 1e5;  // 0.01 um, Keyence LJ's integer unit
constexpr long long kLjInvalid = -2147483648LL;

double RoundToUnit(double mm) { return std::round(mm * kUnitsPerMm) / kUnitsPerMm; }

long long Units(double mm) { return std::llround(mm * kUnitsPerMm); }

std::string GocatorText(const ProfileScan& scan) {
  const std::size_t frames = scan.frames(), points = scan.points();
  const bool encoder = !scan.encoder.empty();
  std::string text;
  text.reserve(200 + (frames + 1) * (points * 10 + 60));
  const auto line = [&](const std::string& l) { text += l + "\r\n"; };
  line("Info");
  line(
      "CSV Version,Sensor Count,Trigger Mode,Trigger Rate,Trigger Delay Domain,Trigger Delay,Operation Mode,"
      "XResolution,YResolution,ZResolution,Yspeed,Layout");
  line(fmt::format("2,1,{},0.00000,0,0.00000,1,0.01000,0.00000,0.00001,0.00000,0", encoder ? 1 : 0));
  line("End");
  line("DeviceInfo");
  line("ID,Model,Version");
  line("13434,2430,6.1.12.2");
  line("End");
  line("Profile");
  line("Frame Count,Column Count,X Offset,Y Offset,Z Offset");
  line(fmt::format("{},{},{:.5f},0.00000,0.00000", frames, points, scan.x_mm.front()));
  text += "Frame,Source,Time,Encoder,Z Encoder,Inputs,Exposure,Y(mm),Axis";
  for (const double x : scan.x_mm) text += fmt::format(",{:.5f}", x);
  text += "\r\n";
  for (std::size_t f = 0; f < frames; ++f) {
    const double t = scan.t_s.empty() ? 0.0 : scan.t_s[f];
    text += fmt::format("{},0,{},{},0,0,300,0.00000,Z", f, std::llround(t * 1.024e6),
                        encoder ? std::llround(scan.encoder[f]) : 0);
    for (std::size_t i = 0; i < points; ++i) {
      const double z = scan.z_mm[f * points + i];
      text += ',';
      if (std::isfinite(z)) text += fmt::format("{:.5f}", z);
    }
    text += "\r\n";
  }
  line("End");
  return text;
}

std::string KeyenceLjText(const ProfileScan& scan) {
  const std::size_t frames = scan.frames(), points = scan.points();
  std::string text;
  text.reserve((frames + 1) * points * 9);
  for (std::size_t i = 0; i < points; ++i)
    text += fmt::format("{}{}", i == 0 ? "" : "\t", Units(scan.x_mm[i]));
  text += "\r\n";
  for (std::size_t f = 0; f < frames; ++f) {
    for (std::size_t i = 0; i < points; ++i) {
      const double z = scan.z_mm[f * points + i];
      text += fmt::format("{}{}", i == 0 ? "" : "\t", std::isfinite(z) ? Units(z) : kLjInvalid);
    }
    text += "\r\n";
  }
  return text;
}

void WriteProfileHdf5(const ProfileScan& scan, const std::filesystem::path& path) {
  OutputSet outputs;
  const std::filesystem::path staged = outputs.Stage(path);
  {
    hdf5::File file = hdf5::File::Create(staged);
    file.CreateGroup("/profile");
    const auto frames = static_cast<hsize_t>(scan.frames()), points = static_cast<hsize_t>(scan.points());
    file.WriteDoubles("/profile/z", scan.z_mm, {frames, points});
    file.WriteDoubles("/profile/x_mm", scan.x_mm, {points});
    if (!scan.t_s.empty()) file.WriteDoubles("/profile/t", scan.t_s, {frames});
    if (!scan.encoder.empty()) file.WriteDoubles("/profile/encoder", scan.encoder, {frames});
    const ScanMetadata& m = scan.metadata;
    if (m.spindle_rpm) file.WriteAttribute("/profile", "spindle_rpm", *m.spindle_rpm);
    if (m.sample_period_s) file.WriteAttribute("/profile", "sample_period_s", *m.sample_period_s);
    file.WriteAttribute("/profile", "radius_sign", m.radius_sign);
    file.WriteAttribute("/profile", "start_phase_deg", m.start_phase_deg);
    if (scan.placement.encoder_counts_per_rev > 0.0) {
      file.WriteAttribute("/profile", "encoder_counts_per_rev", scan.placement.encoder_counts_per_rev);
    }
    if (!m.wheel_id.empty()) file.WriteAttribute("/profile", "wheel_id", m.wheel_id);
    if (!m.timestamp.empty()) file.WriteAttribute("/profile", "timestamp", m.timestamp);
  }
  outputs.Commit();
}

void CheckSettings(const ProfileScanSettings& s) {
  const auto refuse = [](const std::string& problem) {
    throw Error(ErrorCode::kInvalidOption, "simulate", problem);
  };
  if (s.points < 8) refuse(fmt::format("points = {} violates >= 8", s.points));
  if (!(s.x_end_mm > s.x_start_mm)) refuse("x_end_mm must exceed x_start_mm");
  if (s.frames_per_turn < 4) refuse(fmt::format("frames_per_turn = {} violates >= 4", s.frames_per_turn));
  if (!(s.turns > 0.0)) refuse("turns must be > 0");
  if (!(s.spindle_rpm > 0.0)) refuse("spindle_rpm must be > 0");
  const double per_frame = s.encoder_counts_per_rev / s.frames_per_turn;
  if (!(per_frame >= 1.0) || per_frame != std::floor(per_frame)) {
    refuse(fmt::format("encoder_counts_per_rev = {} must be a whole multiple of frames_per_turn = {}",
                       s.encoder_counts_per_rev, s.frames_per_turn));
  }
  if (!(s.noise_um >= 0.0) || !(s.dropout_rate >= 0.0 && s.dropout_rate < 1.0)) {
    refuse("noise_um must be >= 0 and dropout_rate in [0, 1)");
  }
}

// The sensor's reading r (rho frame) at column x: the rim point on the sensor's ray, found by
// fixed-point iteration (the tilt moves the point along the axis by r sin(tilt), a small step).
double RimReading(const WheelModel& wheel, double phase_deg, double x, const ProfileScanSettings& s) {
  const double tilt = s.placement.tilt_deg * M_PI / 180.0;
  const double c = std::cos(tilt), sn = std::sin(tilt);
  double r = 0.0;
  for (int k = 0; k < (tilt == 0.0 ? 1 : 8); ++k) {
    const double y = s.placement.axial_offset_mm + x * c - r * sn;
    const double rho = wheel.RadiusMm(phase_deg, y) - s.sensor_zero_radius_mm;
    if (!std::isfinite(rho)) return rho;
    r = (rho - x * sn) / c;
  }
  return r;
}

}  // namespace

void WriteProfileScan(const ProfileScan& scan, ScanFormat format, const std::filesystem::path& path) {
  switch (format) {
    case ScanFormat::kProfileHdf5:
      return WriteProfileHdf5(scan, path);
    case ScanFormat::kGocator:
      return WriteFileAtomically(path, GocatorText(scan));
    case ScanFormat::kKeyenceLj:
      return WriteFileAtomically(path, KeyenceLjText(scan));
    default:
      throw Error(ErrorCode::kInvalidOption, kProfileWriterStage,
                  fmt::format("no profile writer of the {} layout (gocator, keyence-lj or profile-hdf5)",
                              InfoOf(format).name));
  }
}

std::string ProfileScanSettingsJson(const ProfileScan& scan) {
  const ScanMetadata& m = scan.metadata;
  const ProfilePlacement& p = scan.placement;
  nlohmann::json settings = nlohmann::json::object();
  if (m.spindle_rpm) settings["spindle_rpm"] = *m.spindle_rpm;
  if (m.sample_period_s) settings["sample_period_s"] = *m.sample_period_s;
  settings["radius_sign"] = m.radius_sign;
  settings["start_phase_deg"] = m.start_phase_deg;
  if (p.encoder_counts_per_rev > 0.0) settings["encoder_counts_per_rev"] = p.encoder_counts_per_rev;
  settings["sensor_tilt_deg"] = p.tilt_deg;
  settings["sensor_tilt_u_deg"] = p.tilt_u_deg;
  settings["sensor_axial_offset_mm"] = p.axial_offset_mm;
  settings["sensor_axial_offset_u_mm"] = p.axial_offset_u_mm;
  if (m.wheel_diameter_mm) settings["wheel_diameter_mm"] = *m.wheel_diameter_mm;
  if (m.wheel_width_mm) settings["wheel_width_mm"] = *m.wheel_width_mm;
  if (!m.wheel_id.empty()) settings["wheel_id"] = m.wheel_id;
  if (!m.timestamp.empty()) settings["timestamp"] = m.timestamp;
  return JsonText(settings, 2) + "\n";
}

ProfileScan SimulateProfileScan(const WheelModel& wheel, const ProfileScanSettings& s) {
  CheckSettings(s);
  ProfileScan scan;
  scan.path = "simulated";
  const auto points = static_cast<std::size_t>(s.points);
  const auto frames = static_cast<std::size_t>(std::llround(s.turns * s.frames_per_turn));
  const double period_s = 60.0 / (s.spindle_rpm * s.frames_per_turn);
  const double counts_per_frame = s.encoder_counts_per_rev / s.frames_per_turn;
  for (std::size_t i = 0; i < points; ++i) {
    scan.x_mm.push_back(RoundToUnit(s.x_start_mm + (s.x_end_mm - s.x_start_mm) * static_cast<double>(i) /
                                                       static_cast<double>(points - 1)));
  }
  scan.z_mm.resize(frames * points);
  std::mt19937_64 rng(s.seed);
  std::normal_distribution<double> noise(0.0, s.noise_um / 1000.0);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (std::size_t f = 0; f < frames; ++f) {
    const double phase = s.start_phase_deg + 360.0 * static_cast<double>(f) / s.frames_per_turn;
    scan.t_s.push_back(static_cast<double>(f) * period_s);
    scan.encoder.push_back(static_cast<double>(f) * counts_per_frame);
    for (std::size_t i = 0; i < points; ++i) {
      const double r = RimReading(wheel, phase, scan.x_mm[i], s);
      const double e = noise(rng);
      const bool dropped = s.dropout_rate > 0.0 && uniform(rng) < s.dropout_rate;
      scan.z_mm[f * points + i] = std::isfinite(r) && !dropped ? RoundToUnit(s.radius_sign * r + e)
                                                               : std::numeric_limits<double>::quiet_NaN();
    }
  }
  ScanMetadata& m = scan.metadata;
  m.spindle_rpm = s.spindle_rpm;
  m.sample_period_s = period_s;
  m.radius_sign = s.radius_sign;
  m.start_phase_deg = s.start_phase_deg;
  m.wheel_diameter_mm = wheel.wheel_diameter_mm;
  m.wheel_width_mm = wheel.width_mm;
  m.wheel_id = s.wheel_id;
  m.timestamp = s.timestamp;
  scan.placement = s.placement;
  scan.placement.encoder_counts_per_rev = s.encoder_counts_per_rev;
  return scan;
}

}  // namespace arcwheel::acquisition
