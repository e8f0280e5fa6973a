#include "acquisition/sensor_writer.h"

#include <fmt/core.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <nlohmann/json.hpp>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"

namespace arcwheel::acquisition {
namespace {

constexpr const char* kSensorWriterStage = "acquisition.write";

// The first and last valid sample: outside them the sensor sees no rim.
std::pair<std::size_t, std::size_t> ValidSpan(const Scan& scan) {
  std::size_t first = scan.z_mm.size(), last = 0;
  for (std::size_t i = 0; i < scan.z_mm.size(); ++i) {
    if (std::isfinite(scan.z_mm[i])) {
      first = std::min(first, i);
      last = i;
    }
  }
  return {first, last};
}

std::string WithComma(std::string text) {
  std::replace(text.begin(), text.end(), '.', ',');
  return text;
}

double PeriodOf(const Scan& scan) {
  if (scan.metadata.sample_period_s) return *scan.metadata.sample_period_s;
  throw Error(ErrorCode::kInvalidOption, kSensorWriterStage, "the scan has no sample period to write");
}

std::string SensorToolText(const Scan& scan) {
  const double period_s = PeriodOf(scan);
  std::string text = "\xEF\xBB\xBF";
  const auto line = [&](const std::string& l) { text += l + "\r\n"; };
  line("sensorTOOL;1.9.0");
  line("Sensor;ILD2300");
  line("Serial number;1234567");
  line("Date;13.09.2017 10:00:00");
  line(WithComma(fmt::format("Measuring rate;{:.12g} kHz", 1.0 / period_s / 1e3)));
  line("Acquisition time;Epoch time (ms);Distance1 (mm)");
  constexpr long long kEpochMs = 1505296800000;  // 2017-09-13 10:00:00 UTC
  text.reserve(text.size() + scan.z_mm.size() * 40);
  for (std::size_t i = 0; i < scan.z_mm.size(); ++i) {
    const double t_s = scan.has_time() ? scan.t_s[i] - scan.t_s[0] : static_cast<double>(i) * period_s;
    const double z = scan.z_mm[i];
    text +=
        WithComma(fmt::format("{:.6f};{};", t_s, kEpochMs + static_cast<long long>(std::floor(t_s * 1e3))));
    if (std::isfinite(z)) text += WithComma(fmt::format("{:.6f}", z));
    text += "\r\n";
  }
  return text;
}

std::string KeyenceLkText(const Scan& scan) {
  const double period_s = PeriodOf(scan);
  const auto [first, last] = ValidSpan(scan);
  std::string text;
  const auto line = [&](const std::string& l) { text += l + "\r\n"; };
  line("LK-Navigator 2");
  line("Model,LK-G5001");
  line(fmt::format("Sampling cycle,{:.12g}us", period_s * 1e6));
  line("Date,2017/09/13 10:00:00");
  line("No.,OUT1(mm)");
  text.reserve(text.size() + scan.z_mm.size() * 20);
  for (std::size_t i = 0; i < scan.z_mm.size(); ++i) {
    const double z = scan.z_mm[i];
    std::string value;
    if (std::isfinite(z) && std::abs(z) < 99.99995) {
      value = fmt::format("{:+08.4f}", z);
    } else if (std::isfinite(z)) {
      value = z > 0 ? "+FFFFFFF" : "-FFFFFFF";
    } else if (i < 3) {
      value = "-------";
    } else if (i < first) {
      value = "-FFFFFFF";
    } else if (i > last) {
      value = "+FFFFFFF";
    } else {
      value = "XXXXXXXX";
    }
    text += fmt::format("{},{}\r\n", i + 1, value);
  }
  return text;
}

}  // namespace

void WriteSensorScan(const Scan& scan, ScanFormat format, const std::filesystem::path& path) {
  std::string text;
  if (format == ScanFormat::kSensorTool) {
    text = SensorToolText(scan);
  } else if (format == ScanFormat::kKeyenceLk) {
    text = KeyenceLkText(scan);
  } else {
    throw Error(ErrorCode::kInvalidOption, kSensorWriterStage,
                fmt::format("no writer of the {} layout (sensortool or keyence-lk)", InfoOf(format).name));
  }
  WriteFileAtomically(path.string(), text);
}

std::string SensorScanSettingsJson(const Scan& scan) {
  const ScanMetadata& m = scan.metadata;
  nlohmann::json settings = nlohmann::json::object();
  if (m.spindle_rpm) settings["spindle_rpm"] = *m.spindle_rpm;
  if (m.feed_mm_per_min) settings["feed_mm_per_min"] = *m.feed_mm_per_min;
  settings["radius_sign"] = m.radius_sign;
  settings["start_y_mm"] = m.start_y_mm;
  settings["start_phase_deg"] = m.start_phase_deg;
  if (m.wheel_diameter_mm) settings["wheel_diameter_mm"] = *m.wheel_diameter_mm;
  if (m.wheel_width_mm) settings["wheel_width_mm"] = *m.wheel_width_mm;
  if (!m.wheel_id.empty()) settings["wheel_id"] = m.wheel_id;
  if (!m.timestamp.empty()) settings["timestamp"] = m.timestamp;
  return JsonText(settings, 2) + "\n";
}

}  // namespace arcwheel::acquisition
