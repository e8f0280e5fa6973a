// arcwheel history DIR... -o OUTDIR [--dressings dates.csv], or history --wheel ID [--since DATE]
// [--db STORE] -o OUTDIR: every scan of one wheel in time order, its headline numbers against scan
// time, the dressings and the wear rate between them (reports/history.h), from the folders or
// from the results store (store/queries.h).

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
#include "store/queries.h"

namespace arcwheel::cli {
namespace {

struct HistoryArguments {
  std::vector<std::filesystem::path> folders;
  std::filesystem::path outdir;
  std::filesystem::path dressings;
  std::string wheel;
  std::string since;
  std::string db;
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
  if (arguments.folders.empty() == arguments.wheel.empty()) {
    throw Error(ErrorCode::kInvalidOption, "reports.history",
                "give the folders of the scans or --wheel ID (from the results store), not both");
  }
  reports::History history;
  if (arguments.wheel.empty()) {
    history = reports::BuildHistory(arguments.folders, dressing_times_s, dressing_timestamps);
  } else {
    std::optional<double> since_s;
    if (!arguments.since.empty()) since_s = store::ParseSince_s(arguments.since, "--since");
    store::Store results = store::Store::Open(store::StoreLocation(arguments.db));
    history =
        store::HistoryFromStore(results, arguments.wheel, since_s, dressing_times_s, dressing_timestamps);
  }
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
  command->add_option("DIR", arguments->folders, "folders written by `arcwheel process` (summary.json)");
  command->add_option("--wheel", arguments->wheel,
                      "instead of folders: every scan of this wheel id recorded in the results store");
  command->add_option("--since", arguments->since,
                      "with --wheel: the scans at or after this date (YYYY-MM-DD)");
  AddDbOption(command, arguments->db);
  command->add_option("-o,--output", arguments->outdir, "folder to write the history to")->required();
  command->add_option("--dressings", arguments->dressings,
                      "CSV of dressing dates, one ISO 8601 date-time per line in the first column");
  command->callback([arguments] { RunHistory(*arguments); });
}

}  // namespace arcwheel::cli
