#include "swarmbox/runner/fault_injector.hpp"

#include <cstdio>
#include <future>
#include <utility>
#include <variant>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::runner {

using dsl::Verdict;
using faults::FaultPhase;
using faults::TimelineAction;

namespace {

constexpr std::string_view kPhysicsMechanism = "physics-command";
// events.jsonl notes for what the end of a trial leaves to the containers' removal (Remove,
// Teardown).
constexpr std::string_view kWithNamespace = "with the sidecar's network namespace";
constexpr std::string_view kWithPhysics = "with the physics server";

std::string MechanismEventJson(const std::string& host, faults::Mechanism mechanism, bool cached,
                               double wall_s) {
  using yaml::Node;
  auto str = [](std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); };
  Node root = Node::Mapping();
  root.Set("type", str("mechanism"));
  root.Set("host", str(host));
  root.Set("mechanism", str(faults::MechanismName(mechanism)));
  root.Set("detected", Node::Scalar(cached ? "false" : "true"));
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3f", wall_s);
  root.Set("wall_s", Node::Scalar(buf));
  return yaml::EmitJson(root);
}

}  // namespace

faults::MechanismCache& HostMechanisms() {
  static faults::MechanismCache cache;
  return cache;
}

FaultInjector::FaultInjector(docker::DockerApi& api, InjectorConfig config, EventSink events,
                             ClockFn sim_s, ClockFn wall_s, faults::MechanismCache* mechanisms)
    : api_(api),
      config_(std::move(config)),
      events_(std::move(events)),
      sim_s_(std::move(sim_s)),
      wall_s_(std::move(wall_s)),
      mechanisms_(mechanisms != nullptr ? mechanisms : &HostMechanisms()),
      timeline_(config_.faults),
      layers_(config_.mesh.rules, config_.drones),
      rng_(config_.seed) {}

faults::FaultEventRecord FaultInjector::Record(FaultPhase phase) const {
  faults::FaultEventRecord r;
  r.phase = phase;
  r.t_sim_s = sim_s_ ? sim_s_() : 0.0;
  r.wall_s = wall_s_ ? wall_s_() : 0.0;
  return r;
}

faults::CommandRunner& FaultInjector::Sidecar(const std::string& drone) {
  auto it = runners_.find(drone);
  if (it == runners_.end()) {
    auto container = config_.sidecars.find(drone);
    const std::string name = container == config_.sidecars.end() ? drone + "-faults" : container->second;
    it = runners_.emplace(drone, std::make_unique<faults::DockerExecCommandRunner>(api_, name)).first;
  }
  return *it->second;
}

Status FaultInjector::SendToPhysics(const std::vector<faults::WorldCommandCall>& calls) {
  if (!physics_runner_) {
    physics_runner_ = std::make_unique<faults::DockerExecCommandRunner>(api_, config_.physics_container);
  }
  // One exec per call, all at once (each waits up to ~1 s for the bus): a fault on several drones
  // starts on all of them together. The first failure in call order.
  std::vector<std::future<Status>> jobs;
  for (const faults::WorldCommandCall& call : calls) {
    jobs.push_back(std::async(std::launch::async, [this, argv = config_.physics_command_argv(call)] {
      return faults::RunCommands(*physics_runner_, {faults::Command{argv, false}});
    }));
  }
  Status first = Ok{};
  for (std::size_t i = 0; i < jobs.size(); ++i) {
    Status s = jobs[i].get();
    if (!s && first) first = s.error().Context("sending " + faults::WorldCommandText(calls[i]) + " to the physics server");
  }
  return first;
}

faults::LinkTarget FaultInjector::LinkOf(const std::string& drone) const {
  faults::LinkTarget link;
  link.node = drone;
  link.mesh_interface = config_.mesh_interface;
  for (const auto& [peer, ip] : config_.mesh_ipv4) {
    if (peer != drone) link.peer_ipv4[peer] = ip;
  }
  return link;
}

