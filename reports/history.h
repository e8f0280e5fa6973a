#pragma once
// A wheel's history across scans and dressings (stage id reports.history): every summary.json of
// one wheel id, in the order of its scan timestamp (summary.json scan.timestamp, ISO 8601).
//
// Dressings split the history into segments: a scan belongs to the segment after the last
// dressing at or before its timestamp. In each segment with at least two scans, the wear rate is
// the weighted least-squares slope of the mean arc radius against scan time (weights 1/sigma^2,
// sigma = mean_arc_radius_sigma_mm), in um per hour of elapsed time, with its 1-sigma
// sqrt(1 / sum w (t - t_w)^2), scaled by sqrt(chi2 / dof) when the scatter about the line exceeds
// the sigmas (chi2 / dof > 1; three or more scans).
//
// Writes OUTDIR/history.csv (one row per scan), OUTDIR/history.html and OUTDIR/history.pdf.

#include <filesystem>
#include <string>
#include <vector>

#include "reports/report_inputs.h"

namespace arcwheel::reports {

struct HistoryScan {
  std::filesystem::path folder;
  std::string timestamp;  // as recorded
  double time_s = 0.0;    // seconds since 1970-01-01 UTC
  int segment = 0;        // 0 before the first dressing, k after the k-th
  Summary summary;
};

struct WearRate {
  int segment = 0;
  std::size_t scans = 0;
  double rate_um_per_h = 0.0;
  double sigma_um_per_h = 0.0;
  double chi2_per_dof = 0.0;  // NaN with two scans; after the repeatability term, when one is added
  // The scatter between scans that their sigmas do not explain: when the chi-square test rejects
  // the sigmas alone (p < 0.05), s_R (um) such that chi-square / dof = 1 with sigma_i^2 + s_R^2,
  // added to every scan's sigma for the fit; 0 when not needed or with two scans.
  double repeatability_um = 0.0;
  double chi2_per_dof_scans_alone = 0.0;  // chi-square / dof with the scans' sigmas only (NaN: two scans)
  double intercept_mm = 0.0;              // fitted radius at the segment's first scan time
  double first_time_s = 0.0;
  double last_time_s = 0.0;
};

struct History {
  std::string wheel_id;
  std::vector<HistoryScan> scans;  // in time order
  std::vector<double> dressing_times_s;
  std::vector<std::string> dressing_timestamps;
  std::vector<WearRate> wear;  // segments with at least two scans
};

// Seconds since 1970-01-01 UTC of an ISO 8601 date-time "YYYY-MM-DDTHH:MM[:SS[.fff]]" with "Z", a
// "+HH:MM"/"-HH:MM" offset or none (read as UTC); a space may stand for the "T". Throws
// Error{kBadInput} with `where` (file and key or line) for anything else.
[[nodiscard]] double ParseTimestamp_s(const std::string& text, const std::string& where);

// Dressing times from a CSV: an optional header line whose first cell is not a date, then one
// date-time per line in the first column; '#' lines and blank lines are skipped. Throws
// Error{kBadInput} naming the file and line.
[[nodiscard]] std::vector<double> ParseDressingsCsv(const std::string& text, const std::string& name,
                                                    std::vector<std::string>* timestamps = nullptr);

// Weighted least-squares line through (t_s, radius_mm +- sigma_mm): the wear rate as above.
[[nodiscard]] WearRate FitWearRate(const std::vector<double>& time_s, const std::vector<double>& radius_mm,
                                   const std::vector<double>& sigma_mm);

// Reads DIR/summary.json of every folder and builds the history. Throws Error{kBadInput} when the
// folders hold more than one wheel id (naming two folders and their ids), a timestamp is missing
// or unreadable, or two scans have the same timestamp; as ReadSummary otherwise.
[[nodiscard]] History BuildHistory(const std::vector<std::filesystem::path>& folders,
                                   const std::vector<double>& dressing_times_s,
                                   const std::vector<std::string>& dressing_timestamps);

// What BuildHistory does once it has read the folders, for scans read elsewhere (the results
// store, store/history.h): orders the scans by time (refusing two of one time, naming their
// folders), assigns each its segment and fits the wear rate of each segment.
[[nodiscard]] History AssembleHistory(const std::string& wheel_id, std::vector<HistoryScan> scans,
                                      const std::vector<double>& dressing_times_s,
                                      const std::vector<std::string>& dressing_timestamps);

[[nodiscard]] std::string HistoryCsv(const History& history);

struct WrittenHistory {
  std::filesystem::path csv;
  std::filesystem::path html;
  std::filesystem::path pdf;
};

// Writes OUTDIR/history.csv, .html and .pdf (OUTDIR created if needed), all or none.
WrittenHistory WriteHistory(const History& history, const std::filesystem::path& outdir);

}  // namespace arcwheel::reports
