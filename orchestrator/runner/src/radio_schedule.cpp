#include "swarmbox/runner/radio_schedule.hpp"

#include <algorithm>
#include <charconv>
#include <random>
#include <set>
#include <variant>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/channel_support.hpp"
#include "swarmbox/faults/leader_tracker.hpp"
#include "swarmbox/faults/physics_plan.hpp"
#include "swarmbox/faults/target_resolver.hpp"

namespace swarmbox::runner {

namespace {

using yaml::Node;

constexpr std::string_view kRaftLeader = "raft_leader";
constexpr double kRestartOutS = 0.004;  // one lockstep step [simulated s]

double Seconds(std::int64_t ms) { return static_cast<double>(ms) / 1000.0; }

// Names, globs and `all` resolved against the drones; `random` drawn from rng; raft_leader kept.
Result<std::vector<std::string>> Targets(const faults::FaultTarget& target,
                                         const std::vector<std::string>& drones, std::mt19937_64& rng) {
  if (target.kind == faults::FaultTarget::Kind::kRaftLeader)
    return std::vector<std::string>{std::string(kRaftLeader)};
  const faults::LeaderTracker no_leader;  // never asked: raft_leader is handled above
  return faults::ResolveTarget(target, drones, no_leader, rng);
}

std::string Number(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}
Node Num(double v) { return Node::Scalar(Number(v)); }
Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }
Node StrList(const std::vector<std::string>& items) {
  Node list = Node::Sequence();
  for (const std::string& s : items) list.Append(Str(s));
  return list;
}

Node Impairment(const faults::NetemSpec& s) {
  Node n = Node::Mapping();
  n.Set("delay_ms", Num(s.delay_ms));
  n.Set("jitter_ms", Num(s.jitter_ms));
  n.Set("distribution", Str(faults::DistributionName(s.distribution)));
  n.Set("loss", Num(s.loss));
  n.Set("rate_kbit", Num(s.rate_kbit.value_or(0.0)));
  n.Set("duplicate", Num(s.duplicate));
  return n;
}

std::string_view KindName(ScheduleEntry::Kind kind) {
  switch (kind) {
    case ScheduleEntry::Kind::kDroneOut:
      return "drone_out";
    case ScheduleEntry::Kind::kRadio:
      return "radio";
    case ScheduleEntry::Kind::kPartition:
      return "partition";
    case ScheduleEntry::Kind::kWorldCommand:
      return "world_command";
  }
  return "drone_out";
}

}  // namespace

bool InRadioSchedule(const faults::Fault& fault) {
  return fault.start.clock == faults::FaultStart::Clock::kSim;
}

namespace {

// What one fault's entries are planned from: the trial's drones and the generator `random` draws from.
struct ScheduleContext {
  const std::vector<std::string>& drones;
  std::mt19937_64& rng;
  RadioSchedule& plan;
};

Error InFault(const faults::Fault& f, const Error& e) {
  return e.Context("fault " + f.id + " (" + f.mark.ToString() + ")");
}

// The fault indexes in the order they fire (ties: schedule order), so `random` draws as the
// injector would.
std::vector<std::size_t> FiringOrder(const dsl::TrialSpec& spec) {
  std::vector<std::size_t> order;
  for (std::size_t i = 0; i < spec.faults.size(); ++i) {
    if (InRadioSchedule(spec.faults[i])) order.push_back(i);
  }
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) {
    return spec.faults[a].start.at_ms < spec.faults[b].start.at_ms;
  });
  return order;
}

Status ScheduleDroneOut(ScheduleContext& ctx, const faults::Fault& f, const faults::ProcessFault& process,
                        ScheduleEntry e) {
  auto targets = Targets(process.target, ctx.drones, ctx.rng);
  if (!targets) return InFault(f, targets.error());
  e.kind = ScheduleEntry::Kind::kDroneOut;
  e.mode = process.action;
  e.targets = std::move(*targets);
  // The physics server's modes (physics_server/app/radio_plan.hpp): a kill stays out (0); a
  // kill that ends is out for its duration and back as a new process, its `restart`; stop and
  // pause need an end (none: the rest of the trial); a restart is out for one lockstep step.
  if (process.action == faults::ProcessAction::kKill && f.duration_ms) {
    e.mode = faults::ProcessAction::kRestart;
  } else if (process.action == faults::ProcessAction::kRestart) {
    e.duration_s = kRestartOutS;
  } else if (process.action != faults::ProcessAction::kKill && !f.duration_ms) {
    e.duration_s = faults::kUntilEndS;
  }
  ctx.plan.schedule.push_back(std::move(e));
  return Ok{};
}

Status ScheduleRadio(ScheduleContext& ctx, const faults::Fault& f, const faults::RadioFault& radio, ScheduleEntry e) {
  auto targets = Targets(radio.target, ctx.drones, ctx.rng);
  if (!targets) return InFault(f, targets.error());
  e.kind = ScheduleEntry::Kind::kRadio;
  e.targets = std::move(*targets);
  if (!radio.rules.empty()) e.impairment = radio.rules.front().spec;
  ctx.plan.schedule.push_back(std::move(e));
  return Ok{};
}

// The partition's groups, and the drones no group lists as one more group.
void SchedulePartition(ScheduleContext& ctx, const faults::PartitionFault& partition, ScheduleEntry e) {
  e.kind = ScheduleEntry::Kind::kPartition;
  e.groups = partition.groups;
  e.oneway = partition.oneway;
  std::set<std::string> listed;
  for (const auto& g : e.groups) listed.insert(g.begin(), g.end());
  std::vector<std::string> rest;
  for (const std::string& d : ctx.drones) {
    if (listed.count(d) == 0) rest.push_back(d);
  }
  if (!rest.empty()) e.groups.push_back(std::move(rest));
  ctx.plan.schedule.push_back(std::move(e));
}

