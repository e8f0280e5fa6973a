#pragma once
// Writes a toolpath job's outputs into a folder, all or nothing (core/atomic_file.h):
//   toolpath.csv   formats.md section 6: `# ` header lines naming the surface, the wheel and the
//                  arcwheel version, then xw_mm,yw_mm,zw_mm,x_mm,y_mm,z_mm,nx,ny,nz,feed_mm_min,
//                  row,pass with every number at full (shortest round-trip) precision;
//   toolpath.nc    ISO G-code: G90 G21, G01 moves of the wheel centre with F in mm/min;
//   toolpath.pmc   PMAC/UMAC motion program: OPEN PROG n CLEAR, ABS, LINEAR, F, moves, CLOSE;
//   prediction.h5  the predicted form-error map (prediction.h), when enabled;
//   toolpath_summary.json  the job as used (defaults filled in), counts and checks, PV / RMS.
// Machine programs round coordinates to `machine.decimals` and say so in their header.

#include <filesystem>
#include <string>

#include "grinding/job.h"

namespace arcwheel::grinding {

struct ToolpathRunReport {
  ToolpathSummary toolpath;
  bool predicted = false;
  FormPrediction prediction;
};

// Generates the toolpath of `job` (streamed to the files row by row) and, if enabled, the
// prediction; commits every file at the end. Throws what GenerateToolpath / PredictFormError
// throw, or Error{kIo}; on any error no new file is left in `output_folder`.
ToolpathRunReport RunToolpathJob(const Job& job, const std::filesystem::path& output_folder);

// Appends the CSV lines of `row` (formats.md section 6, shortest round-trip numbers) to `out`.
void AppendCsvLines(const ToolpathRow& row, double feed_mm_per_min, std::string& out);

// "arc radius: measured R mm (1-sigma s mm), used; nominal N mm (job); difference ..." for the
// headers and the terminal.
[[nodiscard]] std::string ArcRadiusLine(const WheelChange& change);

// The header lines shared by the three toolpath files (without comment markers).
[[nodiscard]] std::vector<std::string> ToolpathHeaderLines(const Job& job);

}  // namespace arcwheel::grinding
