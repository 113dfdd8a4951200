#include "swarmbox/faults/fault_spec.hpp"

#include <fnmatch.h>

#include <algorithm>
#include <set>
#include <string>

#include "swarmbox/faults/detail/number_format.hpp"
#include "swarmbox/faults/duration_ms.hpp"

namespace swarmbox::faults {
namespace {

Error Invalid(std::string message, std::string where) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), std::move(where));
}

bool IsGlob(std::string_view text) { return text.find_first_of("*?[") != std::string_view::npos; }

bool IsName(std::string_view text) {
  if (text.empty()) return false;
  return std::all_of(text.begin(), text.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-' || c == '.';
  });
}

constexpr std::string_view kKinds[] = {"radio",       "partition",   "kill",     "stop",     "pause", "restart",
                                       "gps_dropout", "gps_degrade", "imu_bias", "wind_gust"};

std::string KindList() {
  std::string out;
  for (auto k : kKinds) out += (out.empty() ? "" : ", ") + std::string(k);
  return out;
}

// `{target: TARGET, ...fields}` (target required): read_fields(reader) declares the other keys;
// returns the target, parsed after the mapping checked out.
template <typename ReadFields>
Result<FaultTarget> ReadTargetedMapping(const yaml::Node& value, const char* kind, ReadFields&& read_fields) {
  yaml::MapReader r(value, kind);
  const yaml::Node* t = r.Child("target", /*required=*/true);
  read_fields(r);
  SWARMBOX_TRY(r.Finish());
  return ParseTarget(*t);
}

// kill/stop/pause/restart/gps_dropout: `kind: TARGET` or `kind: {target: TARGET, ...options}`.
// Returns the options mapping (nullptr when the value was a bare target).
Result<FaultTarget> ReadShortTarget(const yaml::Node& value, std::string_view kind,
                                    const yaml::Node** options) {
  *options = nullptr;
  if (value.is_mapping()) {
    const yaml::Node* t = value.Find("target");
    if (t == nullptr) {
      return Invalid("missing required key 'target' in " + std::string(kind), value.Where());
    }
    *options = &value;
    return ParseTarget(*t);
  }
  return ParseTarget(value);
}

Result<ProcessFault> ParseProcess(const yaml::Node& value, ProcessAction action) {
  ProcessFault out;
  out.action = action;
  const yaml::Node* options = nullptr;
  auto target = ReadShortTarget(value, ProcessActionName(action), &options);
  if (!target) return target.error();
  out.target = std::move(*target);
  if (options != nullptr) {
    yaml::MapReader r(*options, std::string(ProcessActionName(action)));
    r.Child("target");
    if (action == ProcessAction::kKill) r.Optional("signal", &out.signal);
    std::int64_t timeout_ms = -1;
    if (action == ProcessAction::kStop || action == ProcessAction::kRestart) {
      if (const yaml::Node* t = r.Child("timeout")) {
        if (auto s = DecodeDurationMs(*t, &timeout_ms); !s) r.Fail(s.error());
      }
    }
    SWARMBOX_TRY(r.Finish());
    if (timeout_ms >= 0) {
      if (timeout_ms % 1000 != 0) {
        return Invalid("'timeout' is whole seconds (Docker's stop timeout)", options->Find("timeout")->Where());
      }
      out.timeout_s = static_cast<int>(timeout_ms / 1000);
    }
    if (action == ProcessAction::kKill) {
      const bool known_form = out.signal.rfind("SIG", 0) == 0 && out.signal.size() > 3 &&
                              IsName(out.signal);
      if (!known_form) {
        return Invalid("'signal' is a signal name such as SIGKILL or SIGTERM, got '" + out.signal + "'",
                       options->Find("signal")->Where());
      }
    }
  }
  return out;
}

Result<PartitionFault> ParsePartition(const yaml::Node& value) {
  PartitionFault out;
  yaml::MapReader r(value, "partition");
  r.Required("groups", &out.groups).Optional("oneway", &out.oneway);
  SWARMBOX_TRY(r.Finish());
  const yaml::Node& groups = *value.Find("groups");
  if (out.groups.empty()) return Invalid("'groups' needs at least one group", groups.Where());
  for (std::size_t i = 0; i < out.groups.size(); ++i) {
    if (out.groups[i].empty()) {
      return Invalid("partition group " + std::to_string(i) + " is empty", groups.items()[i].Where());
    }
  }
  return out;
}

