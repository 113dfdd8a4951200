#include "radio_plan.hpp"

#include <algorithm>
#include <cmath>

#include "world_commands.hpp"

namespace swarmbox::physics {
namespace {

Error Bad(const yaml::Node& node, const std::string& message) {
  return Error(ErrorCode::kInvalidArgument, message, node.Where());
}

Result<PlanImpairment> ParseImpairment(const yaml::Node& node, const std::string& what) {
  if (!node.is_mapping()) return Bad(node, "expected a mapping for " + what);
  Result<PlanImpairment> read = channel::ReadImpairmentKeys(node, what);
  if (!read) return read.error();
  const PlanImpairment& m = *read;
  auto non_negative = [](double v) { return std::isfinite(v) && v >= 0; };
  if (!non_negative(m.delay_ms) || !non_negative(m.jitter_ms) || !non_negative(m.rate_kbit)) {
    return Bad(node, what + ": delay_ms, jitter_ms and rate_kbit must be >= 0");
  }
  if (!(m.loss >= 0 && m.loss <= 1) || !(m.duplicate >= 0 && m.duplicate <= 1)) {
    return Bad(node, what + ": loss and duplicate are probabilities in [0, 1]");
  }
  static const char* const kDistributions[] = {"normal", "uniform", "pareto", "paretonormal"};
  if (std::find(std::begin(kDistributions), std::end(kDistributions), m.distribution) == std::end(kDistributions)) {
    return Bad(node, what + ": distribution '" + m.distribution + "' is not one of normal, uniform, pareto, paretonormal");
  }
  return m;
}

std::int64_t ToNs(double s) { return static_cast<std::int64_t>(std::llround(s * 1e9)); }

// The keys of the entry's kind into *r (read by its Finish), the drone_out mode into *mode.
Status ReadKindKeys(const yaml::Node& node, const std::string& kind, yaml::MapReader& r, PlanEntry* e,
                    std::string* mode) {
  if (kind == "drone_out") {
    e->kind = PlanEntry::Kind::kDroneOut;
    r.Required("mode", mode).Required("targets", &e->targets);
  } else if (kind == "world_command") {
    e->kind = PlanEntry::Kind::kWorldCommand;
    r.Optional("target", &e->target).Required("command", &e->command).Optional("args", &e->args);
  } else if (kind == "radio") {
    e->kind = PlanEntry::Kind::kRadio;
    r.Required("targets", &e->targets);
    if (const yaml::Node* imp = r.Child("impairment", /*required=*/true)) {
      auto m = ParseImpairment(*imp, "impairment");
      if (!m) return m.error();
      e->impairment = *m;
    }
  } else if (kind == "partition") {
    e->kind = PlanEntry::Kind::kPartition;
    r.Required("groups", &e->groups).Optional("oneway", &e->oneway);
  } else {
    return Bad(node, "unknown kind '" + kind + "' (drone_out, world_command, radio, partition)");
  }
  return Ok{};
}

// A drone_out's mode: a kill stays out, the others come back after duration_s.
Status SetDroneOutMode(const yaml::Node& node, const std::string& mode, PlanEntry* e) {
  if (mode == "kill") {
    e->mode = PlanEntry::Mode::kKill;
    if (e->duration_ns != 0) return Bad(node, "a kill stays out: duration_s must be 0");
  } else if (mode == "stop" || mode == "pause" || mode == "restart") {
    e->mode = mode == "stop" ? PlanEntry::Mode::kStop : mode == "pause" ? PlanEntry::Mode::kPause : PlanEntry::Mode::kRestart;
    if (e->duration_ns <= 0) return Bad(node, "mode " + mode + " needs duration_s > 0 (the drone comes back after it)");
  } else {
    return Bad(node, "unknown mode '" + mode + "' (kill, stop, pause, restart)");
  }
  return Ok{};
}

// Who an entry acts on: targets for drone_out and radio, two or more non-empty groups for a partition.
Status CheckParties(const yaml::Node& node, const PlanEntry& e) {
  if ((e.kind == PlanEntry::Kind::kDroneOut || e.kind == PlanEntry::Kind::kRadio) && e.targets.empty()) {
    return Bad(node, "targets must name at least one drone");
  }
  if (e.kind == PlanEntry::Kind::kPartition) {
    if (e.groups.size() < 2) return Bad(node, "a partition needs at least two groups");
    for (const auto& g : e.groups) {
      if (g.empty()) return Bad(node, "a partition group is empty");
    }
  }
  return Ok{};
}

Result<PlanEntry> ParseEntry(const yaml::Node& node) {
  if (!node.is_mapping()) return Bad(node, "expected a mapping for a schedule entry");
  PlanEntry e;
  e.where = node.Where();
  double at_s = 0, duration_s = 0;
  std::string kind, mode;
  yaml::MapReader r(node, "schedule entry");
  r.Required("at_s", &at_s).Required("name", &e.name).Required("kind", &kind).Optional("duration_s", &duration_s);
  if (!r.ok()) return r.Finish().error();
  if (!std::isfinite(at_s) || at_s < 0) return Bad(node, "at_s must be a simulated time >= 0");
  if (!std::isfinite(duration_s) || duration_s < 0) return Bad(node, "duration_s must be >= 0");
  e.at_ns = ToNs(at_s);
  e.duration_ns = ToNs(duration_s);
  if (Status s = ReadKindKeys(node, kind, r, &e, &mode); !s) return s.error();
  if (auto s = r.Finish(); !s) return s.error();
  if (e.kind == PlanEntry::Kind::kDroneOut) {
    if (Status s = SetDroneOutMode(node, mode, &e); !s) return s.error();
  }
  if (Status s = CheckParties(node, e); !s) return s.error();
  return e;
}

}  // namespace

const char* ModeName(PlanEntry::Mode mode) {
  switch (mode) {
    case PlanEntry::Mode::kKill: return "kill";
    case PlanEntry::Mode::kStop: return "stop";
    case PlanEntry::Mode::kPause: return "pause";
    case PlanEntry::Mode::kRestart: return "restart";
  }
  return "?";
}

const char* KindName(PlanEntry::Kind kind) {
  switch (kind) {
    case PlanEntry::Kind::kDroneOut: return "drone_out";
    case PlanEntry::Kind::kWorldCommand: return "world_command";
    case PlanEntry::Kind::kRadio: return "radio";
    case PlanEntry::Kind::kPartition: return "partition";
  }
  return "?";
}

Result<RadioPlan> ParseRadioPlan(const yaml::Node& root) {
  if (!root.is_mapping()) return Bad(root, "expected a radio plan mapping {seed, mesh, schedule}");
  RadioPlan plan;
  yaml::MapReader r(root, "radio plan");
  r.Optional("seed", &plan.seed);
  const yaml::Node* mesh = r.Child("mesh");
  const yaml::Node* schedule = r.Child("schedule");
  if (auto s = r.Finish(); !s) return s.error();
  if (mesh != nullptr && !yaml::IsNullScalar(*mesh)) {
    auto m = ParseImpairment(*mesh, "mesh");
    if (!m) return m.error();
    plan.mesh = *m;
  }
  if (schedule != nullptr && !yaml::IsNullScalar(*schedule)) {
    if (!schedule->is_sequence()) return Bad(*schedule, "schedule: expected a list of entries");
    for (const yaml::Node& item : schedule->items()) {
      auto e = ParseEntry(item);
      if (!e) return e.error();
      plan.schedule.push_back(std::move(*e));
    }
  }
  std::stable_sort(plan.schedule.begin(), plan.schedule.end(),
                   [](const PlanEntry& a, const PlanEntry& b) { return a.at_ns < b.at_ns; });
  return plan;
}

Result<RadioPlan> LoadRadioPlan(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseRadioPlan(*doc);
}

Status CheckRadioPlan(const RadioPlan& plan, const std::vector<std::string>& drones) {
  auto known = [&](const std::string& name) { return std::find(drones.begin(), drones.end(), name) != drones.end(); };
  for (const PlanEntry& e : plan.schedule) {
    auto unknown = [&](const std::string& name) {
      return Error(ErrorCode::kInvalidArgument, "entry '" + e.name + "': unknown drone '" + name + "'", e.where);
    };
    for (const std::string& t : e.targets) {
      const bool leader_ok = e.kind == PlanEntry::Kind::kDroneOut && t == kRaftLeaderTarget;
      if (!leader_ok && !known(t)) return unknown(t);
    }
    for (const auto& g : e.groups) {
      for (const std::string& t : g) {
        if (!known(t)) return unknown(t);
      }
    }
    if (e.kind == PlanEntry::Kind::kWorldCommand) {
      if (!e.target.empty() && !known(e.target)) return unknown(e.target);
      if (Status s = CheckWorldCommand(e.command, !e.target.empty(), e.args); !s) {
        return Error(ErrorCode::kInvalidArgument, "entry '" + e.name + "': " + e.command + ": " + s.error().message(), e.where);
      }
    }
  }
  return Ok{};
}

}  // namespace swarmbox::physics
