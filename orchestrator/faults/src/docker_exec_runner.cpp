#include "swarmbox/faults/docker_exec_runner.hpp"

namespace swarmbox::faults {

Result<CommandOutput> DockerExecCommandRunner::Run(const std::vector<std::string>& argv) {
  const std::string doing = "exec `" + CommandText(argv) + "` in " + container_;
  docker::ExecSpec spec;
  spec.cmd = argv;
  auto id = api_.CreateExec(container_, spec);
  if (!id) return id.error().Context(doing);
  CommandOutput out;
  auto started = api_.StartExec(
      *id,
      [&](const docker::LogLine& line) {
        std::string& sink = line.stream == docker::StreamKind::kStderr ? out.stderr_text : out.stdout_text;
        sink += line.text;
        sink += '\n';
      },
      nullptr);
  if (!started) return started.error().Context(doing);
  auto state = api_.InspectExec(*id);
  if (!state) return state.error().Context(doing);
  if (!state->exit_code) {
    return Error(ErrorCode::kProtocol, "the exec ended without an exit code", doing);
  }
  out.exit_code = static_cast<int>(*state->exit_code);
  return out;
}

}  // namespace swarmbox::faults
