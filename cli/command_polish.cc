// arcwheel polish JOB -o OUTDIR (issue: polishing-robot correction).

#include <fmt/core.h>

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "polishing/job.h"
#include "reports/polish_report.h"
#include "store/records.h"
#include "workflows/record.h"
#include "workflows/steps.h"

namespace arcwheel::cli {
namespace {

// The segments slowed for the robot's joints, and what they cost (docs/polishing.md).
void PrintSlowed(const polishing::TimeScaling& slowing) {
  if (slowing.slowed.empty()) return;
  double most = 1.0;
  std::size_t most_target = 0;
  for (const polishing::SlowedSegment& s : slowing.slowed) {
    if (s.slowed_s / s.planned_s > most) {
      most = s.slowed_s / s.planned_s;
      most_target = s.target + 1;
    }
  }
  fmt::print(
      "slowed {} segments for the robot's joints (most: into target {}, {:.3g} times as long): {:.4g} s "
      "added, adding up to {:.4g} nm of removal (RMS {:.4g} nm) at ({:.3f}, {:.3f}) mm, in the prediction; "
      "listed in polish_summary.json robot.slowed_segments\n",
      slowing.slowed.size(), most_target, most, slowing.added_time_s, slowing.added.max_nm,
      slowing.added.rms_nm, slowing.added.max_at_mm.x(), slowing.added.max_at_mm.y());
}

}  // namespace

void AddPolishCommand(CLI::App& app) {
  struct Arguments {
    std::string job;
    std::string output;
    std::vector<std::string> report_formats;
    bool place_workobject = false;
    std::string db;
  };
  auto arguments = std::make_shared<Arguments>();
  CLI::App* command = app.add_subcommand(
      "polish", "dwell time, tool frames and an ABB RAPID program that polish an error map away");
  command->add_option("JOB", arguments->job, "job file (JSON, see docs/polishing.md)")->required();
  command->add_option("-o,--output", arguments->output, "output folder")->required();
  command->add_flag("--place-workobject", arguments->place_workobject,
                    "propose a work-object origin where the job's robot runs the path with every margin "
                    "kept, print it and its margins; writes nothing");
  command
      ->add_option("--report", arguments->report_formats,
                   "also render the polishing report: html,pdf (both are written, docs/reports.md)")
      ->delimiter(',')
      ->check(CLI::IsMember({"html", "pdf"}));
  AddDbOption(command, arguments->db);
  command->callback([arguments] {
    if (arguments->place_workobject) {
      const polishing::PolishJob job = polishing::ReadPolishJob(arguments->job);
      fmt::print("{}", polishing::DescribeProposal(polishing::ProposeWorkObject(job), job));
      return;
    }
    workflows::RunRecorded(
        arguments->db,
        [&] {
          const polishing::PolishRunReport report =
              workflows::RunPolishStep(arguments->job, std::nullopt, arguments->output);
          PrintSlowed(report.slowing);
          if (!arguments->report_formats.empty()) {
            // Drawn from the files just written, exactly as `arcwheel report OUTDIR` would.
            const reports::WrittenPolishReports written = reports::WritePolishReports(arguments->output);
            fmt::print("report: {}\n        {}\n", written.html.string(), written.pdf.string());
          }
        },
        [&] {
          return std::vector<store::StoredRun>{
              store::PolishRun(arguments->output, arguments->job, std::nullopt, "polish")};
        });
  });
}

}  // namespace arcwheel::cli
