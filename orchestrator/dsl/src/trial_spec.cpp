#include "swarmbox/dsl/trial_spec.hpp"

#include <charconv>
#include <utility>

namespace swarmbox::dsl {

std::string_view MiddlewareName(Middleware middleware) {
  return middleware == Middleware::kFastDds ? "fastdds" : "cyclonedds";
}

std::string_view FaultKindName(FaultKind kind) {
  switch (kind) {
    case FaultKind::kKill: return "kill";
    case FaultKind::kStop: return "stop";
    case FaultKind::kPause: return "pause";
    case FaultKind::kRestart: return "restart";
    case FaultKind::kPartition: return "partition";
    case FaultKind::kGpsDropout: return "gps_dropout";
    case FaultKind::kWindGust: return "wind_gust";
    case FaultKind::kNetem: return "netem";
  }
  return "?";
}

FaultSpec FaultSpec::Kill(Duration at, std::string target) {
  FaultSpec f;
  f.at = at;
  f.kind = FaultKind::kKill;
  f.targets = {std::move(target)};
  return f;
}

TrialSpec TrialSpec::Named(std::string name) {
  TrialSpec t;
  t.name = std::move(name);
  return t;
}
TrialSpec& TrialSpec::Seed(std::uint64_t value) {
  seed = value;
  return *this;
}
TrialSpec& TrialSpec::Using(Middleware value) {
  middleware = value;
  return *this;
}
TrialSpec& TrialSpec::World(std::string value) {
  world = std::move(value);
  return *this;
}
TrialSpec& TrialSpec::Rtf(double value) {
  rtf = value;
  return *this;
}
TrialSpec& TrialSpec::Drone(std::string drone_name, std::string airframe,
                            std::array<double, 3> pose, std::string payload) {
  drones.push_back({std::move(drone_name), std::move(airframe), pose, std::move(payload), {}});
  return *this;
}
TrialSpec& TrialSpec::Mesh(MeshSpec value) {
  mesh = std::move(value);
  return *this;
}
TrialSpec& TrialSpec::Fault(FaultSpec fault) {
  faults.push_back(std::move(fault));
  return *this;
}
TrialSpec& TrialSpec::EndOn(std::string pattern, Outcome outcome, std::string reason,
                            std::string from) {
  end.push_back({std::move(pattern), outcome, std::move(reason), std::move(from)});
  return *this;
}
TrialSpec& TrialSpec::Timeout(Duration sim, Outcome outcome, Duration wall) {
  timeout = {sim, wall, outcome};
  return *this;
}

const DroneSpec* TrialSpec::FindDrone(std::string_view drone_name) const {
  for (const DroneSpec& d : drones) {
    if (d.name == drone_name) return &d;
  }
  return nullptr;
}

namespace {

using yaml::Node;

std::string Number(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

Node Str(std::string_view s) { return Node::Scalar(std::string(s), {}, /*quoted=*/true); }
Node Plain(std::string s) { return Node::Scalar(std::move(s)); }

Node StringList(const std::vector<std::string>& items) {
  Node seq = Node::Sequence();
  for (const auto& s : items) seq.Append(Str(s));
  return seq;
}

Node MeshNode(const MeshSpec& m) {
  Node n = Node::Mapping();
  if (m.delay_ms > 0) n.Set("delay_ms", Plain(Number(m.delay_ms)));
  if (m.jitter_ms > 0) n.Set("jitter_ms", Plain(Number(m.jitter_ms)));
  if (!m.distribution.empty()) n.Set("distribution", Str(m.distribution));
  if (m.loss > 0) n.Set("loss", Plain(Number(m.loss)));
  if (m.duplicate > 0) n.Set("duplicate", Plain(Number(m.duplicate)));
  if (m.corrupt > 0) n.Set("corrupt", Plain(Number(m.corrupt)));
  if (m.rate_kbit > 0) n.Set("rate_kbit", Plain(Number(m.rate_kbit)));
  return n;
}

}  // namespace

yaml::Node ToDocument(const TrialSpec& spec) {
  Node doc = Node::Mapping();
  doc.Set("name", Str(spec.name));
  doc.Set("seed", Plain(std::to_string(spec.seed)));
  doc.Set("middleware", Str(MiddlewareName(spec.middleware)));
  doc.Set("world", Str(spec.world));
  Node physics = Node::Mapping();
  physics.Set("rtf", Plain(Number(spec.rtf)));
  doc.Set("physics", std::move(physics));
  Node drones = Node::Sequence();
  for (const DroneSpec& d : spec.drones) {
    Node dn = Node::Mapping();
    dn.Set("name", Str(d.name));
    dn.Set("airframe", Str(d.airframe));
    Node pose = Node::Sequence();
    for (double v : d.pose) pose.Append(Plain(Number(v)));
    dn.Set("pose", std::move(pose));
    if (!d.payload.empty()) dn.Set("payload", Str(d.payload));
    drones.Append(std::move(dn));
  }
  doc.Set("drones", std::move(drones));
  if (spec.mesh.impaired()) {
    Node network = Node::Mapping();
    network.Set("mesh", MeshNode(spec.mesh));
    doc.Set("network", std::move(network));
  }
  if (!spec.faults.empty()) {
    Node faults = Node::Sequence();
    for (const FaultSpec& f : spec.faults) {
      Node fn = Node::Mapping();
      fn.Set("at", Str(f.at.ToString()));
      const std::string kind(FaultKindName(f.kind));
      switch (f.kind) {
        case FaultKind::kPartition: {
          Node groups = Node::Sequence();
          for (const auto& g : f.groups) groups.Append(StringList(g));
          fn.Set(kind, std::move(groups));
          break;
        }
        case FaultKind::kWindGust: {
          Node w = Node::Mapping();
          w.Set("speed_mps", Plain(Number(f.wind_speed_mps)));
          w.Set("direction_deg", Plain(Number(f.wind_direction_deg)));
          fn.Set(kind, std::move(w));
          break;
        }
        case FaultKind::kNetem:
          fn.Set(kind, MeshNode(f.netem));
          if (!f.targets.empty()) fn.Set("on", StringList(f.targets));
          break;
        default:
          fn.Set(kind, Str(f.targets.empty() ? std::string() : f.targets.front()));
      }
      if (!f.duration.zero()) fn.Set("for", Str(f.duration.ToString()));
      faults.Append(std::move(fn));
    }
    doc.Set("faults", std::move(faults));
  }
  if (!spec.end.empty()) {
    Node end = Node::Sequence();
    for (const EndSpec& e : spec.end) {
      Node en = Node::Mapping();
      en.Set("on", Str(e.on));
      en.Set("outcome", Str(OutcomeName(e.outcome)));
      if (!e.reason.empty()) en.Set("reason", Str(e.reason));
      if (!e.from.empty()) en.Set("from", Str(e.from));
      end.Append(std::move(en));
    }
    doc.Set("end", std::move(end));
  }
  Node timeout = Node::Mapping();
  timeout.Set("sim", Str(spec.timeout.sim.ToString()));
  if (!spec.timeout.wall.zero()) timeout.Set("wall", Str(spec.timeout.wall.ToString()));
  timeout.Set("outcome", Str(OutcomeName(spec.timeout.outcome)));
  doc.Set("timeout", std::move(timeout));
  return doc;
}

}  // namespace swarmbox::dsl
