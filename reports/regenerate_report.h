#pragma once
// The report of `arcwheel regenerate` (docs/regenerate.md): one page that chains the steps after a
// dressing, wheel verdict, toolpath, predicted form error and polishing plan, and what changed
// since the previous regeneration. The command gathers the figures from the steps' own files;
// this unit lays them out as HTML and PDF with the machinery the other reports use.

#include <filesystem>
#include <string>
#include <vector>

#include "reports/report_content.h"

namespace arcwheel::reports {

// A grid map to draw: values[j * x_mm.size() + i] at (x_mm[i], y_mm[j]), NaN = no data.
struct ChainMap {
  std::string caption{};
  std::vector<double> x_mm{};
  std::vector<double> y_mm{};
  std::vector<double> values_um{};
};

struct ChainStep {
  std::string title;   // e.g. "1. Wheel verdict"
  std::string status;  // e.g. "done", "reused (inputs unchanged)", "not run: no polishing job"
  std::vector<KeyValue> rows{};
};

struct RegenerateReportContent {
  std::string title;
  std::vector<KeyValue> provenance;
  std::vector<ChainStep> steps;
  std::vector<ChainMap> maps;
  std::string previous;                           // the previous regeneration's folder, or ""
  std::vector<std::vector<std::string>> changes;  // quantity, previous, now, change
};

struct WrittenRegenerateReport {
  std::filesystem::path html;
  std::filesystem::path pdf;
};

// Writes OUTDIR/regenerate_report.html and .pdf together (neither on failure). Throws Error{kIo}.
WrittenRegenerateReport WriteRegenerateReport(const RegenerateReportContent& content,
                                              const std::filesystem::path& outdir);

}  // namespace arcwheel::reports
