// A DockerApi fake for fault tests: records container state changes and exec calls, and fails the
// calls a test names. Everything a fault never uses answers kUnavailable.
#pragma once

#include <functional>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::faults::testing {

class FakeDockerApi : public docker::DockerApi {
 public:
  std::vector<std::string> calls;              // "kill scout_1 SIGKILL", "exec c1 tc qdisc ..."
  std::set<std::string> fail;                  // calls (as recorded) that fail with kInvalidArgument
  // exec: argv text -> {stdout lines, stderr lines, exit code}
  struct ExecAnswer {
    std::vector<std::string> out, err;
    std::int64_t exit_code = 0;
  };
  std::map<std::string, ExecAnswer> exec_answers;

  Result<std::string> Ping() override { return Unavailable(); }
  Result<docker::EngineVersion> Version() override { return Unavailable(); }
  std::string api_version() const override { return "1.41"; }
  Result<docker::BuildResult> BuildImage(const docker::BuildRequest&, const docker::BuildProgressFn&,
                                         docker::CancelToken*) override {
    return Unavailable();
  }
  Result<docker::ImageInfo> InspectImage(std::string_view) override { return Unavailable(); }
  Result<std::vector<docker::ImageInfo>> ListImages(const docker::LabelSelector&) override { return Unavailable(); }
  Status RemoveImage(std::string_view, bool) override { return Unavailable(); }
  Result<std::string> CreateNetwork(const docker::NetworkSpec&) override { return Unavailable(); }
  Result<docker::NetworkInfo> InspectNetwork(std::string_view) override { return Unavailable(); }
  Result<std::vector<docker::NetworkInfo>> ListNetworks(const docker::LabelSelector&) override { return Unavailable(); }
  Status ConnectNetwork(const docker::EndpointSpec&, std::string_view) override { return Unavailable(); }
  Status DisconnectNetwork(std::string_view, std::string_view, bool) override { return Unavailable(); }
  Status RemoveNetwork(std::string_view) override { return Unavailable(); }
  Result<std::string> CreateContainer(const docker::ContainerSpec&) override { return Unavailable(); }
  Result<docker::ContainerInfo> InspectContainer(std::string_view) override { return Unavailable(); }
  Result<std::vector<docker::ContainerSummary>> ListContainers(const docker::LabelSelector&, bool) override {
    return Unavailable();
  }
  Status StartContainer(std::string_view id) override { return Record("start " + std::string(id)); }
  Status StopContainer(std::string_view id, int t) override {
    return Record("stop " + std::string(id) + " " + std::to_string(t));
  }
  Status RestartContainer(std::string_view id, int t) override {
    return Record("restart " + std::string(id) + " " + std::to_string(t));
  }
  Status KillContainer(std::string_view id, std::string_view signal) override {
    return Record("kill " + std::string(id) + " " + std::string(signal));
  }
  Status PauseContainer(std::string_view id) override { return Record("pause " + std::string(id)); }
  Status UnpauseContainer(std::string_view id) override { return Record("unpause " + std::string(id)); }
  Result<std::int64_t> WaitContainer(std::string_view, docker::WaitCondition, docker::CancelToken*) override {
    return Unavailable();
  }
  Status RemoveContainer(std::string_view, bool, bool) override { return Unavailable(); }
  Status FollowLogs(std::string_view, const docker::LogOptions&, const docker::LogLineFn&,
                    docker::CancelToken*) override {
    return Unavailable();
  }
  Result<std::string> CreateExec(std::string_view container, const docker::ExecSpec& spec) override {
    std::string text;
    for (const auto& a : spec.cmd) text += (text.empty() ? "" : " ") + a;
    calls.push_back("exec " + std::string(container) + " " + text);
    const std::string id = "exec" + std::to_string(execs_.size());
    execs_[id] = text;
    return id;
  }
  Status StartExec(std::string_view exec_id, const docker::LogLineFn& on_line, docker::CancelToken*) override {
    const auto& answer = exec_answers[execs_.at(std::string(exec_id))];
    for (const auto& l : answer.out) on_line({docker::StreamKind::kStdout, l});
    for (const auto& l : answer.err) on_line({docker::StreamKind::kStderr, l});
    return Ok{};
  }
  Result<docker::ExecState> InspectExec(std::string_view exec_id) override {
    docker::ExecState state;
    state.exit_code = exec_answers[execs_.at(std::string(exec_id))].exit_code;
    return state;
  }
  Status PutArchive(std::string_view, std::string_view, std::string_view) override { return Unavailable(); }
  Result<std::string> GetArchive(std::string_view, std::string_view) override { return Unavailable(); }
  Status StreamEvents(const docker::EventFilter&, const docker::EventFn&, docker::CancelToken*) override {
    return Unavailable();
  }

 private:
  static Error Unavailable() { return Error(ErrorCode::kUnavailable, "not used by fault injection", "fake"); }
  Status Record(std::string call) {
    calls.push_back(call);
    if (fail.count(call) != 0) return Error(ErrorCode::kInvalidArgument, "container is not running", "fake");
    return Ok{};
  }
  std::map<std::string, std::string> execs_;
};

}  // namespace swarmbox::faults::testing