faults::RadioPlanOptions FaultInjector::PlanOptions() const {
  faults::RadioPlanOptions o;
  o.seed = config_.seed;
  o.netemd = config_.netemd;
  return o;
}

Verdict FaultInjector::Setup() {
  if (set_up_) return Verdict::Success();
  set_up_ = true;
  if (auto done = CheckSetupNeeds()) return *done;
  auto mech = DetectMechanismOnce();
  if (!mech) return Verdict::FromError(mech.error(), "faults");
  // Refuse, before any agent starts, what this host's mechanism cannot honour.
  if (Status s = CheckMechanismHonours(*mech); !s) return Verdict::FromError(s.error(), "faults");
  if (config_.mesh.empty()) return Verdict::Success();
  return ApplyMesh(*mech);
}

// A physics fault needs the physics container; network faults need a sidecar per drone on the
// mesh. Without network faults and sidecars there is nothing more to set up (success).
std::optional<Verdict> FaultInjector::CheckSetupNeeds() const {
  for (const faults::Fault& f : config_.faults) {
    if (faults::IsPhysicsFault(f) && (config_.physics_container.empty() || !config_.physics_command_argv)) {
      return Verdict::Err("fault " + f.id + " (" + std::string(f.kind()) + ", " + f.mark.ToString() +
                              ") cannot be carried out: no physics server container to send it to",
                          "faults");
    }
  }
  bool network_faults = !config_.mesh.empty();
  for (const faults::Fault& f : config_.faults) {
    network_faults = network_faults || std::holds_alternative<faults::RadioFault>(f.action) ||
                     std::holds_alternative<faults::PartitionFault>(f.action);
  }
  if (config_.sidecars.empty()) {
    if (!network_faults) return Verdict::Success();
    return Verdict::Err("this trial impairs the mesh but its agents have no fault sidecars (planned "
                        "without a fault sidecar image)",
                        "faults");
  }
  for (const std::string& d : config_.drones) {
    if (config_.sidecars.count(d) == 0 || config_.mesh_ipv4.count(d) == 0) {
      return Verdict::Err("drone " + d + " has no fault sidecar on the mesh network", "faults");
    }
  }
  return std::nullopt;
}

// The host's mechanism (probed in the first drone's sidecar, once per host) into mechanism_, and
// its event.
Result<faults::Mechanism> FaultInjector::DetectMechanismOnce() {
  const std::string& probe_drone = config_.drones.front();
  bool detected_now = false;
  auto mech = mechanisms_->Get(config_.host, [&]() {
    detected_now = true;
    return faults::DetectMechanism(Sidecar(probe_drone));
  });
  if (!mech) return mech.error().Context("detecting the netem mechanism in the sidecar of " + probe_drone);
  mechanism_ = *mech;
  if (events_) events_(MechanismEventJson(config_.host, *mech, !detected_now, wall_s_ ? wall_s_() : 0.0));
  return *mech;
}

Status FaultInjector::CheckMechanismHonours(faults::Mechanism mech) const {
  if (Status s = faults::CheckMechanismSupports(config_.mesh.rules, mech); !s) {
    return s.error().Context("network.mesh");
  }
  for (const faults::Fault& f : config_.faults) {
    if (const auto* radio = std::get_if<faults::RadioFault>(&f.action)) {
      if (Status s = faults::CheckMechanismSupports(radio->rules, mech); !s) {
        return s.error().Context("fault " + f.id);
      }
    }
  }
  return Ok{};
}

