// Command and CommandRunner: how fault plans touch the system (STYLE.md 3).
//
// A plan is a list of argv arrays (no shell anywhere). Where they run is the runner's business:
// PosixCommandRunner (posix_command_runner.hpp, I/O) spawns them on this machine (posix_spawnp,
// stdout and stderr captured), PrefixCommandRunner prepends a fixed argv (e.g. {"ip", "netns", "exec", "ns1"} or
// {"nsenter", "-t", PID, "-n"}), DockerExecCommandRunner (docker_exec_runner.hpp) runs them in the
// fault sidecar (I/O, docker_exec_runner.hpp); tests use a fake that records argv. This header
// and RunCommands are part of the pure fault model (swarmbox_faults_model).
//
//   PosixCommandRunner local;
//   Status s = RunCommands(local, plan.apply);   // stops at the first failure, says which argv
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::faults {

struct Command {
  std::vector<std::string> argv;
  // Undo steps that may find nothing to undo (e.g. `tc qdisc del` on a fresh interface) are
  // allowed to fail; everything else must exit 0.
  bool may_fail = false;
  bool operator==(const Command&) const = default;
};

// argv joined with spaces, for messages and logs only (never executed through a shell).
std::string CommandText(const std::vector<std::string>& argv);

struct CommandOutput {
  int exit_code = 0;  // 128 + signal when killed by a signal
  std::string stdout_text;
  std::string stderr_text;
};

class CommandRunner {
 public:
  virtual ~CommandRunner() = default;
  // Runs argv to completion. An Error only when it could not run at all (no such program: kNotFound;
  // spawn failure: kIo); a non-zero exit is a successful Result with exit_code set.
  virtual Result<CommandOutput> Run(const std::vector<std::string>& argv) = 0;
};

class PrefixCommandRunner : public CommandRunner {
 public:
  PrefixCommandRunner(CommandRunner& inner, std::vector<std::string> prefix)
      : inner_(inner), prefix_(std::move(prefix)) {}
  Result<CommandOutput> Run(const std::vector<std::string>& argv) override;

 private:
  CommandRunner& inner_;
  std::vector<std::string> prefix_;
};

// Runs each command in order. A command that exits non-zero (and may not fail) stops the run with
// kInternal: "`tc qdisc replace ...` exited 2: <its stderr>".
Status RunCommands(CommandRunner& runner, const std::vector<Command>& commands);
// Runs every command even after failures (undo paths: take down as much as possible); returns the
// first failure.
Status RunAllCommands(CommandRunner& runner, const std::vector<Command>& commands);

}  // namespace swarmbox::faults