Result<FaultAction> ParseRadioAction(std::string_view /*kind*/, const yaml::Node& value) {
  RadioFault out;
  if (!value.is_mapping()) {
    return Invalid("expected radio to be a mapping of netem keys (delay_ms, loss, ...)", value.Where());
  }
  if (const yaml::Node* t = value.Find("target")) {
    auto target = ParseTarget(*t);
    if (!target) return target.error();
    out.target = std::move(*target);
  }
  auto rules = ParseRadioRules(value, "radio", {"target"});
  if (!rules) return rules.error();
  out.rules = std::move(*rules);
  return FaultAction(std::move(out));
}

Result<FaultAction> ParsePartitionAction(std::string_view /*kind*/, const yaml::Node& value) {
  auto p = ParsePartition(value);
  if (!p) return p.error();
  return FaultAction(std::move(*p));
}

// kill, stop, pause, restart.
Result<FaultAction> ParseProcessAction(std::string_view kind, const yaml::Node& value) {
  ProcessAction action = kind == "kill"   ? ProcessAction::kKill
                         : kind == "stop" ? ProcessAction::kStop
                         : kind == "pause" ? ProcessAction::kPause
                                           : ProcessAction::kRestart;
  auto p = ParseProcess(value, action);
  if (!p) return p.error();
  return FaultAction(std::move(*p));
}

Result<FaultAction> ParseGpsDropout(std::string_view kind, const yaml::Node& value) {
  const yaml::Node* options = nullptr;
  auto target = ReadShortTarget(value, kind, &options);
  if (!target) return target.error();
  if (options != nullptr) {
    yaml::MapReader r(*options, "gps_dropout");
    r.Child("target");
    SWARMBOX_TRY(r.Finish());
  }
  return FaultAction(GpsDropout{std::move(*target)});
}

Result<FaultAction> ParseGpsDegrade(std::string_view /*kind*/, const yaml::Node& value) {
  GpsDegrade out;
  if (!value.is_mapping()) {
    return Invalid("expected gps_degrade to be a mapping such as {target: scout_1, h_acc_m: 5, v_acc_m: 8}",
                   value.Where());
  }
  auto target = ReadTargetedMapping(value, "gps_degrade", [&out](yaml::MapReader& r) {
    r.Required("h_acc_m", &out.h_acc_m).Required("v_acc_m", &out.v_acc_m);
  });
  if (!target) return target.error();
  out.target = std::move(*target);
  for (const char* key : {"h_acc_m", "v_acc_m"}) {
    const double v = std::string_view(key) == "h_acc_m" ? out.h_acc_m : out.v_acc_m;
    if (!(v > 0.0 && v <= kMaxGpsAccuracyM)) {
      return Invalid("'" + std::string(key) + "' is the degraded 1-sigma accuracy in metres, in (0, " +
                         detail::FormatDecimal(kMaxGpsAccuracyM) + "]; got " + detail::FormatDecimal(v) +
                         " (for no fix at all use gps_dropout)",
                     value.Find(key)->Where());
    }
  }
  return FaultAction(std::move(out));
}

Result<FaultAction> ParseImuBias(std::string_view /*kind*/, const yaml::Node& value) {
  ImuBias out;
  auto target = ReadTargetedMapping(value, "imu_bias", [&out](yaml::MapReader& r) {
    r.Optional("accel_m_s2", &out.accel_m_s2).Optional("gyro_rad_s", &out.gyro_rad_s);
  });
  if (!target) return target.error();
  out.target = std::move(*target);
  if (out.accel_m_s2 == std::array<double, 3>{} && out.gyro_rad_s == std::array<double, 3>{}) {
    return Invalid("imu_bias changes nothing: give accel_m_s2 and/or gyro_rad_s", value.Where());
  }
  return FaultAction(std::move(out));
}