// network.mesh on every sidecar at once (each is a few docker exec round trips); results
// recorded in trial order, the first failure the verdict.
Verdict FaultInjector::ApplyMesh(faults::Mechanism mech) {
  const std::string mechanism_name(faults::MechanismName(mech));
  std::vector<std::pair<std::string, std::future<Status>>> jobs;
  for (const std::string& drone : config_.drones) {
    const auto rules = layers_.Effective(drone);
    installed_[drone] = rules;  // partly applied counts: teardown undoes it (undo may fail)
    faults::CommandRunner& sidecar = Sidecar(drone);
    auto plan = faults::PlanRadio(rules, LinkOf(drone), mech, PlanOptions());
    if (!plan) {
      std::promise<Status> failed;
      failed.set_value(plan.error());
      jobs.emplace_back(drone, failed.get_future());
      continue;
    }
    jobs.emplace_back(drone, std::async(std::launch::async, [&sidecar, commands = plan->apply] {
                        return faults::RunCommands(sidecar, commands);
                      }));
  }
  std::optional<Verdict> failure;
  for (auto& [drone, job] : jobs) {
    const Status s = job.get();
    faults::FaultEventRecord record = Record(FaultPhase::kApplied);
    record.mechanism = mechanism_name;
    if (!s) {
      record.phase = FaultPhase::kFailed;
      record.error = s.error().ToString();
      if (!failure) {
        failure = Verdict::FromError(s.error().Context("applying network.mesh on " + drone), "faults");
      }
    }
    if (events_) events_(faults::MeshEventJson(drone, installed_[drone], record));
  }
  return failure ? *failure : Verdict::Success();
}

Status FaultInjector::RunOnSidecars(const std::map<std::string, std::vector<faults::Command>>& per_drone,
                                    bool run_all) {
  // Every sidecar at once, so a fault on several drones starts (and ends) on all of them together;
  // the first failure in trial order is returned.
  std::vector<std::pair<std::string, std::future<Status>>> jobs;
  for (const std::string& drone : config_.drones) {
    auto it = per_drone.find(drone);
    if (it == per_drone.end()) continue;
    faults::CommandRunner& sidecar = Sidecar(drone);
    jobs.emplace_back(drone, std::async(std::launch::async, [&sidecar, commands = it->second, run_all] {
                        return run_all ? faults::RunAllCommands(sidecar, commands)
                                       : faults::RunCommands(sidecar, commands);
                      }));
  }
  Status first = Ok{};
  for (auto& [drone, job] : jobs) {
    Status s = job.get();
    if (!s && first) first = s.error().Context(drone);
  }
  return first;
}

Status FaultInjector::ChangeRadio(const std::map<std::string, std::vector<faults::RadioRule>>& before,
                                  const std::vector<std::string>& changed) {
  if (!mechanism_) {
    return Error(ErrorCode::kInternal, "radio fault before the mechanism was detected (no sidecars?)");
  }
  std::map<std::string, std::vector<faults::Command>> commands;
  for (const std::string& drone : changed) {
    auto it = before.find(drone);
    const std::vector<faults::RadioRule> from =
        it == before.end() ? std::vector<faults::RadioRule>{} : it->second;
    const auto to = layers_.Effective(drone);
    auto plan = faults::PlanRadioChange(from, to, LinkOf(drone), *mechanism_, PlanOptions());
    if (!plan) return plan.error().Context(drone);
    commands[drone] = plan->apply;
  }
  for (const std::string& drone : changed) installed_[drone] = layers_.Effective(drone);
  return RunOnSidecars(commands, /*run_all=*/false);
}

std::vector<faults::MeshNode> FaultInjector::MeshNodes() const {
  std::vector<faults::MeshNode> nodes;
  for (const std::string& d : config_.drones) {
    auto ip = config_.mesh_ipv4.find(d);
    nodes.push_back({d, config_.mesh_interface, ip == config_.mesh_ipv4.end() ? "" : ip->second});
  }
  return nodes;
}