// The world commands of a physics fault, its undo at its end.
Status SchedulePhysicsFault(ScheduleContext& ctx, const faults::Fault& f, const ScheduleEntry& e) {
  std::vector<std::string> targets;
  if (const faults::FaultTarget* target = f.target()) {
    auto resolved = Targets(*target, ctx.drones, ctx.rng);
    if (!resolved) return InFault(f, resolved.error());
    targets = std::move(*resolved);
  }
  const faults::PhysicsPlan calls = faults::PlanPhysicsFault(f, targets);
  auto add = [&](const std::vector<faults::WorldCommandCall>& list, double at_s) {
    for (const faults::WorldCommandCall& call : list) {
      ScheduleEntry w;
      w.kind = ScheduleEntry::Kind::kWorldCommand;
      w.at_s = at_s;
      w.name = f.id;
      w.target = call.target;
      w.command = call.command;
      w.args = call.args;
      ctx.plan.schedule.push_back(std::move(w));
    }
  };
  add(calls.apply, e.at_s);
  add(calls.undo, e.at_s + e.duration_s);  // an imu_bias with a duration: its negated jump
  return Ok{};
}

Status ScheduleFault(ScheduleContext& ctx, const faults::Fault& f) {
  ScheduleEntry e;
  e.at_s = Seconds(f.start.at_ms);
  e.name = f.id;
  e.duration_s = f.duration_ms ? Seconds(*f.duration_ms) : 0.0;
  if (const auto* process = std::get_if<faults::ProcessFault>(&f.action)) {
    return ScheduleDroneOut(ctx, f, *process, std::move(e));
  }
  if (const auto* radio = std::get_if<faults::RadioFault>(&f.action)) return ScheduleRadio(ctx, f, *radio, std::move(e));
  if (const auto* partition = std::get_if<faults::PartitionFault>(&f.action)) {
    SchedulePartition(ctx, *partition, std::move(e));
    return Ok{};
  }
  if (faults::IsPhysicsFault(f)) return SchedulePhysicsFault(ctx, f, e);
  return Ok{};
}

// One entry of the schedule: when, what, and the fields of its kind.
Node ScheduleEntryNode(const ScheduleEntry& e) {
  Node n = Node::Mapping();
  n.Set("at_s", Num(e.at_s));
  n.Set("name", Str(e.name));
  n.Set("kind", Str(KindName(e.kind)));
  switch (e.kind) {
    case ScheduleEntry::Kind::kDroneOut:
      n.Set("mode", Str(faults::ProcessActionName(e.mode)));
      n.Set("targets", StrList(e.targets));
      n.Set("duration_s", Num(e.duration_s));
      break;
    case ScheduleEntry::Kind::kRadio:
      n.Set("targets", StrList(e.targets));
      n.Set("impairment", Impairment(e.impairment));
      n.Set("duration_s", Num(e.duration_s));
      break;
    case ScheduleEntry::Kind::kPartition: {
      Node groups = Node::Sequence();
      for (const auto& g : e.groups) groups.Append(StrList(g));
      n.Set("groups", std::move(groups));
      n.Set("oneway", Node::Scalar(e.oneway ? "true" : "false"));
      n.Set("duration_s", Num(e.duration_s));
      break;
    }
    case ScheduleEntry::Kind::kWorldCommand: {
      n.Set("target", Str(e.target));
      n.Set("command", Str(e.command));
      Node args = Node::Sequence();
      for (double a : e.args) args.Append(Num(a));
      n.Set("args", std::move(args));
      break;
    }
  }
  return n;
}

}  // namespace

Result<RadioSchedule> PlanRadioSchedule(const dsl::TrialSpec& spec) {
  if (spec.radio.model != dsl::RadioModel::kChannel) {
    return Error(ErrorCode::kInvalidArgument,
                 "trial " + spec.name +
                     " runs radio.model netem: its faults are carried out by the runner, "
                     "it has no radio plan");
  }
  SWARMBOX_TRY(faults::CheckChannelSupports(spec.mesh.rules, "network.mesh"));
  SWARMBOX_TRY(faults::CheckChannelFaults(spec.faults));
  std::vector<std::string> drones;
  for (const dsl::DroneSpec& d : spec.drones) drones.push_back(d.name);
  RadioSchedule plan;
  plan.seed = spec.seed;
  if (!spec.mesh.empty()) plan.mesh = spec.mesh.rules.front().spec;
  std::mt19937_64 rng(spec.seed);
  ScheduleContext ctx{drones, rng, plan};
  for (std::size_t i : FiringOrder(spec)) SWARMBOX_TRY(ScheduleFault(ctx, spec.faults[i]));
  // The undo entries land later than their fault's: the whole schedule by time (ties: as added).
  std::stable_sort(plan.schedule.begin(), plan.schedule.end(),
                   [](const ScheduleEntry& a, const ScheduleEntry& b) { return a.at_s < b.at_s; });
  return plan;
}

std::string RadioScheduleJson(const RadioSchedule& plan) {
  Node root = Node::Mapping();
  root.Set("seed", Node::Scalar(std::to_string(plan.seed)));
  if (plan.mesh) root.Set("mesh", Impairment(*plan.mesh));
  Node schedule = Node::Sequence();
  for (const ScheduleEntry& e : plan.schedule) schedule.Append(ScheduleEntryNode(e));
  root.Set("schedule", std::move(schedule));
  return yaml::EmitJson(root);
}

}  // namespace swarmbox::runner