Result<FaultAction> ParseWindGust(std::string_view /*kind*/, const yaml::Node& value) {
  WindGust out;
  yaml::MapReader r(value, "wind_gust");
  r.Required("speed_m_s", &out.speed_m_s).Optional("direction_deg", &out.direction_deg)
      .Optional("vertical_m_s", &out.vertical_m_s);
  SWARMBOX_TRY(r.Finish());
  if (!(out.speed_m_s >= 0.0 && out.speed_m_s <= 100.0)) {
    return Invalid("'speed_m_s' must be in [0, 100] m/s", value.Find("speed_m_s")->Where());
  }
  if (!(out.direction_deg >= 0.0 && out.direction_deg < 360.0)) {
    return Invalid("'direction_deg' must be in [0, 360)", value.Find("direction_deg")->Where());
  }
  return FaultAction(out);
}

// A fault kind's action parser; any other kind (the caller has checked it) is wind_gust.
Result<FaultAction> ParseAction(std::string_view kind, const yaml::Node& value) {
  using Parser = Result<FaultAction> (*)(std::string_view, const yaml::Node&);
  static constexpr std::pair<std::string_view, Parser> kParsers[] = {
      {"radio", &ParseRadioAction},     {"partition", &ParsePartitionAction}, {"kill", &ParseProcessAction},
      {"stop", &ParseProcessAction},    {"pause", &ParseProcessAction},       {"restart", &ParseProcessAction},
      {"gps_dropout", &ParseGpsDropout}, {"gps_degrade", &ParseGpsDegrade},   {"imu_bias", &ParseImuBias},
  };
  for (const auto& [name, parse] : kParsers) {
    if (kind == name) return parse(kind, value);
  }
  return ParseWindGust(kind, value);
}

// The keys of one fault mapping: its start, duration and the one kind key with its value.
struct FaultKeys {
  const yaml::Node* at = nullptr;
  const yaml::Node* at_wall = nullptr;
  const yaml::Node* on = nullptr;
  const yaml::Node* duration = nullptr;
  const yaml::Node* kind_node = nullptr;
  std::string kind;
};

// Reads `name` into fault->id and finds the other keys; an unknown key, two kinds or none is an error.
Result<FaultKeys> ReadFaultKeys(const yaml::Node& node, Fault* fault) {
  FaultKeys keys;
  yaml::MapReader r(node, "fault");
  r.Optional("name", &fault->id);
  keys.at = r.Child("at");
  keys.at_wall = r.Child("at_wall");
  keys.on = r.Child("on");
  keys.duration = r.Child("duration");
  for (auto k : kKinds) {
    if (const yaml::Node* v = r.Child(k)) {
      if (keys.kind_node != nullptr) {
        return Invalid(
            "a fault has exactly one kind; got both '" + keys.kind + "' and '" + std::string(k) + "'",
            node.Where());
      }
      keys.kind_node = v;
      keys.kind = std::string(k);
    }
  }
  SWARMBOX_TRY(r.Finish());
  if (keys.kind_node == nullptr) return Invalid("a fault needs one kind: " + KindList(), node.Where());
  return keys;
}

// Exactly one of at (simulated time), at_wall (wall time) and on (a log event pattern).
Status ParseFaultStart(const yaml::Node& node, const FaultKeys& keys, FaultStart* start) {
  const int starts = (keys.at != nullptr) + (keys.at_wall != nullptr) + (keys.on != nullptr);
  if (starts != 1) {
    return Invalid("a fault needs exactly one start: at (simulated time), at_wall (wall time) or on "
                   "(a log event such as \"event=leader_elected\")",
                   node.Where());
  }
  if (keys.at != nullptr) {
    start->clock = FaultStart::Clock::kSim;
    return DecodeDurationMs(*keys.at, &start->at_ms);
  }
  if (keys.at_wall != nullptr) {
    start->clock = FaultStart::Clock::kWall;
    return DecodeDurationMs(*keys.at_wall, &start->at_ms);
  }
  start->clock = FaultStart::Clock::kEvent;
  SWARMBOX_TRY(yaml::Decode(*keys.on, &start->event_pattern));
  if (start->event_pattern.find('=') == std::string::npos) {
    return Invalid("'on' is a log pattern such as \"event=leader_elected\"", keys.on->Where());
  }
  return Ok{};
}

