// FaultInjector: the runner's I/O shell around swarmbox_faults (faults.hpp says what each piece
// does). It carries out a trial's network.mesh block and its `faults:` schedule on a Docker engine:
//
//   - Setup() (the tree's `faults` Step, after the sidecars started and before the agents start):
//     detects the mechanism once per host through the first sidecar (kernel netem, else the
//     userspace path), refuses rules the mechanism cannot honour (the trial ends with error and the
//     reason before any agent starts), then applies network.mesh on every drone's mesh interface
//     (eth1) from its sidecar. The sim link (eth0) is never touched.
//   - OnLogLine() / Advance(): feed the timeline (sim time, wall time, `on:` log events) and the
//     Raft leader tracker; each due action is carried out at once: radio (RadioLayers +
//     PlanRadioChange in the target's sidecar), partition (iptables chains in every agent's
//     sidecar), kill/stop/pause/restart (Docker API on the agent's container), gps_dropout /
//     gps_degrade / imu_bias / wind_gust (world commands: `swarmbox-physics --send-command ...`
//     exec'd in the physics container, one per target at once, exit code checked;
//     physics_plan.hpp). A fault that cannot be carried out (no leader elected yet, tc/iptables
//     failing, no physics server matched...) returns an error verdict.
//   - RemoveActive() (before the tree stops) and Teardown() (the Step's Stop): end every active
//     fault (newest first), then the mesh block on every sidecar. Both run only when the whole
//     tree stops (the trial's end, or a restart, which stops and removes every container), so
//     what lives in a sidecar's network namespace (network.mesh, radio faults, partitions: tc
//     qdiscs, iptables chains, NFQUEUE rules and the swarmbox-netemd daemons, processes of the
//     sidecar) is not undone command by command: it goes with the namespace when the sidecar
//     stops right after, and is recorded "removed" with a note saying so. Sensor and
//     environment faults end with the physics server the same way. Process faults are still
//     undone (a paused agent is unpaused so it can stop; a killed one started again). A fault
//     whose window ends mid-trial (Advance, OnLogLine) is always undone explicitly: the trial
//     goes on.
// Every fault action is two events.jsonl lines (FaultEventJson, with the mechanism): `requested`
// when the timeline asks for it (the targets resolved then), and `applied` once the mechanism has
// confirmed it on every target (every sidecar's commands exited 0, the Docker API answered for
// every container, every world command was acknowledged), or `failed`; a removal likewise
// `remove_requested`, then `removed`. Each line has its simulated and wall time, `applied` and
// `removed` also the request's (requested_t_sim_s, requested_wall_s). network.mesh is one
// MeshEventJson line per drone once its sidecar confirmed it; the detection is one line
// {"type":"mechanism",...}.
//
// Faults the physics server schedules (radio.model channel: `planned`, the radio plan's entries,
// runner/radio_schedule.hpp). The injector does not fire them; on the physics server's lines:
//   `event=drone_out drone=X fault=F mode=M`: the fault's container action on X's agent (kill: the
//       fault's signal, default SIGKILL; stop and restart: docker stop with the fault's timeout;
//       pause; the server's mode is how it keeps the drone out: radio_schedule.hpp),
//       recorded `requested` then `applied` (or `failed`), both with t_sim_s = the line's `t`, the
//       simulated time the drone left the lockstep (mechanism "docker");
//   `event=drone_back drone=X fault=F`: the reverse (start; unpause), `remove_requested` then
//       `removed` at the line's `t`; a started agent is followed again (TakeResumed);
//   `event=radio_fault fault=F kind=impair|partition state=on|off`: recorded `applied` / `removed`
//       at the line's `t` (mechanism "channel": the physics server carried it out);
//   `event=fault_skipped fault=F reason=R` (e.g. no Raft leader at its time): recorded `failed`.
// At the end of the trial a drone still paused is unpaused (so it can stop); killed and stopped
// ones stay down and are recorded removed with the trial's end.
//
// Process faults and the log watch: a container a fault stopped, killed or restarts is Disrupted()
// (the runner does not call its exit a crash); once a fault brings it back (start, restart) it is
// listed by TakeResumed() so the runner follows its log again.
//
// Thread-safety: none; the runner's thread drives it (the Step runs on that thread too).
#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <random>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/docker/docker_api.hpp"
#include "swarmbox/dsl/outcome.hpp"
#include "swarmbox/faults/faults.hpp"

