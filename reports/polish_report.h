#pragma once
// Polishing reports (stage id reports.polish): polish_report.pdf and polish_report.html, drawn
// from the files `arcwheel polish` writes (reports/polish_report_inputs.h) alone.
//
// Content: the job (name, surface, aperture, removal function, error map) and the source files
// with their SHA-256; a table of PV/RMS before (the error) and after (the predicted residual),
// total dwell time, point count, speed range, largest acceleration and solver iterations, with
// PV, RMS and total time printed exactly as polish_summary.json writes them; heat maps of the
// removal target, the predicted removal and the predicted residual on one shared colour scale,
// and of the residual on its own scale; the path coloured by speed and by dwell; the speed along
// the path with the machine's speed limits; the job as used.

#include <filesystem>
#include <string>
#include <vector>

#include "reports/polish_report_inputs.h"
#include "reports/report_content.h"

namespace arcwheel::reports {

struct PolishReportContent {
  std::string title;                 // "Polishing report: JOB NAME"
  std::vector<KeyValue> provenance;  // job, surface, aperture, removal function, files, versions
  // Rows of {quantity, before, after}: PV and RMS over the aperture.
  std::vector<std::vector<std::string>> form;
  std::vector<KeyValue> path;                          // dwell time, points, speeds, acceleration, solver
  std::vector<std::vector<ReportFigure>> figure_rows;  // figures laid side by side per row
  std::vector<KeyValue> job;                           // job as used, dotted keys
};

// Builds the report from its inputs. Pure: no I/O.
[[nodiscard]] PolishReportContent ComposePolishReport(const PolishReportInputs& inputs);

// The HTML document (self-contained, like the wheel report's), UTF-8.
[[nodiscard]] std::string RenderPolishHtml(const PolishReportContent& content);

// Writes the A4 PDF to `path` (no temporary: WritePolishReports stages it). Throws Error{kIo}.
void RenderPolishPdf(const PolishReportContent& content, const std::filesystem::path& path);

struct WrittenPolishReports {
  std::filesystem::path html;
  std::filesystem::path pdf;
};

// Reads OUTDIR's polish outputs and writes OUTDIR/polish_report.html and OUTDIR/polish_report.pdf
// together: both are staged under temporary names and renamed only when both are complete, so
// a refused input or a failure leaves no new or partial file (and earlier reports intact).
WrittenPolishReports WritePolishReports(const std::filesystem::path& outdir);

}  // namespace arcwheel::reports
