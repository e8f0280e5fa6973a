#include <fcntl.h>
#include <fmt/core.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstring>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/interrupt.h"
#include "core/json_text.h"
#include "workflows/batch_internal.h"
#include "workflows/step_inputs.h"

extern char** environ;

namespace arcwheel::workflows::batch {

fs::path ArcwheelBinary(const BatchOptions& args) {
  return args.arcwheel_binary.empty() ? fs::read_symlink("/proc/self/exe") : args.arcwheel_binary;
}

pid_t SpawnProcess(const BatchOptions& args, const Scan& scan) {
  const std::string binary = ArcwheelBinary(args).string();
  std::vector<std::string> arguments = {binary, "process", scan.path.string(), "-o",
                                        ResultFolder(args, scan).string()};
  arguments.insert(arguments.end(), args.process_options.begin(), args.process_options.end());
  if (!args.db.empty()) arguments.insert(arguments.end(), {"--db", args.db});
  std::vector<char*> argv;
  for (std::string& argument : arguments) argv.push_back(argument.data());
  argv.push_back(nullptr);
  const std::string log = LogPath(args, scan).string();

  posix_spawn_file_actions_t files;
  posix_spawn_file_actions_init(&files);
  posix_spawn_file_actions_addopen(&files, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&files, STDOUT_FILENO, log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_adddup2(&files, STDOUT_FILENO, STDERR_FILENO);
  posix_spawnattr_t attributes;
  posix_spawnattr_init(&attributes);
  sigset_t blocked;
  sigemptyset(&blocked);
  sigaddset(&blocked, SIGINT);
  sigaddset(&blocked, SIGTERM);
  posix_spawnattr_setsigmask(&attributes, &blocked);
  posix_spawnattr_setpgroup(&attributes, 0);
  posix_spawnattr_setflags(&attributes, POSIX_SPAWN_SETSIGMASK | POSIX_SPAWN_SETPGROUP);
  pid_t pid = 0;
  const int error = posix_spawn(&pid, binary.c_str(), &files, &attributes, argv.data(), environ);
  posix_spawnattr_destroy(&attributes);
  posix_spawn_file_actions_destroy(&files);
  if (error != 0) {
    throw Error(ErrorCode::kIo, kStage, fmt::format("cannot start '{}': {}", binary, std::strerror(error)));
  }
  return pid;
}

// What the child's wait status says; a result folder that did not finish is removed, so that
// only complete results stay (the child's OutputSet removes its own; this covers a crash).
Outcome Finish(const BatchOptions& args, const Scan& scan, int wait_status, double seconds,
               const json& inputs) {
  Outcome outcome{.status = Status::kFailed, .exit_code = std::nullopt, .message = {}, .seconds = seconds};
  const fs::path folder = ResultFolder(args, scan);
  if (WIFEXITED(wait_status)) {
    outcome.exit_code = WEXITSTATUS(wait_status);
    outcome.message = ChildMessage(LogPath(args, scan));
  } else if (WIFSIGNALED(wait_status)) {
    const int signal = WTERMSIG(wait_status);
    outcome.exit_code = 128 + signal;
    outcome.message = fmt::format("killed by signal {} ({})", signal, ::strsignal(signal));
  }
  if (outcome.exit_code == 0) {
    bool complete = true;
    for (const std::string& file : ResultFiles()) complete = complete && fs::exists(folder / file);
    if (complete) {
      WriteFileAtomically(folder / kStepInputsFileName, JsonText(inputs, 2) + "\n");
      outcome.status = Status::kDone;
      outcome.message.clear();
      return outcome;
    }
    outcome.message = "the child exited with 0 but left no complete result";
  }
  if (outcome.exit_code == ExitStatus(ErrorCode::kInterrupted) && InterruptRequested()) {
    outcome.status = Status::kInterrupted;
  }
  std::error_code ignored;
  fs::remove_all(folder, ignored);
  return outcome;
}

}  // namespace arcwheel::workflows::batch