Status FaultInjector::Resolve(std::size_t index, faults::FaultEventRecord* record) {
  const faults::Fault& f = timeline_.faults()[index];
  if (const auto* radio = std::get_if<faults::RadioFault>(&f.action)) {
    if (mechanism_) record->mechanism = std::string(faults::MechanismName(*mechanism_));
    auto targets = faults::ResolveTarget(radio->target, config_.drones, leaders_, rng_);
    if (!targets) return targets.error();
    record->targets = *targets;
  } else if (const auto* partition = std::get_if<faults::PartitionFault>(&f.action)) {
    record->mechanism = "iptables";
    auto plan = faults::PlanPartition(*partition, MeshNodes(), index);  // pure: Apply plans again
    if (!plan) return plan.error();
    for (const auto& group : plan->groups) record->targets.insert(record->targets.end(), group.begin(), group.end());
  } else if (const auto* process = std::get_if<faults::ProcessFault>(&f.action)) {
    record->mechanism = "docker";
    auto targets = faults::ResolveTarget(process->target, config_.drones, leaders_, rng_);
    if (!targets) return targets.error();
    record->targets = *targets;
  } else if (faults::IsPhysicsFault(f)) {
    record->mechanism = std::string(kPhysicsMechanism);
    if (const faults::FaultTarget* target = f.target()) {
      auto resolved = faults::ResolveTarget(*target, config_.drones, leaders_, rng_);
      if (!resolved) return resolved.error();
      record->targets = *resolved;
    }
  }
  targets_[index] = record->targets;
  return Ok{};
}

Status FaultInjector::Apply(std::size_t index, faults::FaultEventRecord* record) {
  const faults::Fault& f = timeline_.faults()[index];
  // Targets and mechanism: Resolve (before the `requested` record).
  const std::vector<std::string> targets = record->targets;
  if (const auto* radio = std::get_if<faults::RadioFault>(&f.action)) {
    const auto before = installed_;
    const auto changed = layers_.Push(f.id, targets, radio->rules);
    return ChangeRadio(before, changed);
  }
  if (const auto* partition = std::get_if<faults::PartitionFault>(&f.action)) {
    auto plan = faults::PlanPartition(*partition, MeshNodes(), index);
    if (!plan) return plan.error();
    partitions_[index] = *plan;  // stored first: a half-applied partition is healed too
    return RunOnSidecars(plan->apply, /*run_all=*/false);
  }
  if (const auto* process = std::get_if<faults::ProcessFault>(&f.action)) {
    return ApplyProcessFault(index, *process, targets);
  }
  if (faults::IsPhysicsFault(f)) {
    faults::PhysicsPlan plan = faults::PlanPhysicsFault(f, targets);
    physics_[index] = plan;  // stored first: a half-applied bias jump is taken back too
    return SendToPhysics(plan.apply);
  }
  return Error(ErrorCode::kInvalidArgument,
               "fault " + f.id + " (" + std::string(f.kind()) + ") cannot be carried out by the runner",
               f.mark.ToString());
}

Status FaultInjector::ApplyProcessFault(std::size_t index, const faults::ProcessFault& process,
                                        const std::vector<std::string>& targets) {
  std::vector<std::string> containers;
  for (const std::string& d : targets) {
    auto c = config_.agents.find(d);
    if (c == config_.agents.end()) return Error(ErrorCode::kInternal, "no container for drone " + d);
    containers.push_back(c->second);
  }
  const bool has_duration = timeline_.faults()[index].duration_ms.has_value();
  faults::ProcessPlan plan = faults::PlanProcessFault(process, containers, has_duration);
  const bool takes_down = process.action != faults::ProcessAction::kPause;
  if (takes_down) disrupted_.insert(targets.begin(), targets.end());
  processes_[index] = plan;
  Status s = faults::ExecuteDockerActions(api_, plan.apply);
  if (process.action == faults::ProcessAction::kRestart) {
    for (const std::string& d : targets) MarkResumed(d);
  }
  return s;
}

void FaultInjector::MarkResumed(const std::string& drone) {
  disrupted_.erase(drone);
  resumed_.push_back(drone);
}

