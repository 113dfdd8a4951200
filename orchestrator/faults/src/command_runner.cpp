#include "swarmbox/faults/command_runner.hpp"

namespace swarmbox::faults {

std::string CommandText(const std::vector<std::string>& argv) {
  std::string out;
  for (const auto& a : argv) {
    if (!out.empty()) out += ' ';
    out += a;
  }
  return out;
}

Result<CommandOutput> PrefixCommandRunner::Run(const std::vector<std::string>& argv) {
  std::vector<std::string> full = prefix_;
  full.insert(full.end(), argv.begin(), argv.end());
  return inner_.Run(full);
}

namespace {

Status RunOne(CommandRunner& runner, const Command& command) {
  auto out = runner.Run(command.argv);
  if (!out) return out.error();
  if (out->exit_code != 0 && !command.may_fail) {
    std::string err = out->stderr_text;
    while (!err.empty() && (err.back() == '\n' || err.back() == ' ')) err.pop_back();
    return Error(ErrorCode::kInternal,
                 "`" + CommandText(command.argv) + "` exited " + std::to_string(out->exit_code) +
                     (err.empty() ? "" : ": " + err));
  }
  return Ok{};
}

}  // namespace

Status RunCommands(CommandRunner& runner, const std::vector<Command>& commands) {
  for (const auto& c : commands) SWARMBOX_TRY(RunOne(runner, c));
  return Ok{};
}

Status RunAllCommands(CommandRunner& runner, const std::vector<Command>& commands) {
  Status first;
  for (const auto& c : commands) {
    Status s = RunOne(runner, c);
    if (!s && first.ok()) first = s;
  }
  return first;
}

}  // namespace swarmbox::faults
