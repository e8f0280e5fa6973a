#pragma once
// A raw helical wheel scan as read from disk (formats.md section 2), before any processing.

#include <cstddef>
#include <optional>
#include <string>
#include <vector>

namespace arcwheel::acquisition {

// The scan's settings and provenance: the HDF5 attributes on /scan, or the CSV's `# key: value`
// lines. Optional fields are empty when the file does not give them.
struct ScanMetadata {
  std::optional<double> spindle_rpm;      // nominal spindle speed, > 0
  std::optional<double> feed_mm_per_min;  // axial feed of the wheel past the sensor, > 0
  std::optional<double> sample_period_s;  // time between samples, > 0
  double radius_sign = 1.0;               // rho = radius_sign * z; +1 or -1
  double start_y_mm = 0.0;                // axial position of the first sample
  double start_phase_deg = 0.0;           // phase of the first sample (no encoder)
  std::optional<double> invalid_value;    // z equal to this marks an invalid sample
  std::optional<double> range_min_mm;     // z outside [range_min_mm, range_max_mm] is invalid
  std::optional<double> range_max_mm;
  std::optional<double> wheel_diameter_mm;
  std::optional<double> wheel_width_mm;
  std::string wheel_id;
  std::string sensor;
  std::string operator_name;
  std::string timestamp;  // ISO 8601, as given
  // What the reader noticed and the user should see (summary.json `warnings`): keys it did not
  // use, text it read as Latin-1, an index column it skipped.
  std::vector<std::string> notes;
};

// Column-wise samples. `z_mm` always has one entry per row of the file; invalid samples are NaN
// (the readers fold invalid_value, the range limits and alarm words into NaN). The optional
// columns are empty when absent, else as long as z_mm.
struct Scan {
  std::string path;  // the file it came from, for messages and provenance
  ScanMetadata metadata;
  std::vector<double> z_mm;
  // The readings as float32, when the file stores them so and the reader was asked to keep them
  // (ReadOptions::keep_float32): z_mm is then empty. Every processing step reads them widened to
  // double, exactly, so the results are those of z_mm; a 1e8-sample scan takes 400 MB instead of
  // 800 MB.
  std::vector<float> z_float_mm;
  std::vector<double> t_s;
  std::vector<double> angle_deg;
  std::vector<double> y_mm;

  [[nodiscard]] std::size_t size() const { return holds_float() ? z_float_mm.size() : z_mm.size(); }
  [[nodiscard]] bool holds_float() const { return !z_float_mm.empty(); }
  // Moves the float32 readings into z_mm as double (exact), for steps that change readings by
  // arithmetic (the beam-offset correction, the moving-mean despiker).
  void WidenToDouble();
  [[nodiscard]] bool has_time() const { return !t_s.empty(); }
  [[nodiscard]] bool has_encoder() const { return !angle_deg.empty(); }
  [[nodiscard]] bool has_axial() const { return !y_mm.empty(); }
  // Number of samples with a finite z.
  [[nodiscard]] std::size_t CountValid() const;
};

// Calls f(readings) with z_float_mm or z_mm, whichever holds the readings.
template <typename ScanType, typename F>
decltype(auto) VisitReadings(ScanType& scan, F&& f) {
  return scan.holds_float() ? f(scan.z_float_mm) : f(scan.z_mm);
}

// Checks everything formats.md 2.3 asks of a scan that does not need processing to see:
// required settings present and positive, radius_sign +-1, columns of equal length, finite
// optional columns, at least one valid sample, and phase/axial coverage of at least 2 turns
// and 3 helix pitches (judged from the nominal settings and the valid samples' extent).
// Throws Error{kBadInput} naming scan.path and the problem.
void ValidateScan(const Scan& scan);

}  // namespace arcwheel::acquisition
