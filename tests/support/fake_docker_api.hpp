// FakeDockerApi: an in-memory Docker engine for the orchestrator's tests (runner, experiment,
// faults; the one fake of DockerApi). Containers follow a script
// per component (the swarmbox.component label): lines they log once started, whether they exit by
// themselves (and with which code), files they hold for GetArchive. Networks check subnet overlap
// like Docker does. Thread-safe (the runner follows logs from several threads).
//
// Fault injection is modelled too: exec in a running container answers from `exec_answers` (by the
// command's text; unlisted commands exit 0) and is recorded as "exec <container name> <argv>";
// kill/pause/unpause/restart change the state ("kill <name> <signal>", ...); a container created
// with network_mode "container:<id>" needs that container to exist, and to run when it starts.
// A test that only acts on containers (fault plans) puts them in place with AddRunning, and may
// make any recorded call fail with `fail`.
// Methods the runner never calls (images, events, wait...) return kInternal "not modelled by
// FakeDockerApi" so a test notices if that changes.
#pragma once

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <functional>
#include <map>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <vector>

#include "swarmbox/docker/docker_api.hpp"

namespace swarmbox::testing {

struct ContainerScript {
  std::vector<std::string> lines;              // logged right after start, in order
  std::optional<std::int64_t> exit_code;       // exits by itself after the lines; nullopt = runs until stopped
  std::map<std::string, std::string> files;    // path in the container -> content (GetArchive)
  int broken_streams = 0;                      // the first N FollowLogs calls fail with kIo...
  std::size_t broken_stream_lines = 0;         // ...after delivering this many lines
  bool fail_start = false;                     // StartContainer fails
  std::vector<std::string> restart_lines;      // logged on each start after the first (restart)
  bool fail_create = false;                    // CreateContainer fails
  // Its log stream delivers nothing until the containers of these components have been created
  // (to show that later levels are created while this one starts); after 10 s in vain it fails.
  std::set<std::string> log_after_created;
  // Its log stream delivers nothing until the containers of these components have exited and
  // been inspected since (the runner inspects a container whose stream ended: so the runner has
  // handled their exit before this stream's lines); after 10 s in vain it fails.
  std::set<std::string> log_after_exit_seen;
  // Its creation waits until the containers of these components have started (to show that it
  // is created while an earlier level starts); after 10 s in vain it fails.
  std::set<std::string> create_after_started;
};

struct ExecAnswer {
  std::vector<std::string> stdout_lines;
  std::vector<std::string> stderr_lines;
  std::int64_t exit_code = 0;
};

class FakeDockerApi : public docker::DockerApi {
 public:
  // Scripts by component name.
  std::map<std::string, ContainerScript> scripts;
  // CreateNetwork answers "Pool overlaps" this many times first (another orchestrator won a race).
  int network_conflicts = 0;
  // RemoveNetwork answers "has active endpoints" this many times first, though nothing is
  // attached (Docker 20.10's stale endpoints, moby#43286).
  int stale_endpoints = 0;
  // Exec answers by command text (argv joined with spaces); others exit 0 with no output.
  std::map<std::string, ExecAnswer> exec_answers;
  // Called with "exec <container name> <argv>" as each exec runs, before it answers (e.g. to let
  // a test's clock jump: a slow sidecar). Called from the runner's exec threads.
  std::function<void(const std::string& call)> on_exec;
  // Rendezvous, to show that calls overlap: StartContainer (StopContainer) of a component named
  // here blocks until every component named here is inside StartContainer (StopContainer) too.
  // A call that waited 10 s in vain fails ("... alone"), so a one-by-one runner fails the test
  // instead of hanging it.
  std::set<std::string> start_together;
  std::set<std::string> stop_together;
  // The engine's own time per call, by kind: "create", "start", "stop", "remove" (slept by the
  // calling thread before the call takes effect, outside the fake's lock, so concurrent calls
  // overlap): a slow engine, to measure how a runner overlaps its calls. Absent = none. Set
  // before the run.
  std::map<std::string, std::chrono::milliseconds> latency;
  // Calls (as Calls() records them: "kill b SIGKILL", "pause a") that fail, once recorded and
  // before they take effect, with kInvalidArgument "container is not running".
  std::set<std::string> fail;
  // A running container named `name` (component `name`, no script), as if created and started
  // before the test: no call is recorded. Returns its id.
  std::string AddRunning(const std::string& name);
  // The most calls of each kind ("create", "start", "stop", "remove") inside the engine at once.
  std::map<std::string, int> MaxInFlight() const;

  // Inspection for tests.
  struct Container {
    docker::ContainerSpec spec;
    std::string component;
    docker::ContainerState state;
    std::string put_archive;  // last PutArchive tar
    int follows = 0;
    int starts = 0;                 // StartContainer/RestartContainer calls that started it
    std::vector<std::string> history;  // every line logged so far (as Docker keeps them)
    bool exit_inspected = false;       // inspected after it exited (log_after_exit_seen)
  };
  std::vector<std::string> Calls() const;                  // "create-network <name>", ...
  std::vector<docker::ContainerSpec> Created() const;      // every CreateContainer spec, in order
  std::map<std::string, Container> Containers() const;     // id -> container
  std::map<std::string, docker::NetworkSpec> Networks() const;  // id -> spec
  std::vector<std::string> SubnetsTried() const;
  std::map<std::string, std::string> PutArchives() const;  // container name -> last tar put
  std::map<std::string, std::string> PutArchiveDirs() const;  // container name -> its dest dir

