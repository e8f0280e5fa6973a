// arcwheel report OUTDIR: renders OUTDIR/report.html and OUTDIR/report.pdf from the
// summary.json and wheel_map.h5 that `arcwheel process` wrote there, or OUTDIR/polish_report.html
// and .pdf from the outputs of `arcwheel polish`.

#include <fmt/core.h>

#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"
#include "reports/polish_report.h"
#include "reports/report.h"
#include "reports/tolerances.h"
#include "schema/polish_outputs.h"
#include "schema/summary.h"

namespace arcwheel::cli {
namespace {

struct ReportArguments {
  std::filesystem::path outdir;
  std::filesystem::path tolerance_file;
  std::vector<std::string> tolerance_flags;
};

void RunWheelReport(const ReportArguments& arguments);

void RunReport(const ReportArguments& arguments) {
  // A folder written by `arcwheel polish` gets the polishing report, one written by `process` the
  // wheel report (and a folder with neither the wheel report's refusal).
  const bool polish = std::filesystem::exists(arguments.outdir / schema::polish::kSummaryFileName);
  const bool wheel = std::filesystem::exists(arguments.outdir / schema::summary::kFileName);
  if (polish && !wheel && (!arguments.tolerance_file.empty() || !arguments.tolerance_flags.empty())) {
    throw Error(
        ErrorCode::kInvalidOption, "reports",
        "tolerances apply to the wheel report; '" + arguments.outdir.string() + "' holds no summary.json");
  }
  if (polish) {
    const reports::WrittenPolishReports written = reports::WritePolishReports(arguments.outdir);
    fmt::print("wrote {}\nwrote {}\n", written.html.string(), written.pdf.string());
  }
  if (wheel || !polish) RunWheelReport(arguments);
}

void RunWheelReport(const ReportArguments& arguments) {
  reports::Tolerances tolerances;
  if (!arguments.tolerance_file.empty()) tolerances = reports::ReadTolerances(arguments.tolerance_file);
  for (const std::string& flag : arguments.tolerance_flags) reports::AddToleranceFlag(tolerances, flag);
  const reports::WrittenReports written = reports::WriteReports(arguments.outdir, tolerances);
  fmt::print("wrote {}\nwrote {}\noverall: {}\n", written.html.string(), written.pdf.string(),
             reports::VerdictText(written.overall));
}

}  // namespace

void AddReportCommand(CLI::App& app) {
  auto arguments = std::make_shared<ReportArguments>();
  CLI::App* command = app.add_subcommand(
      "report",
      "render OUTDIR/report.html and OUTDIR/report.pdf from OUTDIR/summary.json and wheel_map.h5, or "
      "OUTDIR/polish_report.html and .pdf from the outputs of `arcwheel polish`");
  command
      ->add_option("OUTDIR", arguments->outdir, "folder written by `arcwheel process` or `arcwheel polish`")
      ->required();
  command->add_option("--tolerances", arguments->tolerance_file,
                      "JSON file of limits by headline key, e.g. {\"max_runout_um\": 10, "
                      "\"mean_arc_radius_mm\": {\"min\": 74.9, \"max\": 75.1}}");
  command->add_option(
      "--tolerance", arguments->tolerance_flags,
      "one limit KEY=MAX or KEY=MIN:MAX (repeatable; overrides the file), e.g. max_arc_error_um=3");
  command->callback([arguments] { RunReport(*arguments); });
}

}  // namespace arcwheel::cli
