#pragma once
// A raw helical wheel scan as read from disk (formats.md section 2), before any processing.

#include <cstddef>
#include <initializer_list>
#include <iterator>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <utility>
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
  // The keys above (formats.md 2.1 names) that the file itself gave, in the order read; a key
  // not listed holds its default. Settings from outside the file (scan_settings.h) may fill the
  // others, never contradict these.
  std::vector<std::string> file_keys;
};

// What a reader read, for summary.json's `input` (formats.md 2.4).
struct ScanReadRecord {
  // The format's name in scan_format.h ("csv", "sensortool", ...); empty for a scan no reader made.
  std::string format;
  // One quantity of the scan ("z", "t", "angle", "y") and the file's column that held it.
  struct Column {
    std::string quantity;
    std::string name;  // the column's header as written (UTF-8)
    std::string unit;  // the unit it was read in ("mm", "um", "ms", ...)
  };
  std::vector<Column> columns;
  // Invalid samples by the marker that made them ("empty", "out_of_range_high", "alarm", ...), in
  // the order first met; only markers that occurred.
  std::vector<std::pair<std::string, std::size_t>> invalid_markers;
  // The --scan-settings file, and for every setting in effect where it came from: "file" or
  // "settings" (formats.md 2.1 key -> source), in the order of formats.md.
  std::string settings_path;
  std::vector<std::pair<std::string, std::string>> sources;
};

// float32 readings, held in a vector of this process or in the pages that a reader's child process
// filled and this process has mapped (core/hdf5.h, SharedArrays::Map): a 1e8-sample scan's 400 MB
// then reach the processing without a copy. Writable in place either way; a copy is a vector.
class FloatColumn {
 public:
  FloatColumn() = default;
  FloatColumn(std::vector<float> values) : owned_(std::move(values)), values_(owned_) {}  // NOLINT
  FloatColumn(std::initializer_list<float> values) : FloatColumn(std::vector<float>(values)) {}
  // `values` live as long as `owner` (a mapping, say) does.
  FloatColumn(std::span<float> values, std::shared_ptr<void> owner)
      : owner_(std::move(owner)), values_(values) {}
  FloatColumn(const FloatColumn& other) : FloatColumn(std::vector<float>(other.begin(), other.end())) {}
  FloatColumn(FloatColumn&& other) noexcept { *this = std::move(other); }
  FloatColumn& operator=(const FloatColumn& other) { return *this = FloatColumn(other); }
  FloatColumn& operator=(FloatColumn&& other) noexcept;
  ~FloatColumn() = default;

  [[nodiscard]] float* begin() { return values_.data(); }
  [[nodiscard]] float* end() { return values_.data() + values_.size(); }
  [[nodiscard]] const float* begin() const { return values_.data(); }
  [[nodiscard]] const float* end() const { return values_.data() + values_.size(); }
  [[nodiscard]] auto rbegin() const { return std::make_reverse_iterator(end()); }
  [[nodiscard]] auto rend() const { return std::make_reverse_iterator(begin()); }
  [[nodiscard]] float* data() { return values_.data(); }
  [[nodiscard]] const float* data() const { return values_.data(); }
  [[nodiscard]] std::size_t size() const { return values_.size(); }
  [[nodiscard]] bool empty() const { return values_.empty(); }
  [[nodiscard]] float& operator[](std::size_t i) { return values_[i]; }
  [[nodiscard]] float operator[](std::size_t i) const { return values_[i]; }
  // Gives the memory back (a vector's capacity, or the mapping).
  void Release() { *this = FloatColumn(); }

 private:
  std::vector<float> owned_;
  std::shared_ptr<void> owner_;
  std::span<float> values_;
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
  FloatColumn z_float_mm;
  std::vector<double> t_s;
  std::vector<double> angle_deg;
  std::vector<double> y_mm;
  ScanReadRecord read;

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
