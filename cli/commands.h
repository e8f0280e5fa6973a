#pragma once
// One Add*Command per command, each in its own command_<name>.cc. A command's callback does
// its work and throws arcwheel::Error on failure; main() maps the error to the exit status.

#include <CLI/CLI.hpp>
#include <stdexcept>
#include <string>
#include <vector>

namespace arcwheel::cli {

void AddSimulateCommand(CLI::App& app);
void AddProcessCommand(CLI::App& app);
void AddFitCommand(CLI::App& app);
void AddRoundnessCommand(CLI::App& app);
void AddToolpathCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);
void AddFrameCommand(CLI::App& app);
void AddTransformCommand(CLI::App& app);
void AddHeadcenterCommand(CLI::App& app);
void AddPolishCommand(CLI::App& app);
void AddCompareCommand(CLI::App& app);
void AddHistoryCommand(CLI::App& app);
void AddRegenerateCommand(CLI::App& app);
void AddBatchCommand(CLI::App& app);
void AddDbCommand(CLI::App& app);

// `--db STORE` on a command that records its run (or reads the store): a SQLite file or a
// postgresql:// URL; without it, the environment variable ARCWHEEL_DB (docs/store.md).
void AddDbOption(CLI::App* command, std::string& db);

// `arcwheel batch ... -- OPTIONS`: the arguments after `--`, which main() takes off the command
// line before parsing (CLI11 would not hand them to the subcommand as they are).
void SetBatchProcessOptions(std::vector<std::string> options);

// Exit status of a command that ran to its end while some of its items failed (`batch`: some scans
// have no result; its index names them). Not an Error: nothing about the run itself was wrong.
inline constexpr int kSomeFailedExitStatus = 6;
class SomeFailed : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace arcwheel::cli