Status FaultInjector::Remove(std::size_t index, faults::FaultEventRecord* record, bool trial_end) {
  const faults::Fault& f = timeline_.faults()[index];
  if (auto t = targets_.find(index); t != targets_.end()) record->targets = t->second;
  if (std::holds_alternative<faults::RadioFault>(f.action)) return RemoveRadio(f, record, trial_end);
  if (std::holds_alternative<faults::PartitionFault>(f.action)) return RemovePartition(index, record, trial_end);
  if (std::holds_alternative<faults::ProcessFault>(f.action)) return RemoveProcessFault(index, record);
  if (faults::IsPhysicsFault(f)) return RemovePhysicsFault(index, record, trial_end);
  return Ok{};
}

Status FaultInjector::RemoveRadio(const faults::Fault& f, faults::FaultEventRecord* record, bool trial_end) {
  if (mechanism_) record->mechanism = std::string(faults::MechanismName(*mechanism_));
  const auto before = installed_;
  const auto changed = layers_.Pop(f.id);
  if (trial_end) {
    // Its qdiscs, iptables chains and delay daemons live in the sidecars' network namespaces
    // (the daemons are processes of the sidecars): they go when the sidecars stop, right after.
    for (const std::string& drone : changed) installed_[drone] = layers_.Effective(drone);
    record->note = std::string(kWithNamespace);
    return Ok{};
  }
  return ChangeRadio(before, changed);
}

Status FaultInjector::RemovePartition(std::size_t index, faults::FaultEventRecord* record, bool trial_end) {
  record->mechanism = "iptables";
  auto it = partitions_.find(index);
  if (it == partitions_.end()) return Ok{};
  if (trial_end) {  // iptables chains in the sidecars' namespaces, as above
    partitions_.erase(it);
    record->note = std::string(kWithNamespace);
    return Ok{};
  }
  Status first = RunOnSidecars(it->second.undo, /*run_all=*/true);
  partitions_.erase(it);
  return first;
}

Status FaultInjector::RemoveProcessFault(std::size_t index, faults::FaultEventRecord* record) {
  record->mechanism = "docker";
  auto it = processes_.find(index);
  if (it == processes_.end()) return Ok{};
  std::vector<faults::DockerAction> undo = it->second.undo;
  // A pause without a duration lasts until the end: unpaused here, so teardown can stop it.
  if (undo.empty()) {
    for (const auto& a : it->second.apply) {
      if (a.kind == faults::DockerAction::Kind::kPause) {
        undo.push_back({faults::DockerAction::Kind::kUnpause, a.container, "", 0});
      }
    }
  }
  Status s = faults::ExecuteDockerActions(api_, undo);
  bool started = false;
  for (const auto& a : undo) started = started || a.kind == faults::DockerAction::Kind::kStart;
  if (started && s) {
    for (const std::string& d : record->targets) MarkResumed(d);
  }
  processes_.erase(it);
  return s;
}

// gps_dropout, gps_degrade and wind_gust end in the physics server itself (their duration
// travelled with the command); an imu_bias with a duration is taken back by the negated jump.
Status FaultInjector::RemovePhysicsFault(std::size_t index, faults::FaultEventRecord* record, bool trial_end) {
  record->mechanism = std::string(kPhysicsMechanism);
  auto it = physics_.find(index);
  if (it == physics_.end()) return Ok{};
  const std::vector<faults::WorldCommandCall> undo = it->second.undo;
  physics_.erase(it);
  if (trial_end) {  // the physics server stops with the trial: its world state goes with it
    if (!undo.empty()) record->note = std::string(kWithPhysics);
    return Ok{};
  }
  return SendToPhysics(undo);
}