  // docker::DockerApi
  Result<std::string> Ping() override;
  Result<docker::EngineVersion> Version() override;
  std::string api_version() const override { return "1.41"; }
  Result<docker::BuildResult> BuildImage(const docker::BuildRequest&, const docker::BuildProgressFn&,
                                         docker::CancelToken*) override;
  Result<docker::ImageInfo> InspectImage(std::string_view) override;
  Result<std::vector<docker::ImageInfo>> ListImages(const docker::LabelSelector&) override;
  Status RemoveImage(std::string_view, bool) override;
  Result<std::string> CreateNetwork(const docker::NetworkSpec& spec) override;
  Result<docker::NetworkInfo> InspectNetwork(std::string_view id) override;
  Result<std::vector<docker::NetworkInfo>> ListNetworks(const docker::LabelSelector& selector) override;
  Status ConnectNetwork(const docker::EndpointSpec&, std::string_view) override;
  Status DisconnectNetwork(std::string_view, std::string_view, bool) override;
  Status RemoveNetwork(std::string_view id) override;
  Result<std::string> CreateContainer(const docker::ContainerSpec& spec) override;
  Result<docker::ContainerInfo> InspectContainer(std::string_view id) override;
  Result<std::vector<docker::ContainerSummary>> ListContainers(const docker::LabelSelector& selector,
                                                               bool all) override;
  Status StartContainer(std::string_view id) override;
  Status StopContainer(std::string_view id, int timeout_s) override;
  Status RestartContainer(std::string_view, int) override;
  Status KillContainer(std::string_view, std::string_view) override;
  Status PauseContainer(std::string_view) override;
  Status UnpauseContainer(std::string_view) override;
  Result<std::int64_t> WaitContainer(std::string_view, docker::WaitCondition,
                                     docker::CancelToken*) override;
  Status RemoveContainer(std::string_view id, bool force, bool remove_volumes) override;
  Status FollowLogs(std::string_view id, const docker::LogOptions& options,
                    const docker::LogLineFn& on_line, docker::CancelToken* cancel) override;
  Result<std::string> CreateExec(std::string_view, const docker::ExecSpec&) override;
  Status StartExec(std::string_view, const docker::LogLineFn&, docker::CancelToken*) override;
  Result<docker::ExecState> InspectExec(std::string_view) override;
  Status PutArchive(std::string_view container_id, std::string_view dest_dir,
                    std::string_view tar) override;
  Result<std::string> GetArchive(std::string_view container_id, std::string_view path) override;
  Status StreamEvents(const docker::EventFilter&, const docker::EventFn&,
                      docker::CancelToken*) override;

 private:
  static Error NotModelled(std::string_view what);
  static bool Selects(const docker::LabelSelector& selector, const docker::Labels& labels);
  Container* Find(std::string_view id);  // by id or name; mu_ held
  // Records the call; fails it when `fail` names it. mu_ held.
  Status Record(const std::string& call);

  void StartLocked(Container& c);  // mu_ held
  // Waits for the other members of `group` (mu_ held through `lock`); false after 10 s in vain.
  bool Rendezvous(std::unique_lock<std::mutex>& lock, const std::set<std::string>& group,
                  std::set<std::string>& arrived, const std::string& component);
  // Counts the call of `kind` in flight for its lifetime and sleeps its latency first.
  class InFlight {
   public:
    InFlight(FakeDockerApi& api, const std::string& kind);
    ~InFlight();
    InFlight(const InFlight&) = delete;
    InFlight& operator=(const InFlight&) = delete;

   private:
    FakeDockerApi& api_;
    std::string kind_;
  };
  mutable std::mutex flight_mu_;
  std::map<std::string, int> in_flight_;      // guarded by flight_mu_
  std::map<std::string, int> max_in_flight_;  // guarded by flight_mu_
  std::set<std::string> started_together_;
  std::set<std::string> stopped_together_;
  struct Exec {
    std::string container;
    std::vector<std::string> cmd;
    std::optional<std::int64_t> exit_code;
  };
  std::map<std::string, Exec> execs_;
  mutable std::mutex mu_;
  std::condition_variable cv_;
  std::vector<std::string> calls_;
  std::vector<docker::ContainerSpec> created_;
  std::map<std::string, Container> containers_;
  std::map<std::string, docker::NetworkSpec> networks_;
  std::vector<std::string> subnets_tried_;
  std::map<std::string, std::string> put_archives_;
  std::map<std::string, std::string> put_archive_dirs_;
  int next_id_ = 1;
};

}  // namespace swarmbox::testing