namespace swarmbox::runner {

struct InjectorConfig {
  std::vector<std::string> drones;                 // trial order
  std::map<std::string, std::string> agents;       // drone -> agent container (Docker name or id)
  std::map<std::string, std::string> sidecars;     // drone -> fault sidecar container; empty when
                                                   // the trial has no network faults
  std::map<std::string, std::string> mesh_ipv4;    // drone -> its mesh address
  std::string mesh_interface = "eth1";
  faults::MeshImpairment mesh;
  std::vector<faults::Fault> faults;
  std::uint64_t seed = 0;        // the trial's: random targets and the delay daemons' draws
  std::string host = "local";    // the mechanism is detected once per host
  std::string netemd = "/usr/bin/swarmbox-netemd";  // in the sidecar image
  // Sensor and environment faults: the physics server's container (Docker name or id) and the
  // argv of one world command in it (plan.hpp PhysicsCommandArgv). Needed only when the trial
  // has such faults (Setup refuses them otherwise).
  std::string physics_container;
  std::function<std::vector<std::string>(const faults::WorldCommandCall&)> physics_command_argv;
  // radio.model channel: the faults the physics server schedules (not in `faults`) and the
  // component whose log lines report them.
  std::vector<faults::Fault> planned;
  std::string physics_component = "physics";
};

// The mechanism detected per host, shared by every trial of this process.
faults::MechanismCache& HostMechanisms();

class FaultInjector {
 public:
  using EventSink = std::function<void(const std::string& json_line)>;
  // Clocks: simulated seconds (the monitor's) and wall seconds since the trial's Run.
  using ClockFn = std::function<double()>;

  FaultInjector(docker::DockerApi& api, InjectorConfig config, EventSink events, ClockFn sim_s,
                ClockFn wall_s, faults::MechanismCache* mechanisms = &HostMechanisms());

  // Mechanism + network.mesh on every sidecar. An error verdict says what went wrong (the runner
  // then tears down); sensor and environment faults are refused here when there is no physics
  // container to send them to.
  dsl::Verdict Setup();
  // Every log line of every container (leader tracking, `on:` triggers).
  std::optional<dsl::Verdict> OnLogLine(const std::string& component, const std::string& line);
  // Often (every watch-loop turn): `at`/`at_wall` starts and the ends of durations.
  std::optional<dsl::Verdict> Advance();
  // At the end of the tree (trial end or restart; see the banner): ends every active fault,
  // newest first, leaving what dies with the sidecars' namespaces and the physics server to them
  // (best effort; failures are recorded and returned).
  dsl::Verdict RemoveActive();
  // RemoveActive, then records network.mesh removed with the namespaces. Idempotent. Call it only
  // when the sidecars are stopped right after (the tree's Step does).
  dsl::Verdict Teardown();

  bool Disrupted(const std::string& component) const { return disrupted_.count(component) != 0; }
  std::vector<std::string> TakeResumed();
  // The mechanism in use (after Setup with sidecars).
  const std::optional<faults::Mechanism>& mechanism() const { return mechanism_; }
  // What went wrong without ending the trial (teardown leftovers).
  const std::vector<std::string>& problems() const { return problems_; }

