// arcwheel compare BEFORE_DIR AFTER_DIR -o OUTDIR, or compare --wheel ID [--since DATE] [--db
// STORE] -o OUTDIR: two scans of one wheel (before and after a dressing, or two sensors) compared:
// headline changes with their combined sigma and significance, and the radial map difference
// (reports/compare.h); with --wheel, the scans the results store names (store/queries.h).

#include <fmt/core.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "cli/commands.h"
#include "core/error.h"
#include "reports/compare.h"
#include "store/queries.h"

namespace arcwheel::cli {
namespace {

struct CompareArguments {
  std::filesystem::path before;
  std::filesystem::path after;
  std::filesystem::path outdir;
  std::string wheel;
  std::string since;
  std::string db;
};

void RunCompare(const CompareArguments& arguments) {
  const bool folders = !arguments.before.empty() || !arguments.after.empty();
  if (folders == !arguments.wheel.empty() ||
      (folders && (arguments.before.empty() || arguments.after.empty()))) {
    throw Error(ErrorCode::kInvalidOption, "reports.compare",
                "give BEFORE_DIR and AFTER_DIR, or --wheel ID (from the results store), not both");
  }
  std::filesystem::path before = arguments.before, after = arguments.after;
  if (!arguments.wheel.empty()) {
    std::optional<double> since_s;
    if (!arguments.since.empty()) since_s = store::ParseSince_s(arguments.since, "--since");
    store::Store results = store::Store::Open(store::StoreLocation(arguments.db));
    std::tie(before, after) = store::ComparisonFolders(results, arguments.wheel, since_s);
    fmt::print("before: {}\nafter:  {}\n", before.string(), after.string());
  }
  const reports::WrittenComparison written = reports::WriteComparison(before, after, arguments.outdir);
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
  command->add_option("BEFORE_DIR", arguments->before,
                      "folder of the earlier scan (summary.json, wheel_map.h5)");
  command->add_option("AFTER_DIR", arguments->after, "folder of the later scan");
  command->add_option("--wheel", arguments->wheel,
                      "instead of folders: the last two scans of this wheel id in the results store");
  command->add_option("--since", arguments->since,
                      "with --wheel: the first scan at or after this date (YYYY-MM-DD) against the last");
  AddDbOption(command, arguments->db);
  command->add_option("-o,--output", arguments->outdir, "folder to write the comparison to")->required();
  command->callback([arguments] { RunCompare(*arguments); });
}

}  // namespace arcwheel::cli