Result<Fault> ParseOne(const yaml::Node& node, std::size_t index) {
  Fault fault;
  fault.mark = node.mark();
  fault.id = "fault_" + std::to_string(index);
  if (!node.is_mapping()) {
    return Invalid("expected a fault to be a mapping such as {at: 30s, kill: raft_leader}", node.Where());
  }
  auto keys = ReadFaultKeys(node, &fault);
  if (!keys) return keys.error();
  if (!IsName(fault.id)) return Invalid("'name' must be a plain identifier", node.Find("name")->Where());
  SWARMBOX_TRY(ParseFaultStart(node, *keys, &fault.start));
  if (keys->duration != nullptr) {
    std::int64_t ms = 0;
    SWARMBOX_TRY(DecodeDurationMs(*keys->duration, &ms));
    if (ms <= 0) return Invalid("'duration' must be positive", keys->duration->Where());
    fault.duration_ms = ms;
  }
  auto action = ParseAction(keys->kind, *keys->kind_node);
  if (!action) return action.error();
  fault.action = std::move(*action);
  if (fault.duration_ms && keys->kind == "restart") {
    return Invalid("restart is instantaneous and cannot have a 'duration'", keys->duration->Where());
  }
  return fault;
}

void CollectNames(const FaultTarget& t, std::vector<std::string>* out) {
  if (t.kind == FaultTarget::Kind::kNames) out->insert(out->end(), t.names.begin(), t.names.end());
}

Status CheckTarget(const FaultTarget& t, const std::vector<std::string>& drones, const std::string& where) {
  auto known = [&](const std::string& n) { return std::find(drones.begin(), drones.end(), n) != drones.end(); };
  std::string list;
  for (const auto& d : drones) list += (list.empty() ? "" : ", ") + d;
  if (t.kind == FaultTarget::Kind::kNames) {
    for (const auto& n : t.names) {
      if (!known(n)) return Invalid("unknown drone '" + n + "' (drones: " + list + ")", where);
    }
  } else if (t.kind == FaultTarget::Kind::kPattern) {
    const bool any = std::any_of(drones.begin(), drones.end(), [&](const std::string& d) {
      return fnmatch(t.pattern.c_str(), d.c_str(), 0) == 0;
    });
    if (!any) return Invalid("pattern '" + t.pattern + "' matches no drone (drones: " + list + ")", where);
  }
  return Ok{};
}

}  // namespace

std::string FaultStart::ToString() const {
  switch (clock) {
    case Clock::kSim: return "at " + FormatDurationMs(at_ms);
    case Clock::kWall: return "at_wall " + FormatDurationMs(at_ms);
    case Clock::kEvent: return "on " + event_pattern;
  }
  return "";
}

std::string FaultTarget::ToString() const {
  switch (kind) {
    case Kind::kAll: return "all";
    case Kind::kRaftLeader: return "raft_leader";
    case Kind::kRandom: return "random";
    case Kind::kPattern: return pattern;
    case Kind::kNames: {
      if (names.size() == 1) return names[0];
      std::string out = "[";
      for (const auto& n : names) out += (out.size() > 1 ? ", " : "") + n;
      return out + "]";
    }
  }
  return "";
}

std::string_view ProcessActionName(ProcessAction action) {
  switch (action) {
    case ProcessAction::kKill: return "kill";
    case ProcessAction::kStop: return "stop";
    case ProcessAction::kPause: return "pause";
    case ProcessAction::kRestart: return "restart";
  }
  return "kill";
}

std::string_view Fault::kind() const {
  struct Visitor {
    std::string_view operator()(const RadioFault&) const { return "radio"; }
    std::string_view operator()(const PartitionFault&) const { return "partition"; }
    std::string_view operator()(const ProcessFault& p) const { return ProcessActionName(p.action); }
    std::string_view operator()(const GpsDropout&) const { return "gps_dropout"; }
    std::string_view operator()(const GpsDegrade&) const { return "gps_degrade"; }
    std::string_view operator()(const ImuBias&) const { return "imu_bias"; }
    std::string_view operator()(const WindGust&) const { return "wind_gust"; }
  };
  return std::visit(Visitor{}, action);
}

