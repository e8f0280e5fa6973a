// Readers of line-profile scans (docs/inputs.md, "Line-profile scans"). The text layouts are read
// from one buffer holding the whole file, numbers by std::from_chars, as the point readers do.

#include <fmt/core.h>

#include <algorithm>
#include <charconv>
#include <cmath>
#include <fstream>
#include <functional>
#include <limits>
#include <span>
#include <sstream>

#include "acquisition/profile_scan.h"
#include "acquisition/read_in_child.h"
#include "acquisition/scan_metadata_keys.h"
#include "acquisition/scan_settings.h"
#include "core/check.h"
#include "core/error.h"
#include "core/hdf5.h"
#include "core/nan.h"
#include "core/text_lines.h"

namespace arcwheel::acquisition {
namespace {

// Gocator time stamps count 1/1.024 us.
constexpr double kGocatorTicksPerSecond = 1.024e6;
// Keyence LJ values are integers of 0.01 um; these and below mark invalid points.
constexpr double kKeyenceLjInvalidBelow = -2147483645.0;
constexpr double kKeyenceLjUnitsPerMm = 1e5;

std::string StageOf(ScanFormat format) { return "acquisition." + std::string(InfoOf(format).name); }

bool ParseDouble(std::string_view cell, double& value) {
  cell = TrimBlanks(cell);
  if (!cell.empty() && cell.front() == '+') cell.remove_prefix(1);
  const auto [end, error] = std::from_chars(cell.data(), cell.data() + cell.size(), value);
  return !cell.empty() && error == std::errc() && end == cell.data() + cell.size() && std::isfinite(value);
}

// Calls f(index, cell) for each cell of a separated line.
template <typename F>
void ForEachCell(std::string_view line, char separator, F&& f) {
  std::size_t start = 0, index = 0;
  while (true) {
    const std::size_t next = line.find(separator, start);
    f(index++, line.substr(start, next == std::string_view::npos ? std::string_view::npos : next - start));
    if (next == std::string_view::npos) return;
    start = next + 1;
  }
}

std::vector<std::string_view> Cells(std::string_view line, char separator) {
  std::vector<std::string_view> cells;
  ForEachCell(line, separator,
              [&](std::size_t, std::string_view cell) { cells.push_back(TrimBlanks(cell)); });
  // A trailing separator ends no further column.
  if (cells.size() > 1 && cells.back().empty()) cells.pop_back();
  return cells;
}

class ProfileTextParser {
 public:
  ProfileTextParser(std::string text, std::string name, ScanFormat format)
      : text_(std::move(text)), lines_(text_), stage_(StageOf(format)) {
    scan_.path = std::move(name);
    scan_.read.format = std::string(InfoOf(format).name);
  }

  ProfileScan Gocator() {
    std::string_view line;
    bool saw_profile = false;
    while (lines_.Next(line)) {
      const std::string_view section = TrimBlanks(line);
      if (section == "Info") {
        ReadGocatorInfo();
      } else if (section == "Profile") {
        ReadGocatorProfile();
        saw_profile = true;
      } else if (!section.empty()) {
        SkipSection();
      }
    }
    if (!saw_profile)
      RefuseFile("no 'Profile' section (a Gocator export in Profile mode with uniform spacing)");
    if (trigger_mode_ != 1) scan_.encoder.clear();  // time-triggered: the encoder does not say the phase
    scan_.read.columns = {{"z", "Profile", "mm"}, {"t", "Time", "1/1.024 us"}};
    if (!scan_.encoder.empty()) scan_.read.columns.push_back({"angle", "Encoder", "counts"});
    return std::move(scan_);
  }

