#pragma once
// The sensors' own layouts (formats.md 2.4, docs/inputs.md) written from a scan, as the sensors'
// software writes them, with the settings file (scan_settings.h) that supplies what the layout does
// not carry: `arcwheel simulate --as sensortool|keyence-lk`, for tests and demonstrations.

#include <filesystem>
#include <string>

#include "acquisition/scan.h"
#include "acquisition/scan_format.h"

namespace arcwheel::acquisition {

// Writes `scan` (atomically) in `format`'s layout:
// - kSensorTool: Micro-Epsilon sensorTOOL's CSV export in a German locale: a UTF-8 byte-order mark,
//   header lines (`sensorTOOL`, `Sensor;...`, `Measuring rate;10 kHz`), the column row
//   `Acquisition time;Epoch time (ms);Distance1 (mm)`, `;` separators, decimal commas, CRLF line
//   ends; an invalid sample is an empty cell.
// - kKeyenceLk: an LK-Navigator CSV export of a Keyence LK controller: header lines (`Model`,
//   `Sampling cycle`), the column row `No.,OUT1(mm)` and fixed-width values (`+01.2345`), CRLF;
//   an invalid sample is `-------` (waiting) in the first 3 samples, `-FFFFFFF` before the rim,
//   `+FFFFFFF` after it and `XXXXXXXX` (alarm) in between.
// Throws Error{kInvalidOption} for another format, Error{kIo} when the file cannot be written.
void WriteSensorScan(const Scan& scan, ScanFormat format, const std::filesystem::path& path);

// The settings file (JSON) that supplies what WriteSensorScan's layout does not carry: spindle_rpm,
// feed_mm_per_min, radius_sign, start_y_mm, start_phase_deg, wheel_id, the wheel's size and the
// timestamp.
[[nodiscard]] std::string SensorScanSettingsJson(const Scan& scan);

}  // namespace arcwheel::acquisition
