// arcwheel: one binary, one subcommand per job. main() is the only catch-all.

#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/version.h"

namespace {

using arcwheel::ErrorCode;

struct Command {
  const char* name;
  void (*add)(CLI::App&);
};

// The command table: add a row here and a command_<name>.cc beside this file.
const std::vector<Command> kCommands = {
    {"simulate", arcwheel::cli::AddSimulateCommand},
    {"process", arcwheel::cli::AddProcessCommand},
    {"fit", arcwheel::cli::AddFitCommand},
    {"toolpath", arcwheel::cli::AddToolpathCommand},
    {"report", arcwheel::cli::AddReportCommand},
    {"compare", arcwheel::cli::AddCompareCommand},
    {"history", arcwheel::cli::AddHistoryCommand},
    {"frame", arcwheel::cli::AddFrameCommand},
    {"transform", arcwheel::cli::AddTransformCommand},
    {"headcenter", arcwheel::cli::AddHeadcenterCommand},
    {"polish", arcwheel::cli::AddPolishCommand},
    {"regenerate", arcwheel::cli::AddRegenerateCommand},
    {"batch", arcwheel::cli::AddBatchCommand},
};

constexpr const char* kExitCodes =
    "Exit status: 0 ok; 1 unknown command or usage; 2 invalid option; 3 bad input file;\n"
    "4 I/O failure (cannot read, write or rename); 5 no usable fit; 6 batch: some scans have no\n"
    "result (the index names them); 70 internal error; 130 interrupted (SIGINT/SIGTERM).\n"
    "A failed run leaves no new or partial output file.";

// After a failed write (a full disk) HDF5 keeps the broken file open and its exit handler
// crashes closing it again. Our own cleanup (temporary files) has run during unwinding, so a failed
// run ends without the libraries' exit handlers.
[[noreturn]] void ExitWithoutLibraryCleanup(int status) {
  std::fflush(nullptr);
  std::_Exit(status);
}

// The arguments, with those after `batch ... --` handed to the batch command: they are process
// options, passed to each child unchanged.
std::vector<std::string> ArgumentsForCli11(int argc, char** argv) {
  std::vector<std::string> arguments(argv + 1, argv + argc);
  const auto command = std::find_if(arguments.begin(), arguments.end(),
                                    [](const std::string& a) { return a.empty() || a[0] != '-'; });
  if (command != arguments.end() && *command == "batch") {
    const auto separator = std::find(command, arguments.end(), std::string("--"));
    if (separator != arguments.end()) {
      arcwheel::cli::SetBatchProcessOptions({separator + 1, arguments.end()});
      arguments.erase(separator, arguments.end());
    }
  }
  std::reverse(arguments.begin(), arguments.end());  // CLI11 takes them last first
  return arguments;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"arcwheel: metrology and toolpaths for arc-profile diamond wheels", "arcwheel"};
  app.footer(kExitCodes);
  app.require_subcommand(1);
  bool no_catch = false;
  app.add_flag("--no-catch", no_catch, "let errors escape main() so that a debugger stops at the throw");
  app.set_version_flag("--version", std::string("arcwheel ") + arcwheel::kVersion);
  for (const Command& command : kCommands) command.add(app);
  app.add_subcommand("version", "print the arcwheel version")->callback([] {
    fmt::print("arcwheel {}\n", arcwheel::kVersion);
  });
  app.add_subcommand("help", "list the commands; `arcwheel COMMAND --help` for one")->callback([&app] {
    fmt::print("{}", app.help());
  });
  arcwheel::InstallInterruptHandlers();

  try {
    app.parse(ArgumentsForCli11(argc, argv));
  } catch (const CLI::CallForHelp&) {
    fmt::print("{}", app.help());
    return 0;
  } catch (const CLI::CallForAllHelp&) {
    fmt::print("{}", app.help("", CLI::AppFormatMode::All));
    return 0;
  } catch (const CLI::Success& success) {
    return app.exit(success);
  } catch (const CLI::ParseError& error) {
    const bool unknown_command = app.get_subcommands().empty();
    fmt::print(stderr, "arcwheel: {}\n", error.what());
    fmt::print(stderr, "{}\n",
               unknown_command ? "run `arcwheel help` for the list of commands"
                               : "run `arcwheel COMMAND --help` for its options");
    return unknown_command ? 1 : arcwheel::ExitStatus(ErrorCode::kInvalidOption);
  } catch (const arcwheel::cli::SomeFailed& failed) {
    fmt::print(stderr, "arcwheel: {}\n", failed.what());
    ExitWithoutLibraryCleanup(arcwheel::cli::kSomeFailedExitStatus);
  } catch (const arcwheel::Error& error) {
    if (no_catch) throw;
    fmt::print(stderr, "arcwheel: {}: {}\n", arcwheel::ErrorCodeName(error.code()), error.what());
    ExitWithoutLibraryCleanup(arcwheel::ExitStatus(error.code()));
  } catch (const std::exception& error) {
    if (no_catch) throw;
    fmt::print(stderr, "arcwheel: internal error: {}\n", error.what());
    ExitWithoutLibraryCleanup(arcwheel::ExitStatus(ErrorCode::kInternal));
  }
  return 0;
}
