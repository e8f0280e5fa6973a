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
          (void)workflows::RunPolishStep(arguments->job, std::nullopt, arguments->output);
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