 private:
  // Setup's steps: what the trial needs of the host (a verdict ends Setup there), the mechanism
  // (detected once per host), what it cannot honour, network.mesh on every sidecar.
  std::optional<dsl::Verdict> CheckSetupNeeds() const;
  Result<faults::Mechanism> DetectMechanismOnce();
  Status CheckMechanismHonours(faults::Mechanism mech) const;
  dsl::Verdict ApplyMesh(faults::Mechanism mech);
  // trial_end: the removals come from RemoveActive (see the banner).
  std::optional<dsl::Verdict> Carry(const std::vector<faults::TimelineAction>& actions, bool trial_end);
  // The fault's targets (and mechanism) into `record` and targets_ (pure: the leader tracker, the
  // random draw); Apply then carries it out on them.
  Status Resolve(std::size_t index, faults::FaultEventRecord* record);
  Status Apply(std::size_t index, faults::FaultEventRecord* record);
  // Apply's process fault: the docker actions on the targets' agent containers.
  Status ApplyProcessFault(std::size_t index, const faults::ProcessFault& process,
                           const std::vector<std::string>& targets);
  // A drone a process fault took down is back (TakeResumed hands it to the runner).
  void MarkResumed(const std::string& drone);
  Status Remove(std::size_t index, faults::FaultEventRecord* record, bool trial_end);
  // Remove's kinds: the radio's layer, a partition's chains, a process fault's docker undo, a
  // physics fault's undo commands.
  Status RemoveRadio(const faults::Fault& f, faults::FaultEventRecord* record, bool trial_end);
  Status RemovePartition(std::size_t index, faults::FaultEventRecord* record, bool trial_end);
  Status RemoveProcessFault(std::size_t index, faults::FaultEventRecord* record);
  Status RemovePhysicsFault(std::size_t index, faults::FaultEventRecord* record, bool trial_end);
  Status ChangeRadio(const std::map<std::string, std::vector<faults::RadioRule>>& before,
                     const std::vector<std::string>& changed);
  // Runs each drone's commands in its sidecar, all sidecars concurrently (RunCommands, or
  // RunAllCommands for undo paths); the first failure in trial order.
  Status RunOnSidecars(const std::map<std::string, std::vector<faults::Command>>& per_drone, bool run_all);
  faults::LinkTarget LinkOf(const std::string& drone) const;
  std::vector<faults::MeshNode> MeshNodes() const;
  faults::RadioPlanOptions PlanOptions() const;
  faults::CommandRunner& Sidecar(const std::string& drone);
  // Sends the world commands through the physics container, all at once; the first failure.
  Status SendToPhysics(const std::vector<faults::WorldCommandCall>& calls);
  faults::FaultEventRecord Record(faults::FaultPhase phase) const;
  // A planned fault's record of one drone's container (mechanism docker) at `t_sim_s`.
  faults::FaultEventRecord DroneRecord(faults::FaultPhase phase, const std::string& drone, double t_sim_s) const;
  // The `requested` record confirmed now: `phase` with the clocks' times, the request's times as
  // requested_t_sim_s/requested_wall_s, targets, mechanism and note kept.
  faults::FaultEventRecord Confirmed(faults::FaultEventRecord requested, faults::FaultPhase phase) const;
  // The event of a fault's step (failed with the error when `s` is one), and then the verdict
  // "fault ID (KIND) could not be DONE: ERROR" for a failure, nullopt for success.
  std::optional<dsl::Verdict> Conclude(const faults::Fault& fault, faults::FaultEventRecord record,
                                       const Status& s, std::string_view done) const;
  void Emit(const faults::Fault& fault, const faults::FaultEventRecord& record) const;
  // A physics server line reporting a planned fault (drone_out, drone_back, radio_fault); nullopt
  // verdict when carried out (or not such a line).
  std::optional<dsl::Verdict> OnPlannedEvent(const std::string& line);
  // The planned fault of that id (nullptr when the plan has none).
  const faults::Fault* PlannedFault(const std::string& id) const;
  // A radio_fault line (state on/off): the channel carried it out; recorded as it happened.
  std::optional<dsl::Verdict> RecordChannelFault(const faults::Fault& fault, const std::string& state,
                                                 const std::string& line, double t_sim_s);
  // Why the physics server cannot take `drone` out for `fault` ("" when it can).
  std::string DroneOutRefusal(const faults::Fault& fault, const std::string& drone) const;
  std::optional<dsl::Verdict> DroneOut(const faults::Fault& fault, const std::string& drone, double t_sim_s);
  // `drone` by value: RemoveActive passes a key of out_, which this erases before it is done.
  std::optional<dsl::Verdict> DroneBack(std::string drone, double t_sim_s, bool trial_end);

  docker::DockerApi& api_;
  InjectorConfig config_;
  EventSink events_;
  ClockFn sim_s_;
  ClockFn wall_s_;
  faults::MechanismCache* mechanisms_;
  std::optional<faults::Mechanism> mechanism_;
  faults::FaultTimeline timeline_;
  faults::LeaderTracker leaders_;
  faults::RadioLayers layers_;
  std::mt19937_64 rng_;
  std::map<std::string, std::unique_ptr<faults::DockerExecCommandRunner>> runners_;
  std::map<std::size_t, std::vector<std::string>> targets_;          // fault -> resolved drones
  std::map<std::size_t, faults::PartitionPlan> partitions_;          // active partitions
  std::map<std::size_t, faults::ProcessPlan> processes_;             // active process faults
  std::map<std::size_t, faults::PhysicsPlan> physics_;               // active sensor/world faults
  std::unique_ptr<faults::DockerExecCommandRunner> physics_runner_;
  std::map<std::string, std::vector<faults::RadioRule>> installed_;  // drone -> rules in place
  // drone -> the planned fault that took it out, and what brings it back
  struct Out {
    const faults::Fault* fault = nullptr;
    std::vector<faults::DockerAction> undo;
  };
  std::map<std::string, Out> out_;
  std::set<std::string> disrupted_;  // agent components a process fault took down
  std::vector<std::string> resumed_;
  std::vector<std::string> problems_;
  bool set_up_ = false;
  bool torn_down_ = false;
};

}  // namespace swarmbox::runner
