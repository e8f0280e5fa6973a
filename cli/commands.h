#pragma once
// One Add*Command per command, each in its own command_<name>.cc. A command's callback does
// its work and throws arcwheel::Error on failure; main() maps the error to the exit status.

#include <CLI/CLI.hpp>

namespace arcwheel::cli {

void AddSimulateCommand(CLI::App& app);
void AddProcessCommand(CLI::App& app);
void AddFitCommand(CLI::App& app);
void AddToolpathCommand(CLI::App& app);
void AddReportCommand(CLI::App& app);
void AddFrameCommand(CLI::App& app);
void AddTransformCommand(CLI::App& app);
void AddHeadcenterCommand(CLI::App& app);
void AddPolishCommand(CLI::App& app);
void AddCompareCommand(CLI::App& app);
void AddHistoryCommand(CLI::App& app);
void AddRegenerateCommand(CLI::App& app);

}  // namespace arcwheel::cli
