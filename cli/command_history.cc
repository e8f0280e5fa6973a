// arcwheel history DIR... -o OUTDIR [--dressings dates.csv]: every scan of one wheel in time order,
// its headline numbers against scan time, the dressings and the wear rate between them
// (reports/history.h).

#include <fmt/core.h>

#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"
#include "reports/format.h"
#include "reports/history.h"

namespace arcwheel::cli {
namespace {

struct HistoryArguments {
  std::vector<std::filesystem::path> folders;
  std::filesystem::path outdir;
  std::filesystem::path dressings;
};

std::string ReadDressingFile(const std::filesystem::path& path) {
  std::ifstream stream(path, std::ios::binary);
  if (!stream) throw Error(ErrorCode::kIo, "reports.history", "cannot open '" + path.string() + "'");
  std::ostringstream text;
  text << stream.rdbuf();
  return text.str();
}

void RunHistory(const HistoryArguments& arguments) {
  std::vector<double> dressing_times_s;
  std::vector<std::string> dressing_timestamps;
  if (!arguments.dressings.empty()) {
    dressing_times_s = reports::ParseDressingsCsv(ReadDressingFile(arguments.dressings),
                                                  arguments.dressings.string(), &dressing_timestamps);
  }
  const reports::History history =
      reports::BuildHistory(arguments.folders, dressing_times_s, dressing_timestamps);
  const reports::WrittenHistory written = reports::WriteHistory(history, arguments.outdir);
  fmt::print("wrote {}\nwrote {}\nwrote {}\n", written.csv.string(), written.html.string(),
             written.pdf.string());
  for (const reports::WearRate& wear : history.wear) {
    fmt::print(
        "wear, segment {} ({} scans): {}\n", wear.segment, wear.scans,
        reports::FormatWithSigma(wear.rate_um_per_h, wear.sigma_um_per_h, reports::units::kWear_um_per_h));
  }
}

}  // namespace

void AddHistoryCommand(CLI::App& app) {
  auto arguments = std::make_shared<HistoryArguments>();
  CLI::App* command = app.add_subcommand(
      "history",
      "the scans of one wheel in time order: headline numbers against scan time, dressings, wear rate "
      "between dressings; writes history.csv, .html and .pdf");
  command->add_option("DIR", arguments->folders, "folders written by `arcwheel process` (summary.json)")
      ->required();
  command->add_option("-o,--output", arguments->outdir, "folder to write the history to")->required();
  command->add_option("--dressings", arguments->dressings,
                      "CSV of dressing dates, one ISO 8601 date-time per line in the first column");
  command->callback([arguments] { RunHistory(*arguments); });
}

}  // namespace arcwheel::cli
