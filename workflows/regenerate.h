#pragma once
// `arcwheel regenerate`: after a dressing, the chain scan -> wheel -> toolpath with the measured
// wheel -> predicted form error -> polishing program, each step in its own folder of OUTDIR with
// the files of the single command, and one report (docs/regenerate.md). A step whose inputs
// (SHA-256 of its files, its options) are unchanged is not redone.

#include <string>

#include "grinding/job.h"

namespace arcwheel::workflows {

struct RegenerateOptions {
  std::string scan;  // raw wheel scan (.h5/.hdf5 or .csv)
  // How the scan is read (formats.md 2.4, `process --scan-settings/--format/--columns`); empty: as
  // `process` reads it by default.
  std::string scan_settings;
  std::string scan_format;
  std::string columns;
  std::string job;       // toolpath job of the part (docs/grinding.md)
  std::string polish;    // polishing job; empty: no polishing step
  std::string output;    // OUTDIR
  std::string previous;  // an earlier regeneration to compare with; empty: the latest beside OUTDIR
  // The map polished: "prediction" (what the regenerated toolpath leaves) or "nominal-path".
  std::string polish_map = "prediction";
  // The measured wheel for the toolpath: "mean" (per-phase fits) or "model".
  std::string wheel_profile = "mean";
  double max_wheel_change_mm = grinding::kDefaultMaxWheelChangeMm;
  // The results store the steps that ran are recorded into (`--db`); empty: ARCWHEEL_DB, else none.
  std::string db;
};

// Runs (or reuses) every step and writes the report and OUTDIR/regenerate.json, printing a line
// per step on stdout. A failing step leaves the earlier steps' outputs complete and the later ones
// absent; its Error keeps its code and names the step. With a store, the store is opened before
// any step runs and the steps that ran (not those reused) are recorded once the report is written.
void RunRegenerate(const RegenerateOptions& options);

}  // namespace arcwheel::workflows