std::optional<Verdict> FaultInjector::Carry(const std::vector<TimelineAction>& actions, bool trial_end) {
  std::optional<Verdict> failure;
  for (const TimelineAction& action : actions) {
    const faults::Fault& f = timeline_.faults()[action.fault];
    const bool apply = action.kind == TimelineAction::Kind::kApply;
    // `requested` (or `remove_requested`) when the timeline asks, with the targets it resolved;
    // `applied` (`removed`) with the time every target's mechanism confirmed it: tc/iptables/
    // swarmbox-netemd exited 0 in every sidecar (the delay daemon only once bound to its queue),
    // the Docker API answered for every container, every world command's exec exited 0.
    faults::FaultEventRecord record = Record(apply ? FaultPhase::kRequested : FaultPhase::kRemoveRequested);
    Status s = Ok{};
    if (apply) {
      s = Resolve(action.fault, &record);
    } else if (auto t = targets_.find(action.fault); t != targets_.end()) {
      record.targets = t->second;
    }
    Emit(f, record);
    if (s) {
      s = apply ? Apply(action.fault, &record) : Remove(action.fault, &record, trial_end);
      record = Confirmed(std::move(record), apply ? FaultPhase::kApplied : FaultPhase::kRemoved);
    }
    auto verdict = Conclude(f, std::move(record), s, apply ? "applied" : "removed");
    if (verdict && !failure) failure = std::move(verdict);
  }
  return failure;
}

std::optional<Verdict> FaultInjector::OnPlannedEvent(const std::string& line) {
  const LogfmtFields fields = ParseLogfmt(line);
  const std::string event = FindField(fields, "event").value_or("");
  if (event != "drone_out" && event != "drone_back" && event != "radio_fault" && event != "fault_skipped") {
    return std::nullopt;
  }
  const std::string name = FindField(fields, "fault").value_or("");
  const faults::Fault* fault = PlannedFault(name);
  if (fault == nullptr) {
    return Verdict::Err("the physics server reported fault '" + name + "', which is not in the radio plan: " + line,
                        "faults");
  }
  // The simulated time it landed: the line's own (the monitor's clock may lag a line behind).
  const auto t = yaml::ScalarAsDouble(FindField(fields, "t").value_or(""));
  const double t_sim_s = t ? *t : (sim_s_ ? sim_s_() : 0.0);
  const std::string drone = FindField(fields, "drone").value_or("");
  if (event == "drone_out") return DroneOut(*fault, drone, t_sim_s);
  if (event == "drone_back") return DroneBack(drone, t_sim_s, /*trial_end=*/false);
  if (event == "fault_skipped") {  // e.g. no drone led the Raft group at its time
    faults::FaultEventRecord record = Record(FaultPhase::kFailed);
    record.t_sim_s = t_sim_s;
    record.mechanism = "physics";
    record.error = "skipped by the physics server: " + FindField(fields, "reason").value_or("no reason given");
    Emit(*fault, record);
    return std::nullopt;
  }
  return RecordChannelFault(*fault, FindField(fields, "state").value_or(""), line, t_sim_s);
}

const faults::Fault* FaultInjector::PlannedFault(const std::string& id) const {
  const faults::Fault* fault = nullptr;
  for (const faults::Fault& f : config_.planned) {
    if (f.id == id) fault = &f;
  }
  return fault;
}

// radio_fault: the channel carried it out in the physics server; recorded as it happened.
std::optional<Verdict> FaultInjector::RecordChannelFault(const faults::Fault& fault, const std::string& state,
                                                         const std::string& line, double t_sim_s) {
  if (state != "on" && state != "off") {
    return Verdict::Err("the physics server reported a radio fault with state '" + state + "': " + line, "faults");
  }
  faults::FaultEventRecord record = Record(state == "on" ? FaultPhase::kApplied : FaultPhase::kRemoved);
  record.t_sim_s = t_sim_s;
  record.requested_t_sim_s = t_sim_s;
  record.requested_wall_s = record.wall_s;
  record.mechanism = "channel";
  Emit(fault, record);
  return std::nullopt;
}