  ProfileScan KeyenceLj() {
    std::string_view line;
    std::size_t frame = 0;
    while (lines_.Next(line)) {
      if (TrimBlanks(line).empty()) continue;
      if (scan_.x_mm.empty()) {
        ReadXRow(Cells(line, '\t'), 0, kKeyenceLjUnitsPerMm);
        continue;
      }
      ReadFrameRow(line, '\t', 0, frame++, kKeyenceLjUnitsPerMm);
    }
    if (scan_.x_mm.empty()) RefuseFile("no X block (the first row: the X of each column)");
    scan_.read.columns = {{"z", "profile rows", "0.01 um"}};
    return std::move(scan_);
  }

 private:
  [[noreturn]] void Refuse(const std::string& problem) const {
    throw Error(ErrorCode::kBadInput, stage_,
                fmt::format("'{}' line {}: {}", scan_.path, lines_.number(), problem));
  }
  [[noreturn]] void RefuseFile(const std::string& problem) const {
    throw Error(ErrorCode::kBadInput, stage_, fmt::format("'{}': {}", scan_.path, problem));
  }

  void SkipSection() {
    std::string_view line;
    while (lines_.Next(line)) {
      if (TrimBlanks(line) == "End") return;
    }
  }

  // `Info`: a header row and a value row; the trigger mode says whether the encoder is the phase.
  void ReadGocatorInfo() {
    std::string_view header, values;
    if (!lines_.Next(header) || !lines_.Next(values)) RefuseFile("the 'Info' section ends early");
    const std::vector<std::string_view> names = Cells(header, ',');
    const std::vector<std::string_view> cells = Cells(values, ',');
    for (std::size_t i = 0; i < names.size() && i < cells.size(); ++i) {
      if (names[i] != "Trigger Mode") continue;
      double mode = 0.0;
      if (!ParseDouble(cells[i], mode))
        Refuse(fmt::format("column 'Trigger Mode': '{}' is not a number", cells[i]));
      trigger_mode_ = mode == 1.0 ? 1 : 0;  // 1: encoder; any other: the time says the phase
    }
    SkipSection();
  }

  // `Profile`: the attribute rows, the column row (9 stamp columns, then one per X), one row per frame.
  void ReadGocatorProfile() {
    std::string_view attributes_header, attributes, header;
    if (!lines_.Next(attributes_header) || !lines_.Next(attributes) || !lines_.Next(header)) {
      RefuseFile("the 'Profile' section ends before its column row");
    }
    const std::vector<std::string_view> names = Cells(attributes_header, ',');
    const std::vector<std::string_view> values = Cells(attributes, ',');
    double frame_count = -1.0;
    for (std::size_t i = 0; i < names.size() && i < values.size(); ++i) {
      if (names[i] == "Frame Count" && !ParseDouble(values[i], frame_count)) {
        Refuse(fmt::format("column 'Frame Count': '{}' is not a number", values[i]));
      }
    }
    const std::vector<std::string_view> columns = Cells(header, ',');
    static constexpr std::array<std::string_view, 9> kStamps = {
        "Frame", "Source", "Time", "Encoder", "Z Encoder", "Inputs", "Exposure", "Y(mm)", "Axis"};
    for (std::size_t i = 0; i < kStamps.size(); ++i) {
      if (i >= columns.size() || columns[i] != kStamps[i]) {
        Refuse(fmt::format("column {} of the Profile column row is '{}', expected '{}'", i + 1,
                           i < columns.size() ? columns[i] : "", kStamps[i]));
      }
    }
    ReadXRow(std::vector<std::string_view>(columns.begin() + kStamps.size(), columns.end()), kStamps.size(),
             1.0);
    const std::size_t first_frame = scan_.frames();
    std::string_view line;
    while (lines_.Next(line)) {
      if (TrimBlanks(line) == "End") break;
      if (TrimBlanks(line).empty()) continue;
      const std::vector<std::string_view> stamps =
          Cells(line.substr(0, NthSeparator(line, ',', kStamps.size())), ',');
      if (stamps.size() < kStamps.size())
        Refuse(fmt::format("has {} cells before the X columns, expected 9", stamps.size()));
      if (stamps[8] != "Z") continue;  // intensity rows
      ReadGocatorStamps(stamps);
      ReadFrameRow(line, ',', kStamps.size(), scan_.frames(), 1.0);
    }
    if (frame_count >= 0.0 && static_cast<double>(scan_.frames() - first_frame) != frame_count) {
      RefuseFile(fmt::format("the Profile section says Frame Count {} but holds {} frames", frame_count,
                             scan_.frames() - first_frame));
    }
  }

