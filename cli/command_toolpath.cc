// arcwheel toolpath JOB [--wheel summary.json] -o OUTDIR (issue: parallel-grinding toolpath).

#include <fmt/core.h>

#include <chrono>
#include <filesystem>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "grinding/job.h"
#include "grinding/toolpath_writer.h"

namespace arcwheel::cli {

void AddToolpathCommand(CLI::App& app) {
  struct Arguments {
    std::string job;
    std::string wheel;
    std::string output;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "toolpath",
      "parallel-grinding toolpath (CSV, G-code, PMAC) for a job file, with the predicted form error");
  command->add_option("JOB", arguments->job, "job file (JSON, see docs/grinding.md)")->required();
  command->add_option("--wheel", arguments->wheel,
                      "summary.json of the measured wheel (replaces the job's wheel.summary)");
  command->add_option("-o,--output", arguments->output, "output folder")->required();
  command->callback([arguments] {
    std::optional<std::filesystem::path> wheel;
    if (!arguments->wheel.empty()) wheel = arguments->wheel;
    const auto start = std::chrono::steady_clock::now();
    const grinding::Job job = grinding::ReadJob(arguments->job, wheel);
    const grinding::ToolpathRunReport report = grinding::RunToolpathJob(job, arguments->output);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const grinding::ToolpathSummary& t = report.toolpath;
    fmt::print(
        "{} control points in {} pass(es) of {} rows; rows straight to {:.2e} mm; "
        "{} gouge checks, smallest gap {:.3f} um\n",
        t.control_points, t.passes, t.rows_per_pass, t.max_row_deviation_mm, t.gouge_checks,
        1e3 * t.min_gouge_gap_mm);
    if (report.predicted) {
      const grinding::FormPrediction& p = report.prediction;
      fmt::print(
          "predicted form error (arc radius error {} mm{}): PV {:.3f} um, RMS {:.3f} um; "
          "after tilt PV {:.3f} um, RMS {:.3f} um; runout ripple PV {:.3f} um\n",
          job.prediction.arc_radius_error_mm,
          job.prediction.runout_radial_um.empty() ? ", no runout" : ", with runout", p.pv_um, p.rms_um,
          p.pv_after_tilt_um, p.rms_after_tilt_um, p.ripple_pv_um);
    }
    fmt::print("wrote {} in {:.2f} s\n", arguments->output, seconds);
  });
}

}  // namespace arcwheel::cli