namespace {

// The docker actions that take an agent's container out for a planned process fault (the server's
// mode says how it keeps the drone out: a kill with a duration is its `restart`; the fault says
// what happens to the container), and the one that brings it back.
struct DroneOutActions {
  std::vector<faults::DockerAction> apply;
  std::vector<faults::DockerAction> undo;
};

DroneOutActions PlanDroneOut(const faults::ProcessFault& process, const std::string& container) {
  using Kind = faults::DockerAction::Kind;
  DroneOutActions actions;
  switch (process.action) {
    case faults::ProcessAction::kKill: actions.apply = {{Kind::kKill, container, process.signal, 0}}; break;
    case faults::ProcessAction::kStop:
    case faults::ProcessAction::kRestart: actions.apply = {{Kind::kStop, container, "", process.timeout_s}}; break;
    case faults::ProcessAction::kPause: actions.apply = {{Kind::kPause, container, "", 0}}; break;
  }
  const bool paused = process.action == faults::ProcessAction::kPause;
  actions.undo = {{paused ? Kind::kUnpause : Kind::kStart, container, "", 0}};
  return actions;
}

}  // namespace

void FaultInjector::Emit(const faults::Fault& fault, const faults::FaultEventRecord& record) const {
  if (events_) events_(faults::FaultEventJson(fault, record));
}

faults::FaultEventRecord FaultInjector::DroneRecord(FaultPhase phase, const std::string& drone, double t_sim_s) const {
  faults::FaultEventRecord record = Record(phase);
  record.t_sim_s = t_sim_s;
  record.targets = {drone};
  record.mechanism = "docker";
  return record;
}

faults::FaultEventRecord FaultInjector::Confirmed(faults::FaultEventRecord requested, FaultPhase phase) const {
  const faults::FaultEventRecord done = Record(phase);
  requested.requested_t_sim_s = requested.t_sim_s;
  requested.requested_wall_s = requested.wall_s;
  requested.phase = done.phase;
  requested.t_sim_s = done.t_sim_s;
  requested.wall_s = done.wall_s;
  return requested;
}

std::optional<Verdict> FaultInjector::Conclude(const faults::Fault& fault, faults::FaultEventRecord record,
                                               const Status& s, std::string_view done) const {
  if (!s) {
    record.phase = FaultPhase::kFailed;
    record.error = s.error().ToString();
  }
  Emit(fault, record);
  if (s) return std::nullopt;
  return Verdict::Err("fault " + fault.id + " (" + std::string(fault.kind()) + ") could not be " + std::string(done) +
                          ": " + s.error().ToString(),
                      "faults");
}

std::string FaultInjector::DroneOutRefusal(const faults::Fault& fault, const std::string& drone) const {
  if (!std::holds_alternative<faults::ProcessFault>(fault.action)) {
    return "the physics server took " + drone + " out for fault " + fault.id + ", which is a " +
           std::string(fault.kind()) + " fault, not a process fault";
  }
  if (config_.agents.count(drone) == 0) {
    return "the physics server took out '" + drone + "', which is not a drone of this trial";
  }
  return "";
}

std::optional<Verdict> FaultInjector::DroneOut(const faults::Fault& fault, const std::string& drone,
                                               double t_sim_s) {
  faults::FaultEventRecord record = DroneRecord(FaultPhase::kRequested, drone, t_sim_s);
  if (const std::string refusal = DroneOutRefusal(fault, drone); !refusal.empty()) {
    return Conclude(fault, std::move(record), Error(ErrorCode::kInvalidArgument, refusal), "applied");
  }
  Emit(fault, record);
  const auto& process = std::get<faults::ProcessFault>(fault.action);
  DroneOutActions actions = PlanDroneOut(process, config_.agents.at(drone));
  if (process.action != faults::ProcessAction::kPause) disrupted_.insert(drone);
  out_[drone] = Out{&fault, std::move(actions.undo)};  // stored first: a half-done action is undone too
  const Status s = faults::ExecuteDockerActions(api_, actions.apply);
  record = Confirmed(std::move(record), FaultPhase::kApplied);
  record.t_sim_s = t_sim_s;  // out of the lockstep at exactly this time; the container followed
  return Conclude(fault, std::move(record), s, "applied");
}

