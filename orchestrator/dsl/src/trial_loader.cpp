#include "swarmbox/dsl/trial_loader.hpp"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <optional>
#include <regex>
#include <set>
#include <sstream>

#include "detail/user_software_keys.hpp"
#include "swarmbox/dsl/drone_groups.hpp"
#include "swarmbox/dsl/overrides.hpp"
#include "swarmbox/faults/channel_support.hpp"

namespace swarmbox::dsl {

namespace {

using yaml::Node;

constexpr std::size_t kMaxNameLength = 40;
constexpr std::size_t kMaxDrones = 200;  // fixed addresses in a /24 mesh subnet

Error At(const Node& node, std::string message) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), node.Where());
}

Error AtMark(const yaml::Mark& mark, std::string message) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), mark.ToString());
}

bool IsTrialName(std::string_view s) {
  if (s.empty() || s.size() > kMaxNameLength) return false;
  auto alnum = [](char c) { return (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9'); };
  if (!alnum(s[0])) return false;
  for (char c : s) {
    if (!alnum(c) && c != '-' && c != '_' && c != '.') return false;
  }
  return true;
}

bool IsDroneName(std::string_view s) {
  if (s.empty() || s.size() > 32 || !(s[0] >= 'a' && s[0] <= 'z')) return false;
  for (char c : s) {
    if (!((c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '_')) return false;
  }
  return true;
}

// Names that are not drones but can be named where a component is expected.
constexpr std::string_view kPhysics = "physics";
constexpr std::string_view kRaftLeader = "raft_leader";

Status CheckComponent(const TrialSpec& spec, const yaml::Mark& mark, const std::string& name,
                      bool allow_physics, bool allow_leader) {
  if (spec.FindDrone(name) != nullptr) return Ok{};
  if (allow_physics && name == kPhysics) return Ok{};
  if (allow_physics && spec.FindComponent(name) != nullptr) return Ok{};  // `from:` a component
  if (allow_leader && name == kRaftLeader) return Ok{};
  std::string accepted;
  for (const DroneSpec& d : spec.drones) accepted += (accepted.empty() ? "" : ", ") + d.name;
  if (allow_physics) accepted += ", physics";
  if (allow_physics) {
    for (const UserComponentSpec& c : spec.components) accepted += ", " + c.name;
  }
  if (allow_leader) accepted += ", raft_leader";
  return AtMark(mark, "unknown component '" + name + "' (expected one of " + accepted + ")");
}

// `mission: {..., tuning: {scout_altitude_m: 12, ...}}`: a mapping of plain numbers for kind sar.
// The names are the agent's (it refuses an unknown one, naming the known ones); `start` never.
Status DecodeMissionTuning(const Node& tuning, MissionSpec* out) {
  if (tuning.is_null()) return Ok{};
  if (!tuning.is_mapping()) {
    return At(tuning, "'tuning' must be a mapping of numbers by name, e.g. {scout_altitude_m: 12}");
  }
  if (out->kind != MissionKind::kSar) return At(tuning, "'tuning' belongs to mission kind sar (this mission is kind plan)");
  for (const auto& [key, value] : tuning.entries()) {
    if (key.scalar() == "start") {
      return At(key, "'start' is not a tuning number: a drone's take-off spot is its pose");
    }
    const std::optional<double> number =
        value.is_scalar() && !value.quoted() ? yaml::ScalarAsDouble(value.scalar()) : std::nullopt;
    if (!number || !std::isfinite(*number)) return At(value, "tuning '" + key.scalar() + "' must be a number");
  }
  out->tuning = tuning;
  return Ok{};
}

// `mission: {kind: sar|plan, plan: "takeoff:5,hover:10,land", inference_latency_ms: 40, tuning: {...}}`.
Status DecodeMission(const Node& node, MissionSpec* out) {
  std::string kind(MissionKindName(out->kind));
  yaml::MapReader r(node, "mission");
  r.Optional("kind", &kind).Optional("plan", &out->plan).Optional("inference_latency_ms",
                                                                   &out->inference_latency_ms);
  const Node* tuning = r.Child("tuning");
  SWARMBOX_TRY(r.Finish());
  if (kind == "sar") {
    out->kind = MissionKind::kSar;
  } else if (kind == "plan") {
    out->kind = MissionKind::kPlan;
  } else {
    return At(*node.Find("kind"), "unknown mission kind '" + kind + "' (expected sar or plan)");
  }
  if (const Node* plan = node.Find("plan")) {
    if (out->kind != MissionKind::kPlan) {
      return At(*plan, "'plan' belongs to mission kind plan (this mission is kind sar)");
    }
    if (out->plan.empty()) return At(*plan, "'plan' must not be empty (e.g. \"takeoff:5,hover:10,land\")");
    // The agent parses the plan; here only what would break its command line.
    for (char c : out->plan) {
      if (c == ' ' || c == '\t' || c == '\n') {
        return At(*plan, "'plan' is a comma-separated list without spaces, e.g. \"takeoff:5,hover:10,land\"");
      }
    }
  }
  if (out->inference_latency_ms < 0 || out->inference_latency_ms > 10000) {
    return At(*node.Find("inference_latency_ms"), "'inference_latency_ms' must be in [0, 10000] [ms]");
  }
  return tuning != nullptr ? DecodeMissionTuning(*tuning, out) : Ok{};
}

// `raft: {tick_ms, heartbeat_ms, election_timeout_ms, voters}`: what the agent's Raft service accepts
// (positive, both timings multiples of the tick, heartbeat < election timeout).
Status DecodeRaft(const Node& node, RaftSpec* out) {
  yaml::MapReader r(node, "raft");
  r.Optional("tick_ms", &out->tick_ms)
      .Optional("heartbeat_ms", &out->heartbeat_ms)
      .Optional("election_timeout_ms", &out->election_timeout_ms)
      .Optional("voters", &out->voters);
  SWARMBOX_TRY(r.Finish());
  auto where = [&](const char* key) -> const Node& {
    const Node* n = node.Find(key);
    return n != nullptr ? *n : node;
  };
  if (out->voters < 0) return At(where("voters"), "'voters' must be >= 0 (0: every drone votes)");
  for (const auto& [key, value] : {std::pair{"tick_ms", out->tick_ms}, std::pair{"heartbeat_ms", out->heartbeat_ms},
                                   std::pair{"election_timeout_ms", out->election_timeout_ms}}) {
    if (value <= 0) return At(where(key), "'" + std::string(key) + "' must be > 0 [ms]");
  }
  if (out->heartbeat_ms % out->tick_ms != 0) {
    return At(where("heartbeat_ms"), "'heartbeat_ms' (" + std::to_string(out->heartbeat_ms) +
                                         ") must be a multiple of tick_ms (" + std::to_string(out->tick_ms) + ")");
  }
  if (out->election_timeout_ms % out->tick_ms != 0) {
    return At(where("election_timeout_ms"), "'election_timeout_ms' (" + std::to_string(out->election_timeout_ms) +
                                                ") must be a multiple of tick_ms (" + std::to_string(out->tick_ms) + ")");
  }
  if (out->election_timeout_ms <= out->heartbeat_ms) {
    return At(where("election_timeout_ms"), "'election_timeout_ms' (" + std::to_string(out->election_timeout_ms) +
                                                ") must be longer than heartbeat_ms (" +
                                                std::to_string(out->heartbeat_ms) + ")");
  }
  return Ok{};
}

// `limits: {memory_mib, pids}` (the trial's, a drone's or physics'); a key left out keeps *out's
// value (the default, or 0 = the trial's in an override).
Status DecodeLimits(const Node& node, ContainerLimits* out) {
  yaml::MapReader r(node, "limits");
  r.Optional("memory_mib", &out->memory_mib).Optional("pids", &out->pids);
  SWARMBOX_TRY(r.Finish());
  if (const Node* m = node.Find("memory_mib"); m != nullptr && out->memory_mib < 6) {
    return At(*m, "'memory_mib' must be >= 6 [MiB] (Docker's minimum)");
  }
  if (const Node* p = node.Find("pids"); p != nullptr && out->pids < 16) {
    return At(*p, "'pids' must be >= 16 (it counts threads: DDS alone starts several)");
  }
  return Ok{};
}

// `record: {enabled, rate_hz, camera_hz, camera_scale, jpeg_quality}` (every key optional).
Status DecodeRecord(const Node& node, RecordSpec* out) {
  yaml::MapReader r(node, "record");
  r.Optional("enabled", &out->enabled)
      .Optional("rate_hz", &out->rate_hz)
      .Optional("camera_hz", &out->camera_hz)
      .Optional("camera_scale", &out->camera_scale)
      .Optional("jpeg_quality", &out->jpeg_quality);
  SWARMBOX_TRY(r.Finish());
  auto at = [&](std::string_view key, const std::string& what) { return At(*node.Find(key), what); };
  if (!(out->rate_hz > 0 && out->rate_hz <= 250)) {
    return at("rate_hz", "'rate_hz' must be in (0, 250]: true poses per simulated second (the lockstep runs at 250 Hz)");
  }
  if (!(out->camera_hz >= 0 && out->camera_hz <= 250)) {
    return at("camera_hz", "'camera_hz' must be in [0, 250]: camera frames per simulated second per drone (0: none)");
  }
  if (!(out->camera_scale > 0 && out->camera_scale <= 1)) {
    return at("camera_scale", "'camera_scale' must be in (0, 1]: the factor camera frames are resized by");
  }
  if (out->jpeg_quality < 1 || out->jpeg_quality > 100) {
    return at("jpeg_quality", "'jpeg_quality' must be in [1, 100]");
  }
  return Ok{};
}

// `radio: {model: channel|netem, profile: NAME|PATH, ping_every_ms: N, ping_peers: K}`.
Status DecodeRadio(const Node& node, RadioLinkSpec* out) {
  std::string model(RadioModelName(out->model));
  yaml::MapReader r(node, "radio");
  r.Optional("model", &model)
      .Optional("profile", &out->profile)
      .Optional("ping_every_ms", &out->ping_every_ms)
      .Optional("ping_peers", &out->ping_peers);
  SWARMBOX_TRY(r.Finish());
  if (model == "channel") {
    out->model = RadioModel::kChannel;
  } else if (model == "netem") {
    out->model = RadioModel::kNetem;
  } else {
    return At(*node.Find("model"), "unknown radio model '" + model +
                                        "' (expected channel, the simulated radio, or netem, the real network stack)");
  }
  if (const Node* profile = node.Find("profile")) {
    const std::string& p = out->profile;
    bool printable = !p.empty();
    for (char c : p) printable = printable && c > ' ' && c != '\\';
    if (!printable || p.front() == '/' || p.find("..") != std::string::npos) {
      return At(*profile, "'profile' must be a radio profile name (trials/radios/<NAME>.yaml) or a path inside "
                          "the trials directory, such as radios/wifi_5ghz_mesh.yaml");
    }
  }
  if (out->ping_every_ms < 0) {
    return At(*node.Find("ping_every_ms"), "'ping_every_ms' must be >= 0 (0 = no link pings)");
  }
  if (out->ping_peers < 1) {
    return At(*node.Find("ping_peers"), "'ping_peers' must be >= 1 (peers pinged per ping_every_ms round)");
  }
  return Ok{};
}

bool DefaultFileExists(const std::string& path) {
  std::error_code ec;
  return std::filesystem::is_regular_file(path, ec);
}

}  // namespace

std::string DefaultTrialsDir(std::string_view trial_file) {
  const std::filesystem::path folder = std::filesystem::path(std::string(trial_file)).parent_path();
  for (std::filesystem::path p = folder; !p.empty(); p = p.parent_path()) {
    if (p.filename() == "trials") return p.string();
    if (p == p.parent_path()) break;
  }
  return folder.empty() ? std::string(".") : folder.string();
}

namespace {

// The groups (`count:` items) of a document's drones list, as written.
std::vector<DroneGroup> GroupsOf(const yaml::Node& doc) {
  std::vector<DroneGroup> groups;
  const Node* drones = doc.is_mapping() ? doc.Find("drones") : nullptr;
  if (drones == nullptr || !drones->is_sequence()) return groups;
  for (const Node& item : drones->items()) {
    const Node* count = item.is_mapping() ? item.Find("count") : nullptr;
    const Node* name = count != nullptr ? item.Find("name") : nullptr;
    auto n = count != nullptr ? count->AsInt() : Result<std::int64_t>(0);
    if (name != nullptr && name->is_scalar() && n && *n > 0) groups.push_back({name->scalar(), static_cast<int>(*n)});
  }
  return groups;
}

Result<TrialSpec> DecodeExpanded(const yaml::Node& doc, const LoadOptions& options);

}  // namespace

Result<TrialSpec> DecodeTrial(const yaml::Node& document, const LoadOptions& options) {
  std::vector<DroneGroup> groups = GroupsOf(document);
  yaml::Node doc = document;
  SWARMBOX_TRY(ExpandDroneGroups(doc));
  auto spec = DecodeExpanded(doc, options);
  if (spec) spec->groups = std::move(groups);
  return spec;
}

namespace {

// The trial's top-level keys (the mapping checked: unknown keys, required ones), each section's
// node or null when absent.
struct Sections {
  const Node* world = nullptr;
  const Node* world_size = nullptr;
  const Node* physics = nullptr;
  const Node* drones = nullptr;
  const Node* mission = nullptr;
  const Node* raft = nullptr;
  const Node* radio = nullptr;
  const Node* record = nullptr;
  const Node* network = nullptr;
  const Node* faults = nullptr;
  const Node* end = nullptr;
  const Node* timeout = nullptr;
  const Node* limits = nullptr;
  const Node* components = nullptr;
};

// `name`, `seed` and `middleware` into *spec and *middleware, the sections' nodes.
Result<Sections> ReadSections(const Node& doc, TrialSpec* spec, std::string* middleware) {
  Sections s;
  yaml::MapReader r(doc, "trial");
  r.Required("name", &spec->name).Optional("seed", &spec->seed).Optional("middleware", middleware);
  s.world = r.Child("world", /*required=*/true);
  s.world_size = r.Child("world_size_m");
  s.physics = r.Child("physics");
  s.drones = r.Child("drones", /*required=*/true);
  s.mission = r.Child("mission");
  s.raft = r.Child("raft");
  s.radio = r.Child("radio");
  s.record = r.Child("record");
  s.network = r.Child("network");
  s.faults = r.Child("faults");
  s.end = r.Child("end");
  s.timeout = r.Child("timeout", /*required=*/true);
  s.limits = r.Child("limits");
  s.components = r.Child("components");
  SWARMBOX_TRY(r.Finish());
  return s;
}

bool Present(const Node* node) { return node != nullptr && !node->is_null(); }

// `world: worlds/open_field.yaml`, or `world: {generate: ...}` (worlds/generator.hpp).
Status DecodeWorld(const Node& world, TrialSpec* spec) {
  if (world.is_mapping()) {
    auto generate = worlds::ParseGenerateSpec(world);
    if (!generate) return generate.error();
    spec->world_generate = *generate;
    spec->world = "worlds/generated_" + std::string(worlds::KindName(generate->kind)) + ".yaml";
    return Ok{};
  }
  return yaml::Decode(world, &spec->world);
}

// `world_size_m: [X, Y]`: the geofence's size [m].
Status DecodeWorldSize(const Node& world_size, TrialSpec* spec) {
  const std::string what = "'world_size_m' must be [X, Y], the geofence's size in metres (both > 0)";
  if (!world_size.is_sequence() || world_size.items().size() != 2) return At(world_size, what);
  for (std::size_t i = 0; i < 2; ++i) {
    auto v = world_size.items()[i].AsDouble();
    if (!v || !(*v > 0) || !std::isfinite(*v)) return At(world_size.items()[i], what);
    spec->world_size_m[i] = *v;
  }
  return Ok{};
}

Status CheckTrialName(const Node& doc, const TrialSpec& spec) {
  if (IsTrialName(spec.name)) return Ok{};
  return At(*doc.Find("name"), "trial name '" + spec.name + "' must be 1-40 characters of a-z, 0-9, '-', '_', '.', "
                                   "starting with a letter or digit (it names folders and containers)");
}

// `middleware: cyclonedds|fastdds`.
Status DecodeMiddleware(const Node& doc, const std::string& middleware, TrialSpec* spec) {
  if (middleware == "cyclonedds") {
    spec->middleware = Middleware::kCycloneDds;
  } else if (middleware == "fastdds") {
    spec->middleware = Middleware::kFastDds;
  } else {
    return At(*doc.Find("middleware"), "unknown middleware '" + middleware + "' (expected cyclonedds or fastdds)");
  }
  return Ok{};
}

// `physics: {rtf, limits}`.
Status DecodePhysics(const Node& physics, TrialSpec* spec) {
  yaml::MapReader p(physics, "physics");
  p.Optional("rtf", &spec->rtf);
  const Node* physics_limits = p.Child("limits");
  SWARMBOX_TRY(p.Finish());
  if (Present(physics_limits)) SWARMBOX_TRY(DecodeLimits(*physics_limits, &spec->physics_limits));
  if (spec->rtf < 0) return At(*physics.Find("rtf"), "'rtf' must be >= 0 (0 = as fast as possible)");
  return Ok{};
}

// One item of `drones:` {name, airframe, pose, payload, limits, brain}; its name checked against
// the drones before it.
Result<DroneSpec> DecodeDrone(const Node& item, const detail::SoftwareContext& software, const TrialSpec& spec) {
  DroneSpec d;
  d.mark = item.mark();
  yaml::MapReader dr(item, "drone");
  dr.Required("name", &d.name).Required("airframe", &d.airframe).Optional("pose", &d.pose).Optional("payload", &d.payload);
  const Node* drone_limits = dr.Child("limits");
  const Node* brain = dr.Child("brain");
  SWARMBOX_TRY(dr.Finish());
  if (brain != nullptr) {
    auto decoded = detail::DecodeBrain(*brain, software);
    if (!decoded) return decoded.error();
    d.brain = std::move(*decoded);
  }
  if (Present(drone_limits)) SWARMBOX_TRY(DecodeLimits(*drone_limits, &d.limits));
  if (!IsDroneName(d.name) || d.name == kPhysics || d.name == kRaftLeader) {
    return At(*item.Find("name"), "drone name '" + d.name +
                                      "' must be 1-32 characters of a-z, 0-9, '_', starting "
                                      "with a letter, and not physics or raft_leader");
  }
  if (spec.FindDrone(d.name) != nullptr) return At(*item.Find("name"), "drone name '" + d.name + "' is used twice");
  return d;
}

// `drones:` a non-empty list of at most kMaxDrones.
Status DecodeDrones(const Node& drones, const detail::SoftwareContext& software, TrialSpec* spec) {
  if (!drones.is_sequence() || drones.items().empty()) {
    return At(drones, "'drones' must be a non-empty list of {name, airframe, pose}");
  }
  if (drones.items().size() > kMaxDrones) {
    return At(drones, "at most " + std::to_string(kMaxDrones) + " drones per trial");
  }
  for (const Node& item : drones.items()) {
    auto d = DecodeDrone(item, software, *spec);
    if (!d) return d.error();
    spec->drones.push_back(std::move(*d));
  }
  return Ok{};
}

// Every drone is a member of the swarm's one Raft log. The SAR mission's planner runs on the Raft
// leader only, so a SAR drone next to drones on other brains could wait forever under a leader
// that never plans (and the brains would ignore each other's entries): refused up front.
Status CheckSarBrains(const TrialSpec& spec) {
  if (spec.mission.kind != MissionKind::kSar) return Ok{};
  const DroneSpec* builtin = nullptr;
  const DroneSpec* other = nullptr;
  for (const DroneSpec& d : spec.drones) {
    const DroneSpec*& first = d.brain.kind == BrainKind::kBuiltin ? builtin : other;
    if (first == nullptr) first = &d;
  }
  if (builtin == nullptr || other == nullptr) return Ok{};
  return AtMark(other->mark, "drone '" + other->name + "' flies its own brain while '" + builtin->name +
                                 "' flies the sar mission: they would share one consensus log (Raft) whose leader "
                                 "plans the search only if it flies sar; give every drone a brain, or none "
                                 "(mission: {kind: plan} for builtin drones beside brains)");
}

std::vector<std::string> DroneNames(const TrialSpec& spec) {
  std::vector<std::string> names;
  for (const DroneSpec& d : spec.drones) names.push_back(d.name);
  return names;
}

// `network: {mesh: ...}` (the fault injector's schema, swarmbox_faults), names against the drones.
Status DecodeNetwork(const Node& network, TrialSpec* spec) {
  yaml::MapReader nr(network, "network");
  const Node* mesh = nr.Child("mesh");
  SWARMBOX_TRY(nr.Finish());
  if (mesh == nullptr) return Ok{};
  auto parsed = faults::ParseMeshBlock(*mesh);
  if (!parsed) return parsed.error();
  SWARMBOX_TRY(faults::ValidateRadioPeers(parsed->rules, DroneNames(*spec)));
  spec->mesh = std::move(*parsed);
  spec->mesh_node = *mesh;
  return Ok{};
}

// `faults:` the fault injector's schema (swarmbox_faults): shape, values, then names against the drones.
Status DecodeFaults(const Node& faults, TrialSpec* spec) {
  auto parsed = faults::ParseFaults(faults);
  if (!parsed) return parsed.error();
  SWARMBOX_TRY(faults::ValidateFaults(*parsed, DroneNames(*spec)));
  spec->faults = std::move(*parsed);
  spec->faults_node = faults;
  return Ok{};
}

// The simulated channel refuses what it does not carry out, before anything starts (with the
// reason and where; radio.model netem does all of it).
Status CheckChannelSupport(const TrialSpec& spec) {
  if (spec.radio.model != RadioModel::kChannel) return Ok{};
  SWARMBOX_TRY(faults::CheckChannelSupports(spec.mesh.rules, "network.mesh"));
  return faults::CheckChannelFaults(spec.faults);
}

// One item of `end:` {on, outcome, reason, from}.
Result<EndSpec> DecodeEndCondition(const Node& item, const TrialSpec& spec) {
  EndSpec e;
  std::string outcome;
  yaml::MapReader er(item, "end condition");
  er.Required("on", &e.on).Required("outcome", &outcome).Optional("reason", &e.reason).Optional("from", &e.from);
  SWARMBOX_TRY(er.Finish());
  try {
    std::regex check(e.on, std::regex::ECMAScript);
  } catch (const std::regex_error& ex) {
    return At(*item.Find("on"), "'on' is not a valid regular expression: " + std::string(ex.what()));
  }
  if (e.on.empty()) return At(*item.Find("on"), "'on' must not be empty");
  auto o = ParseOutcome(outcome);
  if (!o) {
    return At(*item.Find("outcome"), "unknown outcome '" + outcome + "' (expected success, failure, timeout or error)");
  }
  e.outcome = *o;
  if (!e.from.empty()) SWARMBOX_TRY(CheckComponent(spec, item.Find("from")->mark(), e.from, true, false));
  return e;
}

Status DecodeEnd(const Node& end, TrialSpec* spec) {
  if (!end.is_sequence()) return At(end, "'end' must be a list of {on, outcome, reason}");
  for (const Node& item : end.items()) {
    auto e = DecodeEndCondition(item, *spec);
    if (!e) return e.error();
    spec->end.push_back(std::move(*e));
  }
  return Ok{};
}

// `timeout: {sim, wall, outcome}`.
Status DecodeTimeout(const Node& timeout, TrialSpec* spec) {
  std::string outcome = "timeout";
  yaml::MapReader tr(timeout, "timeout");
  tr.Required("sim", &spec->timeout.sim).Optional("wall", &spec->timeout.wall).Optional("outcome", &outcome);
  SWARMBOX_TRY(tr.Finish());
  auto o = ParseOutcome(outcome);
  if (!o) {
    return At(*timeout.Find("outcome"),
              "unknown outcome '" + outcome + "' (expected success, failure, timeout or error)");
  }
  spec->timeout.outcome = *o;
  if (spec->timeout.sim.zero()) return At(*timeout.Find("sim"), "'sim' must be longer than 0s");
  return Ok{};
}

// A fault at a simulated time after the timeout would never fire.
Status CheckFaultTimes(const TrialSpec& spec) {
  for (const faults::Fault& f : spec.faults) {
    if (f.start.clock == faults::FaultStart::Clock::kSim && f.start.at_ms > spec.timeout.sim.ms()) {
      return AtMark(f.mark, "fault " + f.id + " at " + Duration::Ms(f.start.at_ms).ToString() +
                                " is after the timeout (" + spec.timeout.sim.ToString() + ")");
    }
  }
  return Ok{};
}

// LoadOptions::check_references: the world, a radio profile the file names and every airframe
// are files in the trials directory.
Status CheckReferences(const Node& doc, const Sections& sections, const LoadOptions& options, const TrialSpec& spec) {
  if (spec.trials_dir.empty()) return AtMark(doc.mark(), "no trials directory to resolve world and airframes against");
  auto exists = options.file_exists ? options.file_exists : DefaultFileExists;
  const std::filesystem::path dir(spec.trials_dir);
  if (!spec.world_generate) {
    if (std::filesystem::path(spec.world).is_absolute() || spec.world.find("..") != std::string::npos) {
      return At(*doc.Find("world"), "'world' must be a path inside the trials directory, such as worlds/open_field.yaml");
    }
    const std::string world_path = (dir / spec.world).string();
    if (!exists(world_path)) return At(*doc.Find("world"), "world '" + spec.world + "' not found (no file " + world_path + ")");
  }
  // A profile the file names is checked here, at its key; the default one (trials/radios/
  // wifi_5ghz_mesh.yaml, shipped) when the trial is planned (runner::CheckRadioProfile).
  if (const Node* profile = sections.radio != nullptr ? sections.radio->Find("profile") : nullptr;
      profile != nullptr && spec.radio.model == RadioModel::kChannel) {
    const std::string profile_path = (dir / RadioProfileFile(spec.radio)).string();
    if (!exists(profile_path)) {
      return At(*profile, "radio profile '" + spec.radio.profile + "' not found (no file " + profile_path + ")");
    }
  }
  std::size_t i = 0;
  for (const DroneSpec& d : spec.drones) {
    const Node& item = sections.drones->items()[i++];
    const std::string airframe_path = (dir / "airframes" / (d.airframe + ".yaml")).string();
    if (d.airframe.find('/') != std::string::npos || !exists(airframe_path)) {
      return At(*item.Find("airframe"), "unknown airframe '" + d.airframe + "' (no file " + airframe_path + ")");
    }
  }
  return Ok{};
}

// The sections in the order their errors are reported.
Result<TrialSpec> DecodeExpanded(const yaml::Node& doc, const LoadOptions& options) {
  TrialSpec spec;
  spec.document = doc;
  spec.trials_dir = options.trials_dir;
  std::string middleware = "cyclonedds";
  auto sections = ReadSections(doc, &spec, &middleware);
  if (!sections) return sections.error();
  const Sections& s = *sections;
  detail::SoftwareContext software;
  software.base_dir = options.base_dir;
  software.check_files = options.check_references;
  software.file_kind = options.file_kind;
  if (Present(s.limits)) SWARMBOX_TRY(DecodeLimits(*s.limits, &spec.limits));
  if (s.world != nullptr) SWARMBOX_TRY(DecodeWorld(*s.world, &spec));
  if (Present(s.world_size)) SWARMBOX_TRY(DecodeWorldSize(*s.world_size, &spec));
  SWARMBOX_TRY(CheckTrialName(doc, spec));
  SWARMBOX_TRY(DecodeMiddleware(doc, middleware, &spec));
  if (s.physics != nullptr) SWARMBOX_TRY(DecodePhysics(*s.physics, &spec));
  SWARMBOX_TRY(DecodeDrones(*s.drones, software, &spec));
  if (Present(s.mission)) SWARMBOX_TRY(DecodeMission(*s.mission, &spec.mission));
  if (Present(s.raft)) SWARMBOX_TRY(DecodeRaft(*s.raft, &spec.raft));
  if (Present(s.radio)) SWARMBOX_TRY(DecodeRadio(*s.radio, &spec.radio));
  if (Present(s.record)) SWARMBOX_TRY(DecodeRecord(*s.record, &spec.record));
  if (s.components != nullptr) {
    auto decoded = detail::DecodeComponents(*s.components, spec, software);
    if (!decoded) return decoded.error();
    spec.components = std::move(*decoded);
  }
  SWARMBOX_TRY(CheckSarBrains(spec));
  if (s.network != nullptr) SWARMBOX_TRY(DecodeNetwork(*s.network, &spec));
  if (Present(s.faults)) SWARMBOX_TRY(DecodeFaults(*s.faults, &spec));
  SWARMBOX_TRY(CheckChannelSupport(spec));
  if (Present(s.end)) SWARMBOX_TRY(DecodeEnd(*s.end, &spec));
  SWARMBOX_TRY(DecodeTimeout(*s.timeout, &spec));
  SWARMBOX_TRY(CheckFaultTimes(spec));
  if (options.check_references) SWARMBOX_TRY(CheckReferences(doc, s, options, spec));
  return spec;
}

}  // namespace

Result<TrialSpec> LoadTrialText(std::string_view text, std::string_view filename,
                                const LoadOptions& options) {
  auto doc = yaml::Parse(text, filename);
  if (!doc) return doc.error();
  std::vector<DroneGroup> groups;  // groups expanded by an override naming one of their drones
  for (const std::string& o : options.overrides) {
    if (AddressesGroupMember(*doc, o)) {
      std::vector<DroneGroup> now = GroupsOf(*doc);
      groups.insert(groups.end(), now.begin(), now.end());
      SWARMBOX_TRY(ExpandDroneGroups(*doc));
    }
    SWARMBOX_TRY(ApplyOverride(*doc, o));
  }
  LoadOptions resolved = options;
  if (resolved.trials_dir.empty()) resolved.trials_dir = DefaultTrialsDir(filename);
  if (resolved.base_dir.empty()) {
    const std::filesystem::path folder = std::filesystem::path(std::string(filename)).parent_path();
    resolved.base_dir = folder.empty() ? std::string(".") : folder.string();
  }
  auto spec = DecodeTrial(*doc, resolved);
  if (spec && !groups.empty()) spec->groups.insert(spec->groups.begin(), groups.begin(), groups.end());
  return spec;
}

Result<TrialSpec> LoadTrial(const std::string& path, const LoadOptions& options) {
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error(ErrorCode::kNotFound, "cannot open trial file", path);
  std::ostringstream text;
  text << in.rdbuf();
  return LoadTrialText(text.str(), path, options);
}

}  // namespace swarmbox::dsl
