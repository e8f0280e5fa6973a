#pragma once
// Two scans of one wheel compared (stage id reports.compare): before and after a dressing, or two
// sensors. From two `arcwheel process` output folders (summary.json and wheel_map.h5 each):
//   - the change of each headline number, after minus before, with its combined 1-sigma
//     sqrt(s_before^2 + s_after^2) where both summaries record one, and whether the change is
//     significant: |change| > 3 sigma. A number without a recorded sigma (the peak-to-valley
//     figures) gets its change only.
//   - the difference of the radial maps rho(c, y), after minus before, on a common grid: the
//     before map's phase nodes and the axial nodes of the finer map inside the axial range both
//     cover, each map interpolated bilinearly (periodic in phase).
// Writes OUTDIR/compare.json, OUTDIR/compare.html and OUTDIR/compare.pdf together.

#include <filesystem>
#include <nlohmann/json_fwd.hpp>
#include <string>
#include <vector>

#include "reports/report_content.h"
#include "reports/report_inputs.h"

namespace arcwheel::reports {

inline constexpr double kSignificanceSigmas = 3.0;

struct HeadlineChange {
  std::string key;  // summary.json key; "model." prefix for the wheel model's numbers
  std::string label;
  Unit unit;
  double before = 0.0;
  double after = 0.0;
  double before_sigma = 0.0;  // NaN when not recorded
  double after_sigma = 0.0;
  double change = 0.0;  // after - before
  double sigma = 0.0;   // sqrt(before_sigma^2 + after_sigma^2), NaN when either is missing
  bool significant = false;
};

struct MapDifference {
  std::vector<double> phase_deg;
  std::vector<double> y_mm;
  std::vector<double> difference_um;  // [n_phase, n_y], NaN where either map has no value
  double median_um = 0.0;
  double rms_um = 0.0;  // about zero
  double min_um = 0.0;
  double max_um = 0.0;
};

struct Comparison {
  std::filesystem::path before_dir;
  std::filesystem::path after_dir;
  std::string wheel_id;
  std::string before_timestamp;
  std::string after_timestamp;
  std::vector<HeadlineChange> changes;
  MapDifference map;
  double band_low_mm = 0.0;  // the before scan's band
  double band_high_mm = 0.0;
};

// Compares two scans. Throws Error{kBadInput} when they name different wheels (both record a
// wheel id and they differ) or their maps have no axial range in common.
[[nodiscard]] Comparison CompareScans(const ReportInputs& before, const ReportInputs& after);

// The map of `source` interpolated at (phase_deg, y_mm), bilinear and periodic in phase; NaN
// outside its axial nodes or where a neighbour has no value.
[[nodiscard]] double InterpolateRho_mm(const WheelMapData& source, double phase_deg, double y_mm);

[[nodiscard]] nlohmann::json ComparisonJson(const Comparison& comparison);

struct WrittenComparison {
  std::filesystem::path json;
  std::filesystem::path html;
  std::filesystem::path pdf;
};

// Reads both folders and writes OUTDIR/compare.json, .html and .pdf (created if needed), all or
// none. Throws as ReadReportInputs and CompareScans, Error{kIo} when writing fails.
WrittenComparison WriteComparison(const std::filesystem::path& before_dir,
                                  const std::filesystem::path& after_dir,
                                  const std::filesystem::path& outdir);

}  // namespace arcwheel::reports