  static std::size_t NthSeparator(std::string_view line, char separator, std::size_t n) {
    std::size_t at = 0;
    for (std::size_t k = 0; k < n; ++k) {
      at = line.find(separator, at);
      if (at == std::string_view::npos) return line.size();
      ++at;
    }
    return at;
  }

  void ReadGocatorStamps(const std::vector<std::string_view>& stamps) {
    double frame = 0.0, ticks = 0.0, encoder = 0.0;
    if (!ParseDouble(stamps[0], frame))
      Refuse(fmt::format("column 'Frame': '{}' is not a number", stamps[0]));
    if (!ParseDouble(stamps[2], ticks)) Refuse(fmt::format("column 'Time': '{}' is not a number", stamps[2]));
    if (!ParseDouble(stamps[3], encoder))
      Refuse(fmt::format("column 'Encoder': '{}' is not a number", stamps[3]));
    if (!frame_numbers_.empty() && !(frame > frame_numbers_.back())) {
      Refuse(fmt::format("column 'Frame': frame {} after frame {} (frames out of order)", frame,
                         frame_numbers_.back()));
    }
    frame_numbers_.push_back(frame);
    if (scan_.t_s.empty()) first_ticks_ = ticks;
    scan_.t_s.push_back((ticks - first_ticks_) / kGocatorTicksPerSecond);
    scan_.encoder.push_back(encoder);
  }

  // The X of each column, in mm after dividing by `per_mm`; a later block must repeat the first.
  void ReadXRow(const std::vector<std::string_view>& cells, std::size_t first_column, double per_mm) {
    std::vector<double> x;
    for (std::size_t i = 0; i < cells.size(); ++i) {
      double value = 0.0;
      if (!ParseDouble(cells[i], value)) {
        Refuse(fmt::format("column {}: the X '{}' is not a number", first_column + i + 1, cells[i]));
      }
      x.push_back(value / per_mm);
    }
    if (x.empty()) Refuse("no X columns");
    if (scan_.x_mm.empty()) {
      scan_.x_mm = std::move(x);
      return;
    }
    for (std::size_t i = 0; i < std::max(x.size(), scan_.x_mm.size()); ++i) {
      if (i >= x.size() || i >= scan_.x_mm.size() || x[i] != scan_.x_mm[i]) {
        Refuse(fmt::format("the X columns change from frame {} at column {} ({} mm, was {} mm)",
                           scan_.frames(), first_column + i + 1, i < x.size() ? x[i] : kNaN,
                           i < scan_.x_mm.size() ? scan_.x_mm[i] : kNaN));
      }
    }
  }

  // One frame's readings from cell `first_cell` on: an empty cell is invalid (Gocator); LJ's
  // invalid values are its most negative integers.
  void ReadFrameRow(std::string_view line, char separator, std::size_t first_cell, std::size_t frame,
                    double per_mm) {
    const std::size_t points = scan_.points();
    const std::size_t start = scan_.z_mm.size();
    scan_.z_mm.resize(start + points, kNaN);
    std::size_t cells = 0;
    ForEachCell(line, separator, [&](std::size_t index, std::string_view cell) {
      if (index < first_cell) return;
      const std::size_t column = index - first_cell;
      cell = TrimBlanks(cell);
      if (column >= points) {
        if (!cell.empty()) {
          Refuse(
              fmt::format("frame {} has a reading in column {}, beyond the {} X columns (X columns that "
                          "change without saying so)",
                          frame, index + 1, points));
        }
        return;
      }
      ++cells;
      if (cell.empty()) return;
      double value = 0.0;
      if (!ParseDouble(cell, value)) {
        Refuse(fmt::format("frame {} column {}: '{}' is not a number", frame, index + 1, cell));
      }
      if (value > kKeyenceLjInvalidBelow || per_mm == 1.0) scan_.z_mm[start + column] = value / per_mm;
    });
    if (cells < points) {
      Refuse(
          fmt::format("frame {} has {} readings for {} X columns (X columns that change without saying so)",
                      frame, cells, points));
    }
  }