const FaultTarget* Fault::target() const {
  if (auto* r = std::get_if<RadioFault>(&action)) return &r->target;
  if (auto* p = std::get_if<ProcessFault>(&action)) return &p->target;
  if (auto* g = std::get_if<GpsDropout>(&action)) return &g->target;
  if (auto* g = std::get_if<GpsDegrade>(&action)) return &g->target;
  if (auto* i = std::get_if<ImuBias>(&action)) return &i->target;
  return nullptr;
}

Result<FaultTarget> ParseTarget(const yaml::Node& node) {
  FaultTarget t;
  if (node.is_sequence()) {
    t.kind = FaultTarget::Kind::kNames;
    if (node.items().empty()) return Invalid("a target list names at least one drone", node.Where());
    std::set<std::string> seen;
    for (const auto& item : node.items()) {
      std::string name;
      SWARMBOX_TRY(yaml::Decode(item, &name));
      if (!IsName(name)) {
        return Invalid("a target list holds drone names, got '" + name + "'", item.Where());
      }
      if (!seen.insert(name).second) return Invalid("drone '" + name + "' listed twice", item.Where());
      t.names.push_back(std::move(name));
    }
    return t;
  }
  if (!node.is_scalar() || node.scalar().empty()) {
    return Invalid("expected a target: a drone name, a list of names, a pattern such as \"scout_*\", "
                   "all, raft_leader or random",
                   node.Where());
  }
  const std::string& s = node.scalar();
  if (s == "all") {
    t.kind = FaultTarget::Kind::kAll;
  } else if (s == "raft_leader") {
    t.kind = FaultTarget::Kind::kRaftLeader;
  } else if (s == "random") {
    t.kind = FaultTarget::Kind::kRandom;
  } else if (IsGlob(s)) {
    t.kind = FaultTarget::Kind::kPattern;
    t.pattern = s;
  } else if (IsName(s)) {
    t.kind = FaultTarget::Kind::kNames;
    t.names = {s};
  } else {
    return Invalid("'" + s + "' is neither a drone name, a pattern, all, raft_leader nor random", node.Where());
  }
  return t;
}

Result<std::vector<Fault>> ParseFaults(const yaml::Node& list) {
  std::vector<Fault> out;
  if (list.is_null() || yaml::IsNullScalar(list)) return out;
  if (!list.is_sequence()) return Invalid("expected 'faults' to be a list", list.Where());
  std::set<std::string> ids;
  for (std::size_t i = 0; i < list.items().size(); ++i) {
    auto fault = ParseOne(list.items()[i], i);
    if (!fault) return fault.error();
    if (!ids.insert(fault->id).second) {
      return Invalid("two faults are named '" + fault->id + "'", list.items()[i].Where());
    }
    out.push_back(std::move(*fault));
  }
  return out;
}

Status ValidateFaults(const std::vector<Fault>& faults, const std::vector<std::string>& drones) {
  for (const Fault& f : faults) {
    const std::string where = f.mark.ToString();
    if (const FaultTarget* t = f.target()) SWARMBOX_TRY(CheckTarget(*t, drones, where));
    if (auto* radio = std::get_if<RadioFault>(&f.action)) {
      SWARMBOX_TRY(ValidateRadioPeers(radio->rules, drones));
      std::vector<std::string> targets;
      CollectNames(radio->target, &targets);
      for (const auto& rule : radio->rules) {
        for (const auto& peer : rule.to) {
          if (std::find(targets.begin(), targets.end(), peer) != targets.end()) {
            return Invalid("per-destination rule names its own target '" + peer + "'", rule.mark.ToString());
          }
        }
      }
    }
    if (auto* p = std::get_if<PartitionFault>(&f.action)) {
      std::set<std::string> seen;
      for (const auto& group : p->groups) {
        FaultTarget names{FaultTarget::Kind::kNames, group, {}};
        SWARMBOX_TRY(CheckTarget(names, drones, where));
        for (const auto& n : group) {
          if (!seen.insert(n).second) {
            return Invalid("drone '" + n + "' is in two partition groups", where);
          }
        }
      }
      const bool rest_empty = seen.size() == drones.size();
      if (p->groups.size() < 2 && rest_empty) {
        return Invalid("a partition needs at least two groups (drones in no group form one more)", where);
      }
    }
  }
  return Ok{};
}

}  // namespace swarmbox::faults
