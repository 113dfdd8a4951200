// TrialRun: one run of a trial, what RunTrial (runner.hpp) does, one phase per method.
//
//   TrialRun run(info, planner, api, clock, options);
//   Result<RunOutcome> outcome = run.Run();   // once per object
//
// The phases, in Run's order:
//   PrepareFolder         the trial folder, trial.yaml, TrialInfo::files, events.jsonl, the engine's ping
//   StartWithSubnetRetry  plan the tree for a pair of subnets and Start it; another pair on a conflict
//   StartWatching         the monitor (end conditions), then the faults when the tree has no `faults` Step
//   Watch                 drain the log hub (HandleHubItem), tick the monitor and the faults, Ctrl-C,
//                         Restart (at most RunOptions::max_restarts), progress lines, until the end
//   ShutDown              undo the faults, Stop the tree, collect what the engine reports
//   WriteResult           result.json, trajectories.png, plots.html
//
// Ownership and lifetimes (members are destroyed in reverse order of declaration):
//   events_   open from PrepareFolder to the end; written by the engine's trace callback and the
//             fault injector too, so it outlives both.
//   hub_      outlives engine_, whose log follower threads push into it.
//   tree_     null until a plan succeeds; replaced on each subnet attempt, then fixed (a Restart
//             rebuilds the same tree). faults_step_ is the tree's `faults` Step (kFaultsStepId) or
//             null, looked up once per planned tree.
//   engine_   null until a tree is planned; one per subnet attempt.
//   monitor_  empty until the tree has started; made again after each Restart.
//   injector_ null until the faults are set up (by the tree's `faults` Step or StartWatching); one
//             per started tree. Destroyed first: its callbacks read monitor_ and write events_.
//
// Not thread-safe: everything runs on the calling thread except the engine's trace callback
// (serialised by the engine) and the log followers (which only push into hub_).
#pragma once

#include <cstdio>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/step.hpp"
#include "swarmbox/dsl/trial.hpp"
#include "swarmbox/runner/clock.hpp"
#include "swarmbox/runner/docker_engine.hpp"
#include "swarmbox/runner/fault_injector.hpp"
#include "swarmbox/runner/log_hub.hpp"
#include "swarmbox/runner/monitor.hpp"
#include "swarmbox/runner/results.hpp"
#include "swarmbox/runner/runner.hpp"
#include "swarmbox/runner/start_progress.hpp"
#include "swarmbox/runner/trajectories.hpp"
#include "swarmbox/runner/trial_progress.hpp"

namespace swarmbox::runner::detail {

// events.jsonl, appended line by line as events happen (flushed after each line).
class EventsFile {
 public:
  EventsFile() = default;
  ~EventsFile();
  EventsFile(const EventsFile&) = delete;
  EventsFile& operator=(const EventsFile&) = delete;
  Status Open(const std::filesystem::path& path);  // kIo when the file cannot be written
  void Write(const std::string& line);             // nothing before a successful Open

 private:
  std::FILE* file_ = nullptr;
};

class TrialRun {
 public:
  // Every argument must outlive the TrialRun.
  TrialRun(const TrialInfo& info, const Planner& planner, docker::DockerApi& api, Clock& clock,
           const RunOptions& options);
  TrialRun(const TrialRun&) = delete;
  TrialRun& operator=(const TrialRun&) = delete;

  // The driver: every phase in order. An error only when nothing could be started (RunTrial's
  // contract); every later problem is in the outcome's result.
  Result<RunOutcome> Run();

 private:
  // Phases.
  Status PrepareFolder();
  Result<dsl::Verdict> StartWithSubnetRetry();
  dsl::Verdict StartWatching();
  void Watch();
  void HandleHubItem(const HubItem& item);
  void Restart();
  void ShutDown(dsl::Verdict& verdict);
  Result<RunOutcome> WriteResult(const dsl::Verdict& verdict);

  // Starting.
  void RefreshTakenSubnets();
  EngineOptions MakeEngineOptions();
  void OnTrace(const dsl::Component& component, dsl::EventKind event, const dsl::Verdict& verdict);
  void AdoptTree(std::unique_ptr<dsl::Trial> tree);
  void DropTree();
  dsl::Verdict StartMonitor();

  // Faults.
  std::unique_ptr<FaultInjector> MakeInjector();
  dsl::Verdict SetUpFaults();  // a new injector for the started tree, and its set-up
  void BindFaults();           // the tree's `faults` Step runs SetUpFaults and the teardown
  dsl::Verdict StartFaults();  // SetUpFaults unless the tree's Step does it
  void AdvanceFaults();        // due faults at a watch tick
  void ResumeLogs();           // containers a fault brought back: follow their logs again

  // Watching.
  void HandleLogLine(const HubItem& item);
  void HandleStreamEnd(const HubItem& item);
  void RecordDetection(const HubItem& item, const LogfmtFields& fields);
  void FoldJoining(const HubItem& item, const LogfmtFields& fields);
  void Raise(const std::string& component, dsl::Verdict verdict, bool restart);

  // The end.
  void CollectTeardown(double stop_began_s, const dsl::Verdict& stop, dsl::Verdict& verdict);
  void DrawTrajectoriesPicture();
  void WritePlotsPage(const dsl::Verdict& verdict);

  double Wall() const;                   // [s] since the run began
  void Say(const std::string& line) const;  // a progress line, "[<trial>] <line>"

  const TrialInfo& info_;
  const Planner& planner_;
  docker::DockerApi& api_;
  Clock& clock_;
  const RunOptions& options_;
  const std::string run_id_;
  const std::string trial_id_;  // RunOptions::trial_id, or the trial's name
  const std::filesystem::path dir_;
  const bool has_faults_;

  EventsFile events_;
  std::vector<std::string> taken_subnets_;  // subnets of the engine's networks now
  double t0_s_ = 0;                         // Clock time the run began
  LogHub hub_;
  StartProgress counts_;  // created and started containers (Trace calls are serialised)
  std::unique_ptr<dsl::Trial> tree_;
  dsl::Step* faults_step_ = nullptr;  // in tree_, or null
  std::unique_ptr<DockerEngine> engine_;
  std::optional<Monitor> monitor_;
  std::unique_ptr<FaultInjector> injector_;

  RtfMeter rtf_;
  std::vector<Detection> detections_;  // victim_detected/victim_confirmed, for trajectories.png
  TrialProgress joining_;              // the physics server's event=joining/joined lines only
  TrialResult result_;
};

}  // namespace swarmbox::runner::detail
