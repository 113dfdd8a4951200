#include "swarmbox/dsl/trial_spec.hpp"

#include <charconv>
#include <cstdio>
#include <cstdlib>
#include <utility>

namespace swarmbox::dsl {

std::string_view MiddlewareName(Middleware middleware) {
  return middleware == Middleware::kFastDds ? "fastdds" : "cyclonedds";
}

std::string_view MissionKindName(MissionKind kind) {
  return kind == MissionKind::kPlan ? "plan" : "sar";
}

std::string_view RadioModelName(RadioModel model) {
  return model == RadioModel::kNetem ? "netem" : "channel";
}

std::string RadioProfileFile(const RadioLinkSpec& radio) {
  const std::string& p = radio.profile;
  const bool is_path = p.find('/') != std::string::npos ||
                       (p.size() > 5 && p.compare(p.size() - 5, 5, ".yaml") == 0);
  return is_path ? p : "radios/" + p + ".yaml";
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
TrialSpec& TrialSpec::WorldSize(double x_m, double y_m) {
  world_size_m = {x_m, y_m};
  return *this;
}
TrialSpec& TrialSpec::Rtf(double value) {
  rtf = value;
  return *this;
}
TrialSpec& TrialSpec::Drone(std::string drone_name, std::string airframe,
                            std::array<double, 3> pose, std::string payload) {
  drones.push_back({std::move(drone_name), std::move(airframe), pose, std::move(payload), {}, {}, {}});
  return *this;
}
TrialSpec& TrialSpec::Mesh(std::string_view flow_yaml) {
  auto node = yaml::Parse(flow_yaml, "TrialSpec::Mesh");
  if (node) {
    auto parsed = faults::ParseMeshBlock(*node);
    if (parsed) {
      mesh = std::move(*parsed);
      mesh_node = std::move(*node);
      return *this;
    }
    std::fprintf(stderr, "swarmbox: fatal: TrialSpec::Mesh: %s\n", parsed.error().ToString().c_str());
  } else {
    std::fprintf(stderr, "swarmbox: fatal: TrialSpec::Mesh: %s\n", node.error().ToString().c_str());
  }
  std::abort();
}
TrialSpec& TrialSpec::Fault(std::string_view flow_yaml) {
  if (faults_node.is_null()) faults_node = yaml::Node::Sequence();
  auto item = yaml::Parse(flow_yaml, "TrialSpec::Fault");
  if (item) {
    yaml::Node list = faults_node;
    list.Append(*item);
    auto parsed = faults::ParseFaults(list);
    if (parsed) {
      faults_node = std::move(list);
      faults = std::move(*parsed);
      return *this;
    }
    std::fprintf(stderr, "swarmbox: fatal: TrialSpec::Fault(\"%.*s\"): %s\n",
                 static_cast<int>(flow_yaml.size()), flow_yaml.data(), parsed.error().ToString().c_str());
  } else {
    std::fprintf(stderr, "swarmbox: fatal: TrialSpec::Fault: %s\n", item.error().ToString().c_str());
  }
  std::abort();
}
TrialSpec& TrialSpec::EndOn(std::string pattern, Outcome outcome, std::string reason,
                            std::string from) {
  end.push_back({std::move(pattern), outcome, std::move(reason), std::move(from)});
  return *this;
}
std::string MissionSpec::TuningJson() const {
  if (!tuning.is_mapping() || tuning.entries().empty()) return "";
  return yaml::EmitJson(tuning);
}

TrialSpec& TrialSpec::Mission(MissionSpec value) {
  mission = std::move(value);
  return *this;
}
TrialSpec& TrialSpec::Raft(RaftSpec value) {
  raft = value;
  return *this;
}
TrialSpec& TrialSpec::Radio(RadioLinkSpec value) {
  radio = value;
  return *this;
}

TrialSpec& TrialSpec::Record(RecordSpec value) {
  record = value;
  return *this;
}
TrialSpec& TrialSpec::Timeout(Duration sim, Outcome outcome, Duration wall) {
  timeout = {sim, wall, outcome};
  return *this;
}

TrialSpec& TrialSpec::Limits(ContainerLimits value) {
  limits = value;
  return *this;
}

TrialSpec& TrialSpec::Brain(std::string_view drone_name, BrainSpec brain) {
  for (DroneSpec& d : drones) {
    if (d.name == drone_name) {
      d.brain = std::move(brain);
      return *this;
    }
  }
  std::fprintf(stderr, "swarmbox: fatal: TrialSpec::Brain: no drone '%.*s' (add it with Drone() first)\n",
               static_cast<int>(drone_name.size()), drone_name.data());
  std::abort();
}

TrialSpec& TrialSpec::Component(UserComponentSpec component) {
  components.push_back(std::move(component));
  return *this;
}

const UserComponentSpec* TrialSpec::FindComponent(std::string_view component_name) const {
  for (const UserComponentSpec& c : components) {
    if (c.name == component_name) return &c;
  }
  return nullptr;
}

bool TrialSpec::HasExternalBrain() const {
  for (const DroneSpec& d : drones) {
    if (d.brain.external()) return true;
  }
  return false;
}

ContainerLimits TrialSpec::LimitsOf(const DroneSpec* drone) const {
  const ContainerLimits& own = drone != nullptr ? drone->limits : physics_limits;
  return {own.memory_mib > 0 ? own.memory_mib : limits.memory_mib,
          own.pids > 0 ? own.pids : limits.pids};
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

}  // namespace

namespace {

Node LimitsNode(const ContainerLimits& l) {
  Node n = Node::Mapping();
  if (l.memory_mib > 0) n.Set("memory_mib", Plain(std::to_string(l.memory_mib)));
  if (l.pids > 0) n.Set("pids", Plain(std::to_string(l.pids)));
  return n;
}

Node PhysicsNode(const TrialSpec& spec) {
  Node physics = Node::Mapping();
  physics.Set("rtf", Plain(Number(spec.rtf)));
  if (spec.physics_limits.memory_mib > 0 || spec.physics_limits.pids > 0) {
    physics.Set("limits", LimitsNode(spec.physics_limits));
  }
  return physics;
}

Node DronesNode(const TrialSpec& spec) {
  Node drones = Node::Sequence();
  for (const DroneSpec& d : spec.drones) {
    Node dn = Node::Mapping();
    dn.Set("name", Str(d.name));
    dn.Set("airframe", Str(d.airframe));
    Node pose = Node::Sequence();
    for (double v : d.pose) pose.Append(Plain(Number(v)));
    dn.Set("pose", std::move(pose));
    if (!d.payload.empty()) dn.Set("payload", Str(d.payload));
    if (d.limits.memory_mib > 0 || d.limits.pids > 0) dn.Set("limits", LimitsNode(d.limits));
    if (d.brain.kind != BrainKind::kBuiltin) dn.Set("brain", BrainToNode(d.brain));
    drones.Append(std::move(dn));
  }
  return drones;
}

Node MissionNode(const MissionSpec& m) {
  Node mission = Node::Mapping();
  mission.Set("kind", Str(MissionKindName(m.kind)));
  if (m.kind == MissionKind::kPlan) mission.Set("plan", Str(m.plan));
  mission.Set("inference_latency_ms", Plain(std::to_string(m.inference_latency_ms)));
  if (!m.TuningJson().empty()) mission.Set("tuning", m.tuning);
  return mission;
}

Node RaftNode(const RaftSpec& r) {
  Node raft = Node::Mapping();
  raft.Set("tick_ms", Plain(std::to_string(r.tick_ms)));
  raft.Set("heartbeat_ms", Plain(std::to_string(r.heartbeat_ms)));
  raft.Set("election_timeout_ms", Plain(std::to_string(r.election_timeout_ms)));
  if (r.voters != RaftSpec{}.voters) raft.Set("voters", Plain(std::to_string(r.voters)));
  return raft;
}

Node RadioNode(const RadioLinkSpec& r) {
  Node radio = Node::Mapping();
  radio.Set("model", Str(RadioModelName(r.model)));
  // The default profile is left implied (a profile written out is checked where it is written).
  if (r.profile != kDefaultRadioProfile) radio.Set("profile", Str(r.profile));
  radio.Set("ping_every_ms", Plain(std::to_string(r.ping_every_ms)));
  radio.Set("ping_peers", Plain(std::to_string(r.ping_peers)));
  return radio;
}

Node EndNode(const std::vector<EndSpec>& ends) {
  Node end = Node::Sequence();
  for (const EndSpec& e : ends) {
    Node en = Node::Mapping();
    en.Set("on", Str(e.on));
    en.Set("outcome", Str(OutcomeName(e.outcome)));
    if (!e.reason.empty()) en.Set("reason", Str(e.reason));
    if (!e.from.empty()) en.Set("from", Str(e.from));
    end.Append(std::move(en));
  }
  return end;
}

Node TimeoutNode(const TrialSpec& spec) {
  Node timeout = Node::Mapping();
  timeout.Set("sim", Str(spec.timeout.sim.ToString()));
  if (!spec.timeout.wall.zero()) timeout.Set("wall", Str(spec.timeout.wall.ToString()));
  timeout.Set("outcome", Str(OutcomeName(spec.timeout.outcome)));
  return timeout;
}

// network, faults, components and end: each only when the trial has it.
void SetOptionalSections(const TrialSpec& spec, Node* doc) {
  if (!spec.mesh_node.is_null()) {
    Node network = Node::Mapping();
    network.Set("mesh", spec.mesh_node);
    doc->Set("network", std::move(network));
  }
  if (!spec.faults_node.is_null()) doc->Set("faults", spec.faults_node);
  if (!spec.components.empty()) {
    Node components = Node::Sequence();
    for (const UserComponentSpec& c : spec.components) components.Append(ComponentToNode(c));
    doc->Set("components", std::move(components));
  }
  if (!spec.end.empty()) doc->Set("end", EndNode(spec.end));
}

}  // namespace

yaml::Node ToDocument(const TrialSpec& spec) {
  Node doc = Node::Mapping();
  doc.Set("name", Str(spec.name));
  doc.Set("seed", Plain(std::to_string(spec.seed)));
  doc.Set("middleware", Str(MiddlewareName(spec.middleware)));
  doc.Set("world", spec.world_generate ? worlds::ToNode(*spec.world_generate) : Str(spec.world));
  if (spec.HasWorldSize()) {
    Node size = Node::Sequence();
    for (double v : spec.world_size_m) size.Append(Plain(Number(v)));
    doc.Set("world_size_m", std::move(size));
  }
  doc.Set("physics", PhysicsNode(spec));
  doc.Set("limits", LimitsNode(spec.limits));
  doc.Set("drones", DronesNode(spec));
  doc.Set("mission", MissionNode(spec.mission));
  doc.Set("raft", RaftNode(spec.raft));
  doc.Set("radio", RadioNode(spec.radio));
  SetOptionalSections(spec, &doc);
  doc.Set("timeout", TimeoutNode(spec));
  return doc;
}

}  // namespace swarmbox::dsl
