#pragma once
// Wheel inspection reports (stage ids reports.html and reports.pdf), drawn from summary.json and
// wheel_map.h5 alone (reports/report_inputs.h), without the raw scan.
//
// report.html: one self-contained file (inline CSS and inline SVG plots, no script, no network, no
//   external file), readable on a phone (fluid layout, plots scale to the screen) and printable.
// report.pdf: A4 portrait, vector plots, the same content.
// Content: header with provenance and scan settings; headline table with pass/fail against the
// tolerances (reports/tolerances.h); the plots; the processing parameters and warnings.

#include <filesystem>
#include <string>

#include "reports/report_content.h"
#include "reports/tolerances.h"

namespace arcwheel::reports {

// The HTML document, UTF-8.
[[nodiscard]] std::string RenderHtml(const ReportContent& content);

// Writes the PDF to `path` (no temporary file: callers stage it, see WriteReports). Throws
// Error{kIo} if cairo cannot write it.
void RenderPdf(const ReportContent& content, const std::filesystem::path& path);

struct WrittenReports {
  std::filesystem::path html;
  std::filesystem::path pdf;
  Verdict overall = Verdict::kNoTolerance;
};

// Reads OUTDIR/summary.json and OUTDIR/wheel_map.h5 and writes OUTDIR/report.html and
// OUTDIR/report.pdf together: both are staged under temporary names and renamed into place only
// when both are complete, so a failure leaves no new or partial file. Throws Error as
// ReadReportInputs does, or Error{kIo} when writing fails.
WrittenReports WriteReports(const std::filesystem::path& outdir, const Tolerances& tolerances);

}  // namespace arcwheel::reports
