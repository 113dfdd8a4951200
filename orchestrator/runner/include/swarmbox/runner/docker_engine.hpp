// DockerEngine: the DSL's Engine on a DockerApi. Creates networks and containers with their
// labels, subnets and fixed addresses, copies input files in, starts containers and follows their
// logs into <trial dir>/logs/<component>.log (one thread per container, lines also go to the
// LogHub), waits for readiness patterns, and on Stop: stops, collects the log's end and the
// artifacts (Docker's archive endpoint, so remote engines work too), and removes. Containers are
// never auto-removed, so a crashed container's logs and exit code are kept.
//
// Stop returns as soon as the container's program has exited (SIGTERM, SIGKILL after the grace;
// its log stream ended and was read to the end), so the next level is stopped without waiting for
// the engine's clean-up; Docker's stop call, the exit code, artifacts and removal finish in the
// background. RemoveNetwork, a rebuild, FinishStops() and the destructor wait for them.
//
// The containers of one run-priority level are handled at once (RunSiblings: up to
// EngineOptions::max_parallel threads, each making its own calls on the thread-safe DockerApi):
// started together (each waiting for its own readiness), stopped, drained and removed together
// (a level's stops all at once: they wait, the engine does not work for them). Levels stay in
// order (the tree walks them one after another).
//
// Creates run ahead: CreateContainer queues the creation (create, the second network, the input
// files) on up to max_parallel workers and returns at once, so the tree's Build walk ends right
// after the networks and every level's containers are created while the earlier levels start and
// wait for their readiness (a level's creations begin once the earlier levels' have finished, so
// they do not slow those down). Creating starts nothing: StartContainer waits for its own container's
// creation (and fails with its verdict), so starts keep the priority order. The build event of a
// container is traced when its creation has finished, with its real verdict. StopContainer waits
// for the creation too, so a container created but never started is removed like any other.
// With max_parallel 1 everything goes one at a time on the caller's thread, as before.
//
// Thread-safety: the tree (runner's thread) calls the dsl::Engine methods, concurrently for the
// components of one level; Trace calls are serialised. Inspect, ResumeLogs and IsCurrent may be
// called from the runner's thread at any time; problems() and artifacts() once no walk runs.
//
// The parts, each owning its state under its own lock: JobQueue (job_queue.hpp, the create
// workers), LogFollowers (log_follower.hpp, one follower thread per container and the generations
// that tell a current follower's items from a replaced one's), detail::CreatesAhead and
// detail::BackgroundStops (detail/engine_pipelines.hpp, the creations running ahead by level and
// the stops finishing in the background), CopyInputs and CollectArtifacts (container_files.hpp).
// This class is the adapter between them and dsl::Engine; its own lock guards only its maps.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <functional>
#include <future>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/network.hpp"
#include "swarmbox/dsl/plugin.hpp"
#include "swarmbox/runner/clock.hpp"
#include "swarmbox/runner/detail/engine_pipelines.hpp"
#include "swarmbox/runner/log_follower.hpp"
#include "swarmbox/runner/log_hub.hpp"
#include "swarmbox/runner/results.hpp"
#include "swarmbox/runner/job_queue.hpp"

namespace swarmbox::runner {

struct EngineOptions {
  std::string trial_dir;    // logs/ and artifacts go here; must exist
  double start_wall_s = 0;  // Clock time the trial started (wall_s of log lines is relative)
  const std::atomic<bool>* interrupted = nullptr;  // Ctrl-C: readiness waits give up
  // Called with each lifecycle step (events.jsonl); may be empty.
  std::function<void(const dsl::Component&, dsl::EventKind, const dsl::Verdict&)> on_trace;
  // How many containers are created (ahead) or started at once (1 = one by one, no creating
  // ahead). A level's stops all go at once unless this is 1.
  int max_parallel = 32;
};

// Runs every step, at most `max_threads` at once (the calling thread works too; one thread or one
// step runs on the calling thread alone), waits for all and returns the worst verdict (ties: the
// earliest step's). Steps must not throw.
dsl::Verdict RunConcurrently(const std::vector<std::function<dsl::Verdict()>>& steps,
                             int max_threads);

class DockerEngine final : public dsl::Engine {
 public:
  DockerEngine(docker::DockerApi& api, LogHub& hub, Clock& clock, EngineOptions options);
  ~DockerEngine() override;  // cancels and joins any follower still running
  DockerEngine(const DockerEngine&) = delete;
  DockerEngine& operator=(const DockerEngine&) = delete;

