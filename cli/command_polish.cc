// arcwheel polish JOB -o OUTDIR (issue: polishing-robot correction).

#include <fmt/core.h>

#include <chrono>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "polishing/job.h"
#include "reports/polish_report.h"

namespace arcwheel::cli {

void AddPolishCommand(CLI::App& app) {
  struct Arguments {
    std::string job;
    std::string output;
    std::vector<std::string> report_formats;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "polish", "dwell time, tool frames and an ABB RAPID program that polish an error map away");
  command->add_option("JOB", arguments->job, "job file (JSON, see docs/polishing.md)")->required();
  command->add_option("-o,--output", arguments->output, "output folder")->required();
  command
      ->add_option("--report", arguments->report_formats,
                   "also render the polishing report: html,pdf (both are written, docs/reports.md)")
      ->delimiter(',')
      ->check(CLI::IsMember({"html", "pdf"}));
  command->callback([arguments] {
    const auto start = std::chrono::steady_clock::now();
    const polishing::PolishJob job = polishing::ReadPolishJob(arguments->job);
    const polishing::PolishRunReport report = polishing::RunPolishJob(job, arguments->output);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const polishing::DwellSolution& d = report.dwell;
    fmt::print(
        "{} dwell points; error PV {:.4f} um, RMS {:.4f} um -> predicted residual PV {:.4f} um, "
        "RMS {:.4f} um over {} aperture nodes\n",
        report.points, d.before.pv_um, d.before.rms_um, d.after.pv_um, d.after.rms_um, d.before.nodes);
    fmt::print("total dwell {:.1f} s; speeds {:.3f} .. {:.3f} mm/s, up to {:.1f} mm/s^2; {} iterations{}\n",
               d.total_time_s, report.min_speed_mm_s, report.max_speed_mm_s, d.max_acceleration_mm_s2,
               d.iterations, d.converged ? "" : " (iteration limit reached)");
    fmt::print("wrote {} in {:.2f} s\n", arguments->output, seconds);
    if (!arguments->report_formats.empty()) {
      // Drawn from the files just written, exactly as `arcwheel report OUTDIR` would.
      const reports::WrittenPolishReports written = reports::WritePolishReports(arguments->output);
      fmt::print("report: {}\n        {}\n", written.html.string(), written.pdf.string());
    }
  });
}

}  // namespace arcwheel::cli
