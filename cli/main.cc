// arcwheel: one binary, one subcommand per job. main() is the only catch-all.

#include <fmt/core.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "cli/commands.h"
#include "core/error.h"
#include "core/free_memory.h"
#include "core/interrupt.h"
#include "core/version.h"

namespace {

using arcwheel::ErrorCode;

// The command table: add a row here and a command_<name>.cc beside this file (each names its
// command when it adds it).
const std::vector<void (*)(CLI::App&)> kCommands = {
    arcwheel::cli::AddSimulateCommand,   arcwheel::cli::AddProcessCommand,    arcwheel::cli::AddFitCommand,
    arcwheel::cli::AddRoundnessCommand,  arcwheel::cli::AddToolpathCommand,   arcwheel::cli::AddReportCommand,
    arcwheel::cli::AddCompareCommand,    arcwheel::cli::AddHistoryCommand,    arcwheel::cli::AddFrameCommand,
    arcwheel::cli::AddTransformCommand,  arcwheel::cli::AddHeadcenterCommand, arcwheel::cli::AddPolishCommand,
    arcwheel::cli::AddRegenerateCommand, arcwheel::cli::AddBatchCommand,      arcwheel::cli::AddDbCommand,
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

// Edit distance between two command names: the nearest known command to a mistyped one.
size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    size_t diagonal = row[0];
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// "unknown command 'batchx'; did you mean 'batch'?", the suggestion only where a command is a few
// typing errors away (at most a third of the word's letters, and at least one).
std::string UnknownCommand(const CLI::App& app, const std::string& typed) {
  std::string nearest;
  size_t best = std::numeric_limits<size_t>::max();
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    const size_t distance = EditDistance(typed, command->get_name());
    if (distance < best) best = distance, nearest = command->get_name();
  }
  const std::string suggestion =
      best <= std::max<size_t>(1, typed.size() / 3) ? fmt::format("; did you mean '{}'?", nearest) : "";
  return fmt::format("arcwheel: unknown command '{}'{} (`arcwheel help` lists the commands)\n", typed,
                     suggestion);
}

bool HasCommand(const CLI::App& app, const std::string& name) {
  for (const CLI::App* command : app.get_subcommands([](const CLI::App*) { return true; })) {
    if (command->get_name() == name) return true;
  }
  return false;
}

// The command word: the first argument that is not a flag of arcwheel itself.
std::optional<size_t> CommandIndex(const std::vector<std::string>& arguments) {
  for (size_t i = 0; i < arguments.size(); ++i) {
    if (arguments[i].empty() || arguments[i][0] != '-') return i;
  }
  return std::nullopt;
}

// The arguments, with those after `batch ... --` handed to the batch command: they are process
// options, passed to each child unchanged.
std::vector<std::string> ArgumentsForCli11(int argc, char** argv) {
  std::vector<std::string> arguments(argv + 1, argv + argc);
  const std::optional<size_t> index = CommandIndex(arguments);
  const auto command = index ? arguments.begin() + static_cast<std::ptrdiff_t>(*index) : arguments.end();
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
  arcwheel::KeepFreedBlocksForReuse();
  CLI::App app{"arcwheel: metrology and toolpaths for arc-profile diamond wheels", "arcwheel"};
  app.footer(kExitCodes);
  app.require_subcommand(1);
  bool no_catch = false;
  app.add_flag("--no-catch", no_catch, "let errors escape main() so that a debugger stops at the throw");
  app.set_version_flag("--version", std::string("arcwheel ") + arcwheel::kVersion);
  for (const auto add : kCommands) add(app);
  app.add_subcommand("version", "print the arcwheel version")->callback([] {
    fmt::print("arcwheel {}\n", arcwheel::kVersion);
  });
  app.add_subcommand("help", "list the commands; `arcwheel help COMMAND` for one command's options");
  arcwheel::InstallInterruptHandlers();

  // What a newcomer types first, answered before CLI11 sees it: `arcwheel`, `arcwheel help
  // [COMMAND]` and a mistyped command.
  std::vector<std::string> words(argv + 1, argv + argc);
  const std::optional<size_t> command = CommandIndex(words);
  if (!command) {
    const bool asks_for_something = std::any_of(words.begin(), words.end(), [](const std::string& word) {
      return word == "-h" || word == "--help" || word == "--help-all" || word == "--version";
    });
    if (!asks_for_something) {
      fmt::print(stderr, "{}", app.help());
      return 1;
    }
  } else if (words[*command] == "help") {
    if (*command + 1 >= words.size()) {
      fmt::print("{}", app.help());
      return 0;
    }
    const std::string& topic = words[*command + 1];
    if (!HasCommand(app, topic)) {
      fmt::print(stderr, "{}", UnknownCommand(app, topic));
      return 1;
    }
    fmt::print("{}", app.get_subcommand(topic)->help(app.get_name()));
    return 0;
  } else if (!HasCommand(app, words[*command])) {
    fmt::print(stderr, "{}", UnknownCommand(app, words[*command]));
    return 1;
  }

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
