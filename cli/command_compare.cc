// arcwheel compare BEFORE_DIR AFTER_DIR -o OUTDIR: two scans of one wheel (before and after a
// dressing, or two sensors) compared: headline changes with their combined sigma and significance,
// and the radial map difference (reports/compare.h).

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "reports/compare.h"

namespace arcwheel::cli {
namespace {

struct CompareArguments {
  std::filesystem::path before;
  std::filesystem::path after;
  std::filesystem::path outdir;
};

void RunCompare(const CompareArguments& arguments) {
  const reports::WrittenComparison written =
      reports::WriteComparison(arguments.before, arguments.after, arguments.outdir);
  fmt::print("wrote {}\nwrote {}\nwrote {}\n", written.json.string(), written.html.string(),
             written.pdf.string());
}

}  // namespace

void AddCompareCommand(CLI::App& app) {
  auto arguments = std::make_shared<CompareArguments>();
  CLI::App* command = app.add_subcommand(
      "compare",
      "compare two `arcwheel process` folders of one wheel: headline changes with their combined sigma and "
      "significance (|change| > 3 sigma), the radial map difference; writes compare.json, .html and .pdf");
  command
      ->add_option("BEFORE_DIR", arguments->before, "folder of the earlier scan (summary.json, wheel_map.h5)")
      ->required();
  command->add_option("AFTER_DIR", arguments->after, "folder of the later scan")->required();
  command->add_option("-o,--output", arguments->outdir, "folder to write the comparison to")->required();
  command->callback([arguments] { RunCompare(*arguments); });
}

}  // namespace arcwheel::cli