  std::string text_;
  TextLines lines_;
  std::string stage_;
  ProfileScan scan_;
  int trigger_mode_ = 0;
  double first_ticks_ = 0.0;
  std::vector<double> frame_numbers_;
};

// The contract's layout: /profile/z [frames, points], /profile/x_mm [points] (or [frames, points],
// every row the same), optional /profile/t and /profile/encoder [frames]; attributes on /profile.
// `z_into` gives the room for /profile/z's values (the child's shared pages), or is null to leave
// them to the caller (the parent, which takes what the child read).
ProfileScan ReadProfileHdf5(const hdf5::File& file,
                            const std::function<std::span<double>(std::size_t)>& z_into) {
  const std::string stage = StageOf(ScanFormat::kProfileHdf5);
  ProfileScan scan;
  scan.path = file.path().string();
  scan.read.format = "profile-hdf5";
  const auto refuse = [&](const std::string& problem) {
    throw Error(ErrorCode::kBadInput, stage, fmt::format("'{}': {}", scan.path, problem));
  };
  if (!file.HasObject("/profile/z") || !file.HasObject("/profile/x_mm"))
    refuse("no /profile/z and /profile/x_mm");
  const std::vector<hsize_t> shape = file.Shape("/profile/z");
  if (shape.size() != 2) refuse("/profile/z must be [frames, points]");
  if (z_into) file.ReadInto("/profile/z", z_into(file.NumericCount("/profile/z", sizeof(double))));
  const std::vector<hsize_t> x_shape = file.Shape("/profile/x_mm");
  const std::vector<double> x = file.ReadDoubles("/profile/x_mm");
  const std::size_t points = shape[1];
  if (x_shape.back() != points) {
    refuse(fmt::format("/profile/x_mm has {} columns, /profile/z {}", x_shape.back(), points));
  }
  scan.x_mm.assign(x.begin(), x.begin() + static_cast<long>(points));
  for (std::size_t i = points; i < x.size(); ++i) {
    if (x[i] != x[i % points]) {
      refuse(fmt::format("/profile/x_mm: the X columns change at frame {} column {} ({} mm, was {} mm)",
                         i / points, i % points, x[i], x[i % points]));
    }
  }
  if (file.HasObject("/profile/t")) scan.t_s = file.ReadDoubles("/profile/t");
  if (file.HasObject("/profile/encoder")) scan.encoder = file.ReadDoubles("/profile/encoder");
  MetadataSetter setter(scan.metadata);
  for (const std::string& name : file.AttributeNames("/profile")) {
    if (name == "encoder_counts_per_rev") {
      scan.placement.encoder_counts_per_rev = file.ReadAttributeDouble("/profile", name).value_or(0.0);
      continue;
    }
    const std::string key = setter.Claim(name);
    if (key.empty()) continue;
    if (MetadataSetter::IsNumeric(key)) {
      if (const auto value = file.ReadAttributeDouble("/profile", name)) setter.SetNumber(key, *value);
    } else if (const auto text = file.ReadAttributeString("/profile", name)) {
      setter.SetText(key, *text);
    }
  }
  if (!scan.t_s.empty()) {
    const double t0 = scan.t_s.front();
    for (double& t : scan.t_s) t -= t0;
  }
  scan.read.columns = {{"z", "/profile/z", "mm"}, {"x", "/profile/x_mm", "mm"}};
  return scan;
}

// The placement and the encoder's counts come from the settings file only.
void ApplyProfileSettings(const ScanSettingsFile* settings, ProfileScan& scan) {
  Scan carrier;
  carrier.path = scan.path;
  carrier.metadata = std::move(scan.metadata);
  carrier.read = std::move(scan.read);
  ApplyScanSettings(settings, carrier);
  scan.metadata = std::move(carrier.metadata);
  scan.read = std::move(carrier.read);
  if (settings == nullptr) return;
  ProfilePlacement& p = scan.placement;
  p.encoder_counts_per_rev = settings->Number("encoder_counts_per_rev").value_or(p.encoder_counts_per_rev);
  p.tilt_deg = settings->Number("sensor_tilt_deg").value_or(0.0);
  p.tilt_u_deg = settings->Number("sensor_tilt_u_deg").value_or(0.0);
  p.axial_offset_mm = settings->Number("sensor_axial_offset_mm").value_or(0.0);
  p.axial_offset_u_mm = settings->Number("sensor_axial_offset_u_mm").value_or(0.0);
}

// An encoder that counts within the turn wraps to 0 at encoder_counts_per_rev: unwrapped here.
void UnwrapEncoder(ProfileScan& scan, const std::string& stage) {
  const double per_rev = scan.placement.encoder_counts_per_rev;
  double turns = 0.0;
  for (std::size_t f = 1; f < scan.encoder.size(); ++f) {
    const double before = scan.encoder[f - 1];
    double now = scan.encoder[f] + turns;
    if (now < before) {
      const double wrapped = now + per_rev;
      if (per_rev <= 0.0 || !(wrapped > before) || !(wrapped - before < per_rev / 2.0)) {
        throw Error(
            ErrorCode::kBadInput, stage,
            fmt::format("'{}' frame {} column 'encoder': the encoder goes from {} to {} (backwards, or a "
                        "wrap not at encoder_counts_per_rev = {})",
                        scan.path, f, before - turns, scan.encoder[f], per_rev));
      }
      turns += per_rev;
      now = wrapped;
    }
    scan.encoder[f] = now;
  }
}

}  // namespace

bool IsProfileFormat(ScanFormat format) {
  return format == ScanFormat::kProfileHdf5 || format == ScanFormat::kGocator ||
         format == ScanFormat::kKeyenceLj;
}

double ProfileScan::PhaseDeg(std::size_t frame) const {
  const double start = metadata.start_phase_deg;
  if (!encoder.empty() && placement.encoder_counts_per_rev > 0.0) {
    return start + 360.0 * (encoder[frame] - encoder.front()) / placement.encoder_counts_per_rev;
  }
  const double rpm = metadata.spindle_rpm.value_or(0.0);
  const double t =
      t_s.empty() ? static_cast<double>(frame) * metadata.sample_period_s.value_or(0.0) : t_s[frame];
  return start + 6.0 * rpm * t;
}

ProfileScan ParseProfileScan(std::string text, const std::string& name, ScanFormat format,
                             const ScanSettingsFile* settings) {
  ARCWHEEL_CHECK(format == ScanFormat::kGocator || format == ScanFormat::kKeyenceLj);
  ProfileTextParser parser(std::move(text), name, format);
  ProfileScan scan = format == ScanFormat::kGocator ? parser.Gocator() : parser.KeyenceLj();
  ApplyProfileSettings(settings, scan);
  if (!scan.encoder.empty()) UnwrapEncoder(scan, StageOf(format));
  ValidateProfileScan(scan);
  return scan;
}

ProfileScan ReadProfileScan(const std::filesystem::path& path, ScanFormat format,
                            const ScanSettingsFile* settings) {
  if (format != ScanFormat::kProfileHdf5) {
    return ParseProfileScan(ReadWholeFile(path, StageOf(format)), path.string(), format, settings);
  }
  // The readings are read once, in the child process that guards against libhdf5 crashing on a
  // damaged file (core/hdf5.h); here only the header and the small columns are read again.
  hdf5::SharedArrays arrays;
  const bool handed = hdf5::ReadInChildProcess(path, arrays, [&](hdf5::SharedArrays& shared) {
    internal::ReadProfileInChild(hdf5::File::OpenReadOnly(path), shared);
  });
  return internal::ProfileFromChild(hdf5::File::OpenReadOnly(path), arrays, handed, settings);
}

namespace internal {

void ReadProfileInChild(const hdf5::File& file, hdf5::SharedArrays& shared) {
  (void)ReadProfileHdf5(file,
                        [&](std::size_t count) { return shared.Allocate<double>("/profile/z", count); });
}

ProfileScan ProfileFromChild(const hdf5::File& file, hdf5::SharedArrays& arrays, bool handed,
                             const ScanSettingsFile* settings) {
  ProfileScan scan = ReadProfileHdf5(file, nullptr);
  if (std::optional<std::vector<double>> z = handed ? arrays.Take<double>("/profile/z") : std::nullopt) {
    scan.z_mm = std::move(*z);
  } else {
    scan.z_mm = file.ReadDoubles("/profile/z");
  }
  if (scan.metadata.invalid_value) {
    for (double& z_mm : scan.z_mm) {
      if (z_mm == *scan.metadata.invalid_value) z_mm = kNaN;
    }
  }
  ApplyProfileSettings(settings, scan);
  if (!scan.encoder.empty()) UnwrapEncoder(scan, StageOf(ScanFormat::kProfileHdf5));
  ValidateProfileScan(scan);
  return scan;
}

}  // namespace internal

void ValidateProfileScan(const ProfileScan& scan) {
  const std::string stage =
      "acquisition." + (scan.read.format.empty() ? std::string("profile") : scan.read.format);
  const auto refuse = [&](const std::string& problem) {
    throw Error(ErrorCode::kBadInput, stage, fmt::format("'{}': {}", scan.path, problem));
  };
  const std::size_t points = scan.points(), frames = scan.frames();
  if (points == 0 || frames == 0 || scan.z_mm.size() != frames * points) refuse("no frames");
  if (!scan.t_s.empty() && scan.t_s.size() != frames)
    refuse(fmt::format("{} times for {} frames", scan.t_s.size(), frames));
  if (!scan.encoder.empty() && scan.encoder.size() != frames) {
    refuse(fmt::format("{} encoder counts for {} frames", scan.encoder.size(), frames));
  }
  for (std::size_t f = 1; f < scan.t_s.size(); ++f) {
    if (!(scan.t_s[f] > scan.t_s[f - 1]))
      refuse(fmt::format("frame {} column 't': the time does not increase (frames out of order)", f));
  }
  for (std::size_t f = 1; f < scan.encoder.size(); ++f) {
    if (scan.encoder[f] < scan.encoder[f - 1])
      refuse(fmt::format("frame {} column 'encoder': the encoder goes backwards", f));
  }
  for (std::size_t f = 0; f < frames; ++f) {
    const auto row = scan.z_mm.begin() + static_cast<long>(f * points);
    const auto valid = static_cast<std::size_t>(
        std::count_if(row, row + static_cast<long>(points), [](double z) { return std::isfinite(z); }));
    if (valid < kMinValidPointsPerFrame) {
      refuse(fmt::format("frame {} has {} valid points, a section needs at least {}", f, valid,
                         kMinValidPointsPerFrame));
    }
  }
  const bool by_encoder = !scan.encoder.empty() && scan.placement.encoder_counts_per_rev > 0.0;
  const bool by_time = scan.metadata.spindle_rpm && (!scan.t_s.empty() || scan.metadata.sample_period_s);
  if (!by_encoder && !by_time) {
    refuse(scan.encoder.empty()
               ? "no phase for the frames: give spindle_rpm and, without a time column, sample_period_s (the "
                 "frame "
                 "period) in --scan-settings"
               : "the frames carry encoder counts: give encoder_counts_per_rev in --scan-settings");
  }
}

}  // namespace arcwheel::acquisition