  dsl::Verdict CreateNetwork(dsl::Network& network) override;
  dsl::Verdict RemoveNetwork(dsl::Network& network) override;
  dsl::Verdict CreateContainer(dsl::Plugin& plugin) override;
  dsl::Verdict StartContainer(dsl::Plugin& plugin) override;
  dsl::Verdict StopContainer(dsl::Plugin& plugin) override;
  void Trace(const dsl::Component& component, dsl::EventKind event,
             const dsl::Verdict& verdict) override;
  dsl::Verdict RunSiblings(const std::vector<std::function<dsl::Verdict()>>& steps,
                           bool stop_on_failure) override;

  // The container's state now (after its log stream ended, to tell a crash from a hiccup).
  Result<docker::ContainerState> Inspect(const std::string& component);
  // After a fault restarted the component's container (docker start/restart): follow its log
  // again from the first line not delivered yet (Docker keeps the earlier runs' lines); items of the
  // previous follower are no longer current. kNotFound for an unknown component.
  Status ResumeLogs(const std::string& component);
  // Whether a hub item comes from the component's current follower (not one before a restart).
  bool IsCurrent(const HubItem& item) const;
  // Waits until every creation queued so far has finished (the tree's Stop does too, container by
  // container); after a failed Start, before writing anything, no build trace is still to come.
  void FinishCreates();
  // True when the last network creation failed because its subnet overlaps another network.
  bool subnet_conflict() const { return subnet_conflict_.load(); }
  // Waits for the stops still finishing (exit codes, artifacts, removal) and returns their worst
  // verdict since the last call (a failed stop or removal). Call after the tree's Stop, before
  // Reports(), problems() and artifacts(). The destructor and RemoveNetwork wait for them too.
  dsl::Verdict FinishStops();
  // Per container: exit code, log file, line count (filled on Stop).
  std::vector<ComponentReport> Reports() const;
  // Things that went wrong without changing the outcome (a missing artifact...).
  const std::vector<std::string>& problems() const { return problems_; }
  // Artifacts collected so far: file name (relative to the trial folder: "truth.csv",
  // "components/recorder/out.csv") -> path on the host.
  const std::map<std::string, std::string>& artifacts() const { return artifacts_; }

 private:
  struct StopRequest;
  dsl::Verdict CreateNow(dsl::Plugin& plugin);
  // The queued creation of the component (CreatesAhead) run on a create worker.
  void CreateAhead(dsl::Plugin& plugin, int priority, bool cancelled,
                   const std::optional<std::shared_future<dsl::Verdict>>& owner,
                   const std::shared_ptr<std::promise<dsl::Verdict>>& promise);
  // The creation of the component's container queued by CreateContainer, if any; waits for it.
  std::optional<dsl::Verdict> WaitCreated(const std::string& component);
  // The second half of a stop (a BackgroundStops thread): Docker's stop call, then, once the log
  // is complete, the exit code, the artifacts and the removal.
  dsl::Verdict FinishStop(const StopRequest& request, std::atomic<bool>& stop_returned,
                          const std::shared_future<void>& log_complete);
  void StartFollower(const std::string& component, const std::string& container_id,
                     std::uint64_t skip_lines = 0);
  void CountLines(const std::string& component, std::uint64_t lines);
  void NotifyEnded();  // a follower's stream ended or a Docker stop returned
  void AddProblem(std::string problem);
  std::optional<std::string> ContainerId(const std::string& component) const;

  docker::DockerApi& api_;
  LogHub& hub_;
  Clock& clock_;
  EngineOptions options_;
  std::mutex trace_mu_;    // one Trace at a time
  mutable std::mutex mu_;  // guards the maps and lists below (never held across a Docker call)
  std::map<std::string, std::string> network_ids_;    // component id -> Docker id
  std::map<std::string, std::string> container_ids_;  // component id -> Docker id
  std::map<std::string, ComponentReport> reports_;
  std::vector<std::string> problems_;
  std::map<std::string, std::string> artifacts_;
  std::atomic<bool> subnet_conflict_{false};
  // Signalled when a follower's stream ends or a Docker stop returns (StopContainer waits on
  // either; the flags it waits for are atomics, set before the signal).
  std::mutex ended_mu_;
  std::condition_variable ended_cv_;
  detail::CreatesAhead creates_;
  detail::BackgroundStops stops_;
  LogFollowers followers_;
  JobQueue create_workers_;  // up to max_parallel, started when needed
};

}  // namespace swarmbox::runner