std::optional<Verdict> FaultInjector::DroneBack(std::string drone, double t_sim_s, bool trial_end) {
  auto it = out_.find(drone);
  if (it == out_.end()) {
    return Verdict::Err("the physics server brought back '" + drone + "', which no fault took out", "faults");
  }
  const Out out = it->second;
  out_.erase(it);
  const faults::Fault& fault = *out.fault;
  faults::FaultEventRecord record = DroneRecord(FaultPhase::kRemoveRequested, drone, t_sim_s);
  Emit(fault, record);
  const bool paused = !out.undo.empty() && out.undo.front().kind == faults::DockerAction::Kind::kUnpause;
  Status s = Ok{};
  // At the trial's end only a paused agent is brought back (so it can stop); the others stay down.
  if (!trial_end || paused) s = faults::ExecuteDockerActions(api_, out.undo);
  record = Confirmed(std::move(record), FaultPhase::kRemoved);
  if (!trial_end) record.t_sim_s = t_sim_s;
  if (trial_end && !paused) record.note = "left down: the trial's end stops every container";
  if (s && !trial_end && !paused) MarkResumed(drone);
  return Conclude(fault, std::move(record), s, "removed");
}

std::optional<Verdict> FaultInjector::OnLogLine(const std::string& component, const std::string& line) {
  if (torn_down_) return std::nullopt;
  if (!config_.planned.empty() && component == config_.physics_component) {
    if (auto v = OnPlannedEvent(line)) return v;
  }
  leaders_.Feed(line);
  return Carry(timeline_.OnLogLine(line, wall_s_ ? wall_s_() : 0.0), /*trial_end=*/false);
}

std::optional<Verdict> FaultInjector::Advance() {
  if (torn_down_) return std::nullopt;
  return Carry(timeline_.Advance(sim_s_ ? sim_s_() : 0.0, wall_s_ ? wall_s_() : 0.0),
               /*trial_end=*/false);
}

Verdict FaultInjector::RemoveActive() {
  // The drones the physics server took out and has not brought back, newest fault last: as the
  // trial ends (a paused one is unpaused so it can stop).
  std::optional<Verdict> out_failure;
  while (!out_.empty()) {
    auto v = DroneBack(out_.begin()->first, sim_s_ ? sim_s_() : 0.0, /*trial_end=*/true);
    if (v && !out_failure) out_failure = v;
  }
  auto failure = Carry(timeline_.RemoveAll(), /*trial_end=*/true);
  if (!failure) failure = out_failure;
  if (failure) {
    problems_.push_back(failure->reason);
    return *failure;
  }
  return Verdict::Success();
}

Verdict FaultInjector::Teardown() {
  if (torn_down_) return Verdict::Success();
  Verdict v = RemoveActive();
  torn_down_ = true;
  if (!mechanism_) return v;
  // network.mesh is not undone command by command (it was ~1.3 s of a SAR trial's teardown under
  // load, every sidecar running its iptables -D/-F/-X, tc and `swarmbox-netemd stop` one after
  // another): every rule sits in the sidecar's network namespace (eth1's qdiscs, the iptables
  // chains and NFQUEUE rules) and the delay daemons are processes of the sidecar, so all of it
  // goes when the sidecar stops, which the tree does right after this Step (the agent, which
  // shares the namespace, has stopped before it). Nothing of it is on the host: a crash before
  // this point leaves only labelled containers, which `swarmbox gc` removes with their namespaces.
  for (const std::string& drone : config_.drones) {
    auto it = installed_.find(drone);
    if (it == installed_.end() || it->second.empty()) continue;
    faults::FaultEventRecord record = Record(FaultPhase::kRemoved);
    record.mechanism = std::string(faults::MechanismName(*mechanism_));
    record.note = std::string(kWithNamespace);
    if (events_) events_(faults::MeshEventJson(drone, it->second, record));
    installed_.erase(it);
  }
  return v;
}

std::vector<std::string> FaultInjector::TakeResumed() {
  std::vector<std::string> out;
  out.swap(resumed_);
  return out;
}

}  // namespace swarmbox::runner
