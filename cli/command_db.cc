// arcwheel db init | migrate | export --csv|--json [-o FILE]: the results store (store/store.h,
// docs/store.md) created, migrated to the latest schema, or exported in the shape SPC tools import.

#include <fmt/core.h>

#include <memory>
#include <optional>
#include <string>

#include "cli/commands.h"
#include "core/atomic_file.h"
#include "core/error.h"
#include "core/json_text.h"
#include "store/queries.h"
#include "store/store.h"

namespace arcwheel::cli {

void AddDbOption(CLI::App* command, std::string& db) {
  command->add_option("--db", db,
                      "results store: a SQLite file or a postgresql:// URL (default: $ARCWHEEL_DB); see "
                      "docs/store.md");
}

namespace db {
namespace {

struct DbArguments {
  std::string db;
  int schema_version = schema::store::kLatestVersion;
  bool csv = false;
  bool json = false;
  std::string output;
  std::string wheel;
  std::string since;
};

store::Store OpenNamed(const DbArguments& arguments) {
  const std::string location = store::StoreLocation(arguments.db);
  if (location.empty())
    throw Error(ErrorCode::kInvalidOption, "store", "no store given: --db STORE or ARCWHEEL_DB");
  return store::Store::Open(location);
}

void Init(const DbArguments& arguments) {
  store::Store results = OpenNamed(arguments);
  results.Init(arguments.schema_version);
  fmt::print("store: {} at schema version {}\n", results.Name(), results.Version());
}

void Migrate(const DbArguments& arguments) {
  store::Store results = OpenNamed(arguments);
  const auto [from, to] = results.Migrate();
  if (from == to) {
    fmt::print("store: {} is at the latest schema version {} already\n", results.Name(), to);
  } else {
    fmt::print("store: {} migrated from schema version {} to {}, every row kept\n", results.Name(), from, to);
  }
}

void Export(const DbArguments& arguments) {
  if (arguments.csv == arguments.json) {
    throw Error(ErrorCode::kInvalidOption, "store", "db export needs one of --csv and --json");
  }
  store::Store results = OpenNamed(arguments);
  store::RunFilter filter;
  filter.wheel_id = arguments.wheel;
  if (!arguments.since.empty()) filter.since_s = store::ParseSince_s(arguments.since, "--since");
  const std::vector<store::StoredRun> runs = results.Runs(filter);
  const std::string text =
      arguments.csv ? store::ExportCsv(runs) : JsonText(store::ExportJson(runs), 2) + "\n";
  if (arguments.output.empty() || arguments.output == "-") {
    fmt::print("{}", text);
  } else {
    WriteFileAtomically(arguments.output, text);
    fmt::print(stderr, "wrote {} ({} runs)\n", arguments.output, runs.size());
  }
}

}  // namespace
}  // namespace db

void AddDbCommand(CLI::App& app) {
  auto arguments = std::make_shared<db::DbArguments>();
  CLI::App* command = app.add_subcommand("db", "the results store: init, migrate, export (docs/store.md)");
  command->require_subcommand(1);
  command->footer(
      "A store is a SQLite file (created when missing) or a postgresql:// URL; --db or ARCWHEEL_DB names\n"
      "it. process, batch, regenerate, toolpath and polish record each run into it when given one;\n"
      "history and compare read it with --wheel ID.");
  CLI::App* init = command->add_subcommand("init", "create the schema in an empty store");
  AddDbOption(init, arguments->db);
  init->add_option("--schema-version", arguments->schema_version,
                   "create this older version instead of the latest (to test a migration)")
      ->capture_default_str();
  init->callback([arguments] { db::Init(*arguments); });
  CLI::App* migrate =
      command->add_subcommand("migrate", "bring the store to the latest schema, keeping every row");
  AddDbOption(migrate, arguments->db);
  migrate->callback([arguments] { db::Migrate(*arguments); });
  CLI::App* exported = command->add_subcommand(
      "export", "one row per characteristic per run (the shape SPC tools import), CSV or JSON");
  AddDbOption(exported, arguments->db);
  exported->add_flag("--csv", arguments->csv, "comma-separated, a header line first");
  exported->add_flag("--json", arguments->json, "{\"schema_version\": N, \"rows\": [...]}");
  exported->add_option("-o,--output", arguments->output, "file to write (default: standard output)");
  exported->add_option("--wheel", arguments->wheel, "only the runs of this wheel id");
  exported->add_option("--since", arguments->since, "only the scans at or after this date (YYYY-MM-DD)");
  exported->callback([arguments] { db::Export(*arguments); });
}

}  // namespace arcwheel::cli
