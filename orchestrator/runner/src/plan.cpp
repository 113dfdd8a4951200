#include "swarmbox/runner/plan.hpp"

#include <algorithm>
#include <charconv>
#include <filesystem>
#include <set>
#include <variant>

#include "swarmbox/bus/cyclone_config.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/step.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::runner {

Result<ViewBinding> ParseViewAddress(std::string_view text) {
  ViewBinding b;
  if (text.empty()) return b;
  const std::string what = "'" + std::string(text) + "': expected ADDR:PORT (an IPv4 address of this host and a port 1-65535), e.g. 127.0.0.1:8765";
  std::string_view addr = text;
  const auto colon = text.rfind(':');
  if (colon != std::string_view::npos) {
    addr = text.substr(0, colon);
    const std::string_view port = text.substr(colon + 1);
    int p = 0;
    auto [ptr, ec] = std::from_chars(port.data(), port.data() + port.size(), p);
    if (port.empty() || ec != std::errc() || ptr != port.data() + port.size() || p < 1 || p > 65535) {
      return Error(ErrorCode::kInvalidArgument, what);
    }
    b.host_port = p;
  }
  if (!addr.empty()) {
    int parts = 0;
    std::size_t start = 0;
    while (true) {
      const auto dot = addr.find('.', start);
      const std::string_view part = addr.substr(start, dot == std::string_view::npos ? std::string_view::npos : dot - start);
      int v = -1;
      auto [ptr, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
      if (part.empty() || part.size() > 3 || ec != std::errc() || ptr != part.data() + part.size() || v > 255) {
        return Error(ErrorCode::kInvalidArgument, what);
      }
      ++parts;
      if (dot == std::string_view::npos) break;
      start = dot + 1;
    }
    if (parts != 4) return Error(ErrorCode::kInvalidArgument, what);
    b.host_ip = std::string(addr);
  }
  return b;
}

std::string ShortestNumber(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

namespace {

std::string InContainer(std::string_view relative) {
  return std::string(kContainerTrialsDir) + "/" + std::string(relative);
}

std::string AirframeRelative(const dsl::DroneSpec& d) { return "airframes/" + d.airframe + ".yaml"; }

// --- the command lines: adjust here when the programs' flags change ------------------------------

// Inside the containers: sim is the first network attached (eth0), mesh the second (eth1).
constexpr std::string_view kSimInterface = kSimInterfaceName;
constexpr std::string_view kMeshInterface = kMeshInterfaceName;
constexpr int kSimDomain = 0;   // each trial has its own networks, so fixed domain ids are safe
constexpr int kMeshDomain = 1;

// swarmbox-physics (physics_server/README.md).
constexpr double kFaultClockEveryS = 0.5;  // [simulated s]
// The recording (record:), collected with truth.csv.
void AppendRecordFlags(const dsl::TrialSpec& spec, std::vector<std::string>* argv) {
  if (!spec.record.enabled) return;
  argv->insert(argv->end(), {"--record", std::string(kRecordingPath),
                             "--record-rate-hz", ShortestNumber(spec.record.rate_hz),
                             "--record-camera-hz", ShortestNumber(spec.record.camera_hz),
                             "--record-camera-scale", ShortestNumber(spec.record.camera_scale),
                             "--record-jpeg-quality", std::to_string(spec.record.jpeg_quality)});
}

// The simulated radio: the channel with its profile, and the plan of what happens at simulated
// times (network.mesh, the faults with `at:`; radio_schedule.hpp); the step and join timeouts.
void AppendRadioAndTimeoutFlags(const dsl::TrialSpec& spec, bool radio_plan, std::vector<std::string>* argv) {
  const bool channel = spec.radio.model == dsl::RadioModel::kChannel;
  if (channel) {
    argv->insert(argv->end(), {"--radio-model", "channel", "--radio-profile", InContainer(dsl::RadioProfileFile(spec.radio))});
    if (radio_plan) argv->insert(argv->end(), {"--radio-plan", std::string(kRadioPlanPath)});
  }
  // netem: faults at simulated times fire at the log line that crosses their time (the fault
  // injector's timeline): with such faults the physics server reports its clock every 0.5 s
  // (default 10 s), so they fire at most 0.5 s late. With the channel they are in the plan.
  // An agent with an external brain waits up to the brain's wall-clock bounds for its answer:
  // the server must wait longer before it calls that drone lost.
  if (spec.HasExternalBrain()) {
    argv->insert(argv->end(), {"--step-timeout", ShortestNumber(std::max(kExternalBrainStepTimeoutS, channel ? kChannelStepTimeoutS : 0.0)),
                               "--join-timeout", ShortestNumber(kExternalBrainJoinTimeoutS)});
  } else if (channel) {
    argv->insert(argv->end(), {"--step-timeout", ShortestNumber(kChannelStepTimeoutS)});
  }
  for (const faults::Fault& f : spec.faults) {
    if (!channel && f.start.clock == faults::FaultStart::Clock::kSim) {
      argv->insert(argv->end(), {"--clock-every", ShortestNumber(kFaultClockEveryS)});
      break;
    }
  }
}

// name:airframe:x,y,z[:yaw_deg[:payload[:attached|ground]]]; a payload starts on the ground
// under the drone (a lifter standing on the ground cannot spawn with it hanging).
void AppendDroneFlags(const dsl::TrialSpec& spec, std::vector<std::string>* argv) {
  for (const dsl::DroneSpec& d : spec.drones) {
    std::string drone = d.name + ":" + d.airframe + ":" + ShortestNumber(d.pose[0]) + "," + ShortestNumber(d.pose[1]) +
                        "," + ShortestNumber(d.pose[2]);
    if (!d.payload.empty()) drone += ":0:" + d.payload + ":ground";
    argv->push_back("--drone");
    argv->push_back(std::move(drone));
  }
}

// swarmbox-physics's command line.
std::vector<std::string> PhysicsArgv(const dsl::TrialSpec& spec, bool radio_plan, bool view) {
  std::vector<std::string> argv = {
      images::kPhysicsBinaryInImage,
      "--world", InContainer(spec.world),
      "--airframes-dir", InContainer("airframes"),
      "--seed", std::to_string(spec.seed),
      "--rtf", ShortestNumber(spec.rtf),
      "--middleware", std::string(dsl::MiddlewareName(spec.middleware)),
      "--sim-interface", std::string(kSimInterface),
      "--domain", std::to_string(kSimDomain),
      // Discovery on sim is a star around the server (bus/cyclone_config.hpp): its participant has
      // the well-known index 0, which every agent names (--sim-peer) instead of multicasting.
      "--participant-index", "0",
      "--truth", std::string(kTruthCsvPath),
      // Stops (event=stopped t=...) when the trial's simulated time is up; truth.csv is flushed.
      "--max-sim-time", ShortestNumber(spec.timeout.sim.seconds()),
  };
  // The live view (swarmbox run --view): every address of the container, published by Docker.
  if (view) argv.insert(argv.end(), {"--view", "0.0.0.0:" + std::to_string(kViewContainerPort)});
  AppendRecordFlags(spec, &argv);
  AppendRadioAndTimeoutFlags(spec, radio_plan, &argv);
  AppendDroneFlags(spec, &argv);
  return argv;
}

}  // namespace

std::vector<std::string> PhysicsCommandArgv(dsl::Middleware middleware, const faults::WorldCommandCall& call) {
  std::vector<std::string> argv = {
      images::kPhysicsBinaryInImage,
      "--sim-interface", std::string(kSimInterface),
      "--domain", std::to_string(kSimDomain),
      "--middleware", std::string(dsl::MiddlewareName(middleware)),
      "--send-command", call.target.empty() ? "-" : call.target, call.command,
  };
  for (double a : call.args) argv.push_back(ShortestNumber(a));
  return argv;
}

namespace {

std::string Members(const dsl::TrialSpec& spec) {
  std::string out;
  for (const dsl::DroneSpec& d : spec.drones) out += (out.empty() ? "" : ",") + d.name;
  return out;
}

std::string BasenameOf(const std::string& path) { return std::filesystem::path(path).filename().string(); }

std::string BrainLibraryInImage(const dsl::BrainSpec& brain) {
  return std::string(kBrainsDir) + "/" + BasenameOf(brain.host_path.empty() ? brain.path : brain.host_path);
}

// Raft on the mesh: every drone of the trial, in trial order; timings from `raft:`. At swarm
// scale the first raft.voters drones vote, the others are learners; with no more drones than
// voters every drone votes (no flag: the agent's default).
void AppendRaftFlags(const dsl::TrialSpec& spec, std::vector<std::string>* argv) {
  argv->insert(argv->end(), {
      "--members", Members(spec),
      "--seed", std::to_string(spec.seed),
      "--raft-tick-ms", std::to_string(spec.raft.tick_ms),
      "--raft-heartbeat-ms", std::to_string(spec.raft.heartbeat_ms),
      "--raft-election-timeout-ms", std::to_string(spec.raft.election_timeout_ms),
  });
  if (spec.raft.voters > 0 && static_cast<std::size_t>(spec.raft.voters) < spec.drones.size()) {
    std::string voters;
    for (int k = 0; k < spec.raft.voters; ++k) {
      voters += (voters.empty() ? "" : ",") + spec.drones[static_cast<std::size_t>(k)].name;
    }
    argv->insert(argv->end(), {"--raft-voters", voters});
  }
}

// The user's brain (agent/app/README.md "Which brain flies"): its context gets the world and the payload; the
// mission keys are the builtin brain's.
void AppendUserBrainFlags(const dsl::TrialSpec& spec, const dsl::DroneSpec& d, std::vector<std::string>* argv) {
  const dsl::BrainSpec& brain = d.brain;
  argv->insert(argv->end(), {"--world", InContainer(spec.world),
                             "--inference-latency-ms", std::to_string(spec.mission.inference_latency_ms)});
  if (!d.payload.empty()) argv->insert(argv->end(), {"--payload", d.payload});
  if (brain.kind == dsl::BrainKind::kLibrary) {
    argv->insert(argv->end(), {"--brain", "library",
                               "--brain-library", BrainLibraryInImage(brain),
                               "--brain-name", brain.name,
                               "--brain-args", brain.ArgsJson()});
  } else {
    argv->insert(argv->end(), {"--brain", "external"});
  }
  if (brain.rate_hz > 0) argv->insert(argv->end(), {"--brain-rate-hz", ShortestNumber(brain.rate_hz)});
  if (brain.offboard.timeout_ms) {
    argv->insert(argv->end(), {"--offboard-timeout-ms", std::to_string(*brain.offboard.timeout_ms)});
  }
  if (brain.offboard.hold_ms) {
    argv->insert(argv->end(), {"--offboard-hold-ms", std::to_string(*brain.offboard.hold_ms)});
  }
}

// What decides: the user's brain, else the builtin brain's plan or SAR mission.
void AppendBrainFlags(const dsl::TrialSpec& spec, const dsl::DroneSpec& d, std::vector<std::string>* argv) {
  if (d.brain.kind != dsl::BrainKind::kBuiltin) {
    AppendUserBrainFlags(spec, d, argv);
  } else if (spec.mission.kind == dsl::MissionKind::kPlan) {
    argv->insert(argv->end(), {"--mission", "plan", "--plan", spec.mission.plan});
  } else {
    argv->insert(argv->end(), {"--mission", "sar", "--world", InContainer(spec.world),
                               "--inference-latency-ms", std::to_string(spec.mission.inference_latency_ms)});
    // The lifter starts with its payload on the ground under it (as the physics server places it).
    if (!d.payload.empty()) argv->insert(argv->end(), {"--payload", d.payload});
    // mission.tuning as JSON (the agent checks the names against SarBrain's and refuses others).
    if (const std::string tuning = spec.mission.TuningJson(); !tuning.empty()) {
      argv->insert(argv->end(), {"--mission-tuning", tuning});
    }
  }
}

// swarmbox-agent (agent/app/main.cpp --help): the shared contract's flags. An agent given a flag it
// does not know exits 2, so a new flag goes here only once agent/app/main.cpp has it.
std::vector<std::string> AgentArgv(const dsl::TrialSpec& spec, const dsl::DroneSpec& d) {
  std::vector<std::string> argv = {
      images::kAgentBinaryInImage,
      "--name", d.name,
      "--airframe", InContainer(AirframeRelative(d)),
      "--middleware", std::string(dsl::MiddlewareName(spec.middleware)),
      "--sim-interface", std::string(kSimInterface),
      "--sim-domain", std::to_string(kSimDomain),
      // Discovery by unicast to the physics server (and the drone's brain) only: N agents make N
      // discovery pairs, not N^2/2 (a 40-drone start no longer stalls in agent-agent discovery).
      "--sim-peer", std::string(kPhysicsId),
  };
  if (d.brain.external()) argv.insert(argv.end(), {"--sim-peer", BrainHostName(d.name)});
  if (spec.radio.model == dsl::RadioModel::kChannel) {
    // The radio is the physics server's channel, over the sim bus: no mesh network, no mesh domain.
    argv.insert(argv.end(), {"--radio-model", "channel"});
  } else {
    argv.insert(argv.end(), {"--mesh-interface", std::string(kMeshInterface),
                             "--mesh-domain", std::to_string(kMeshDomain)});
  }
  argv.insert(argv.end(), {"--sample-timeout", ShortestNumber(kAgentStartPatienceS),
                           "--stall-timeout", ShortestNumber(AgentStallTimeoutS(spec.drones.size()))});
  argv.insert(argv.end(), {"--start", ShortestNumber(d.pose[0]) + "," + ShortestNumber(d.pose[1]) + "," +
                                          ShortestNumber(d.pose[2])});
  AppendRaftFlags(spec, &argv);
  // The radio link measurement (event=link per sampled peer).
  argv.insert(argv.end(), {"--ping-every-ms", std::to_string(spec.radio.ping_every_ms),
                           "--ping-peers", std::to_string(spec.radio.ping_peers)});
  // The recording: the agent's telemetry at the rate of the true poses.
  if (spec.record.enabled) argv.insert(argv.end(), {"--telemetry-hz", ShortestNumber(spec.record.rate_hz)});
  // The WAL in the container's volume (the root filesystem is read-only; a restart keeps it).
  argv.insert(argv.end(), {"--raft-dir", std::string(kAgentStateDir) + "/raft"});
  AppendBrainFlags(spec, d, &argv);
  // The agent starts unloaded (--payload-mass 0): its payload lies on the ground.
  return argv;
}

// An external brain (agent/brain/README.md "The offboard topics"): --drone, --domain (the sim bus), --members
// (trial order) first, then the trial's args. A packed program is its image's entrypoint and comes first;
// an image or a Dockerfile's image keeps its ENTRYPOINT and gets these as its command.
std::vector<std::string> BrainArgv(const dsl::TrialSpec& spec, const dsl::DroneSpec& d) {
  std::vector<std::string> argv;
  if (d.brain.kind == dsl::BrainKind::kProgram) {
    argv.push_back(std::string(kProgramDirInImage) + "/" + BasenameOf(d.brain.host_path.empty() ? d.brain.path : d.brain.host_path));
  }
  argv.insert(argv.end(), {"--drone", d.name, "--domain", std::to_string(kSimDomain), "--members", Members(spec)});
  for (std::string& a : d.brain.ArgList()) argv.push_back(std::move(a));
  return argv;
}

// The fault sidecar of a drone: holds the drone's network namespace (sim and mesh attachments,
// fixed addresses) so the mesh impairment is in place before the agent's first packet and survives
// the agent being killed or restarted; the agent joins it (network_of). It alone has NET_ADMIN
// (CapDrop ALL); its pid 1 is swarmbox-netemd's `sleep` (reaps the daemons started by exec).
std::vector<std::string> SidecarArgv() { return {images::kNetemdInImage, "sleep"}; }

// Every agent and the physics server: no capabilities, no privilege gained by exec, nothing
// written outside the volume and the scratch tmpfs, bounded memory and processes.
// The user's containers (brains, components): no capabilities, no privilege gained by exec,
// bounded memory and processes; their root filesystem stays writable (their files are theirs).
void ConfineUser(const dsl::ContainerLimits& limits, dsl::ContainerSpec* c) {
  c->cap_drop = {"ALL"};
  c->no_new_privileges = true;
  c->memory_mib = limits.memory_mib;
  c->pids_limit = limits.pids;
}

void Confine(const dsl::ContainerLimits& limits, dsl::ContainerSpec* c) {
  c->cap_drop = {"ALL"};
  c->no_new_privileges = true;
  c->read_only_rootfs = true;
  c->volumes = {std::string(kContainerVolumeDir)};
  c->tmpfs = {{std::string(kScratchTmpfsDir), kScratchTmpfsMib}};
  c->memory_mib = limits.memory_mib;
  c->pids_limit = limits.pids;
}

// -------------------------------------------------------------------------------------------------

}  // namespace

Result<std::map<std::string, double>> LoadPayloadMasses(const dsl::TrialSpec& spec,
                                                        const std::string& trials_dir) {
  std::map<std::string, double> masses;
  for (const dsl::DroneSpec& d : spec.drones) {
    if (d.payload.empty()) continue;
    const std::string path = (std::filesystem::path(trials_dir) / AirframeRelative(d)).string();
    auto doc = yaml::ParseFile(path);
    if (!doc) return doc.error();
    const yaml::Node* payloads = doc->Find("payloads");
    bool found = false;
    if (payloads != nullptr && payloads->is_sequence()) {
      for (const yaml::Node& p : payloads->items()) {
        const yaml::Node* name = p.Find("name");
        const yaml::Node* mass = p.Find("mass_kg");
        if (name == nullptr || mass == nullptr || name->scalar() != d.payload) continue;
        auto kg = mass->AsDouble();
        if (!kg) return kg.error();
        masses[d.airframe + "/" + d.payload] = *kg;
        found = true;
      }
    }
    if (!found) {
      return Error(ErrorCode::kInvalidArgument,
                   "drone " + d.name + ": airframe " + d.airframe + " has no payload '" + d.payload + "'",
                   d.mark.ToString());
    }
  }
  return masses;
}

Status CheckRadioProfile(const dsl::TrialSpec& spec, const std::string& trials_dir) {
  if (spec.radio.model != dsl::RadioModel::kChannel) return Ok{};
  const std::string relative = dsl::RadioProfileFile(spec.radio);
  const std::string path = (std::filesystem::path(trials_dir) / relative).lexically_normal().string();
  std::error_code ec;
  if (std::filesystem::is_regular_file(path, ec)) return Ok{};
  return Error(ErrorCode::kInvalidArgument,
               "radio profile '" + spec.radio.profile + "' not found (no file " + path +
                   "): radio.model channel needs one (set radio.profile, or radio.model: netem for the real "
                   "network stack)");
}

bool NeedsFaultSidecars(const dsl::TrialSpec& spec) {
  if (spec.radio.model == dsl::RadioModel::kChannel) return false;  // the channel impairs in the plan
  if (!spec.mesh.empty()) return true;
  for (const faults::Fault& f : spec.faults) {
    if (std::holds_alternative<faults::RadioFault>(f.action) ||
        std::holds_alternative<faults::PartitionFault>(f.action)) {
      return true;
    }
  }
  return false;
}

std::string SidecarId(std::string_view drone) { return std::string(drone) + "-faults"; }
std::string BrainId(std::string_view drone) { return std::string(drone) + "-brain"; }
std::string BrainHostName(std::string_view drone) {
  std::string host = "brain-" + std::string(drone);
  std::replace(host.begin(), host.end(), '_', '-');
  return host;
}

std::string CycloneUriFor(std::string_view interface, int participant_index) {
  // The agents' and the physics server's own configuration (swarmbox/bus/cyclone_config.hpp), so a
  // program the runner starts discovers and fragments as they do.
  return bus::CycloneXml({.interface = std::string(interface), .participant_index = participant_index});
}

double AgentStallTimeoutS(std::size_t drones) {
  constexpr double kBaseS = 5.0;
  constexpr double kPerDroneS = 0.15;
  return kBaseS + kPerDroneS * static_cast<double>(drones);
}

dsl::Duration DefaultWallGuard(const dsl::TrialSpec& spec) {
  const double sim_s = spec.timeout.sim.seconds();
  // A step waits for every drone's answer, so its wall cost grows with the fleet: on 2 cores ~10
  // drones run near rtf 1 at rtf 0, 100 drones near 0.1-0.3 (BENCHMARKS.md "swarm"); the start
  // takes ~0.6 s per drone (101 joined in 58.8 s). A fleet past 10 gets proportionally longer.
  const double drones = static_cast<double>(spec.drones.size());
  const double slower = std::max(1.0, drones / 10.0);
  const double start_s = 120.0 + std::max(0.0, drones - 20.0);
  const double guard_s = spec.rtf > 0 ? sim_s / spec.rtf * 1.5 * slower + start_s : sim_s * 3.0 * slower + start_s;
  return dsl::Duration::Ms(static_cast<std::int64_t>(guard_s * 1000.0));
}

namespace {

Status CheckPlanOptions(const dsl::TrialSpec& spec, const PlanOptions& options) {
  if (options.run_id.empty()) return Error(ErrorCode::kInvalidArgument, "PlanTrial: no run id");
  if (spec.world_generate && options.world_path.empty()) {
    return Error(ErrorCode::kInvalidArgument, "PlanTrial: a generated world needs PlanOptions::world_path (DerivedWorldText)");
  }
  if (options.images.physics.empty() || options.images.agent.empty()) {
    return Error(ErrorCode::kInvalidArgument, "PlanTrial: images for physics and agent are needed");
  }
  return Ok{};
}

// Every brain and component has its image, no component takes a trial name, and the fixed
// addresses fit a /24: drones from kFirstDroneHost, then the external brains and the components on
// sim (and on mesh) right after them.
Status CheckImagesAndAddresses(const dsl::TrialSpec& spec, const PlanOptions& options) {
  std::size_t sim_hosts = spec.drones.size();
  std::size_t mesh_hosts = spec.drones.size();
  for (const dsl::DroneSpec& d : spec.drones) {
    if (d.brain.external()) ++sim_hosts;
    if (d.brain.kind == dsl::BrainKind::kLibrary && options.images.drone_agents.count(d.name) == 0) {
      return Error(ErrorCode::kInvalidArgument, "PlanTrial: no agent image with the brain library of " + d.name);
    }
    if (d.brain.external() && options.images.brains.count(d.name) == 0) {
      return Error(ErrorCode::kInvalidArgument, "PlanTrial: no image for the brain of " + d.name);
    }
  }
  for (const dsl::UserComponentSpec& c : spec.components) {
    for (const std::string& n : c.networks) ++(n == kMeshNetworkId ? mesh_hosts : sim_hosts);
    if (options.images.components.count(c.name) == 0) {
      return Error(ErrorCode::kInvalidArgument, "PlanTrial: no image for component " + c.name);
    }
    if (c.name == kPhysicsId || spec.FindDrone(c.name) != nullptr) {
      return Error(ErrorCode::kInvalidArgument, "component name '" + c.name + "' is taken by the trial", c.mark.ToString());
    }
  }
  if (std::max(sim_hosts, mesh_hosts) + kFirstDroneHost >= 255) {
    return Error(ErrorCode::kInvalidArgument,
                 "too many drones, brains and components for a /24: " + std::to_string(std::max(sim_hosts, mesh_hosts)));
  }
  return Ok{};
}

// The tree's run priorities (0 for unused stages).
struct RunLevels {
  std::map<int, int> of_component;  // component priority -> tree run priority
  int physics = 0;
  int brains = 0;
  int sidecars = 0;
  int faults = 0;
  int drones = 0;
};

// A group's plugins carry the group's level as their own priority: the engine orders creations
// by plugin priority across the whole tree (a level's creations wait for the lower ones'), so
// the numbers must be comparable between groups.
// Run levels: networks 0; components below the drones' priority, each priority its own level;
// physics; external brains; sidecars and their set-up step; the drones (with the components of
// priority kDronesPriority); the components above it.
Result<RunLevels> PlanRunLevels(const dsl::TrialSpec& spec, bool sidecars) {
  std::set<int> before;
  std::set<int> after;
  for (const dsl::UserComponentSpec& c : spec.components) {
    if (c.priority < dsl::kDronesPriority) before.insert(c.priority);
    if (c.priority > dsl::kDronesPriority) after.insert(c.priority);
  }
  RunLevels levels;
  int next_level = 1;
  for (int p : before) levels.of_component[p] = next_level++;
  levels.physics = next_level++;
  levels.brains = spec.HasExternalBrain() ? next_level++ : 0;
  levels.sidecars = sidecars ? next_level++ : 0;
  levels.faults = sidecars ? next_level++ : 0;
  levels.drones = next_level++;
  levels.of_component[dsl::kDronesPriority] = levels.drones;
  for (int p : after) levels.of_component[p] = next_level++;
  if (next_level - 1 > dsl::kMaxRunPriority) {
    return Error(ErrorCode::kInvalidArgument, "too many component priorities: " + std::to_string(before.size() + after.size()));
  }
  return levels;
}

// What the plan's stages share: the trial being built, its networks and the next free host
// addresses after the drones' (external brains, then components).
struct TreeBuilder {
  const dsl::TrialSpec& spec;
  const PlanOptions& options;
  const TrialSubnets& nets;
  std::string trial_id;
  dsl::Trial& trial;
  dsl::InputFile world_input = {};
  dsl::Network* sim_net = nullptr;
  dsl::Network* mesh_net = nullptr;  // null with the channel radio
  std::uint32_t next_sim_host = 0;
  std::uint32_t next_mesh_host = 0;

  std::string Name(std::string_view component) const {
    return ResourceName(spec.name, options.run_id, component);
  }
  std::map<std::string, std::string> Labels(std::string_view component) const {
    return RunLabels(options.run_id, trial_id, component);
  }
  dsl::InputFile Input(const std::string& relative) const {
    return dsl::InputFile{(std::filesystem::path(options.trials_dir) / relative).lexically_normal().string(),
                          InContainer(relative)};
  }
  std::map<std::string, std::string> RunEnv() const {
    return {{"SWARMBOX_RUN", options.run_id}, {"SWARMBOX_TRIAL", trial_id}};
  }
  bool channel() const { return spec.radio.model == dsl::RadioModel::kChannel; }
};

// Docker names a container's interfaces in the order of its networks' names (libnetwork sorts
// the endpoints), not in the order they were attached: "net1-sim" < "net2-mesh" makes sim eth0
// and mesh eth1 in every agent, as kSimInterface/kMeshInterface say (measured on 20.10).
void AddNetworks(TreeBuilder& b) {
  dsl::NetworkSpec sim = dsl::NetworkSpec::Subnet(b.Name("net1-sim"), b.nets.sim.ToString(),
                                                  b.nets.sim.Host(kGatewayHost));
  sim.labels = b.Labels(kSimNetworkId);
  // Not `internal`: Docker's isolation rules for internal networks drop every packet whose
  // destination is outside the subnet, DDS discovery multicast (239.255.0.1) included, once
  // bridged traffic goes through iptables (br_netfilter; measured on this host).
  sim.internal = false;
  b.sim_net = &b.trial.Add<dsl::Network>(std::string(kSimNetworkId), std::move(sim), 0);
  // The mesh network carries the netem model's radio; the channel's radio is simulated.
  if (b.channel()) return;
  dsl::NetworkSpec mesh = dsl::NetworkSpec::Subnet(b.Name("net2-mesh"), b.nets.mesh.ToString(),
                                                   b.nets.mesh.Host(kGatewayHost));
  mesh.labels = b.Labels(kMeshNetworkId);
  mesh.internal = false;
  b.mesh_net = &b.trial.Add<dsl::Network>(std::string(kMeshNetworkId), std::move(mesh), 0);
}

// The physics server's files: the world, each airframe once, the channel's profile and plan.
void AddPhysicsInputs(const TreeBuilder& b, bool radio_plan, dsl::ContainerSpec* physics) {
  physics->inputs.push_back(b.world_input);
  std::set<std::string> airframes;
  for (const dsl::DroneSpec& d : b.spec.drones) {
    if (airframes.insert(d.airframe).second) physics->inputs.push_back(b.Input(AirframeRelative(d)));
  }
  if (b.channel()) {
    physics->inputs.push_back(b.Input(dsl::RadioProfileFile(b.spec.radio)));
    if (radio_plan) physics->inputs.push_back({b.options.radio_plan_path, std::string(kRadioPlanPath)});
  }
}

// The physics server: owns simulated time, writes truth.csv.
void AddPhysics(TreeBuilder& b, int level) {
  const dsl::TrialSpec& spec = b.spec;
  const PlanOptions& options = b.options;
  const std::string physics_ip = b.nets.sim.Host(kPhysicsHost);
  const bool radio_plan = b.channel() && !options.radio_plan_path.empty();
  dsl::ContainerSpec physics =
      dsl::ContainerSpec::Image(options.images.physics, PhysicsArgv(spec, radio_plan, options.view.has_value()));
  physics.name = b.Name(kPhysicsId);
  physics.hostname = std::string(kPhysicsId);
  physics.labels = b.Labels(kPhysicsId);
  physics.env = b.RunEnv();
  AddPhysicsInputs(b, radio_plan, &physics);
  physics.scratch_dirs = {std::string(kContainerOutDir)};
  physics.artifacts = {std::string(kTruthCsvPath)};
  if (spec.record.enabled) physics.artifacts.push_back(std::string(kRecordingPath));
  if (options.view) physics.ports.push_back({kViewContainerPort, options.view->host_ip, options.view->host_port});
  Confine(spec.LimitsOf(nullptr), &physics);
  b.trial.Add<dsl::Plugin>(std::string(kPhysicsId), std::move(physics), level)
      .On(*b.sim_net, physics_ip, {std::string(kPhysicsId)})
      .ReadyOn(std::string(kPhysicsReadyPattern), dsl::Duration::Seconds(60));
}

// External brains: their own containers on sim, started before the agents that wait for them.
void AddExternalBrains(TreeBuilder& b, int level) {
  if (!b.spec.HasExternalBrain()) return;
  auto& brains = b.trial.Add<dsl::Component>(std::string(kBrainsGroupId), level);
  for (const dsl::DroneSpec& d : b.spec.drones) {
    if (!d.brain.external()) continue;
    const std::string id = BrainId(d.name);
    dsl::ContainerSpec bc = dsl::ContainerSpec::Image(b.options.images.brains.at(d.name), BrainArgv(b.spec, d));
    bc.argv_is_cmd = d.brain.kind != dsl::BrainKind::kProgram;
    bc.name = b.Name(id);
    bc.hostname = id;
    bc.labels = RoleLabels(b.options.run_id, b.trial_id, id, kRoleBrain);
    bc.env = b.RunEnv();
    // index 0: the well-known port its agent names with --sim-peer
    bc.env["CYCLONEDDS_URI"] = CycloneUriFor(kSimInterface, 0);
    ConfineUser(b.spec.LimitsOf(&d), &bc);
    bc.stop_timeout_s = 5;
    brains.Add<dsl::Plugin>(id, std::move(bc), level)
        .On(*b.sim_net, b.nets.sim.Host(b.next_sim_host++), {id, BrainHostName(d.name)});
  }
}

dsl::ContainerSpec ComponentContainer(const TreeBuilder& b, const dsl::UserComponentSpec& c) {
  std::vector<std::string> argv;
  if (c.source == dsl::ComponentSource::kProgram) {
    argv.push_back(std::string(kProgramDirInImage) + "/" + BasenameOf(c.host_path.empty() ? c.ref : c.host_path));
  }
  argv.insert(argv.end(), c.args.begin(), c.args.end());
  dsl::ContainerSpec cc = dsl::ContainerSpec::Image(b.options.images.components.at(c.name), std::move(argv));
  cc.argv_is_cmd = c.source != dsl::ComponentSource::kProgram;
  cc.name = b.Name(c.name);
  cc.labels = RoleLabels(b.options.run_id, b.trial_id, c.name, kRoleComponent);
  cc.env = b.RunEnv();
  const bool on_sim = std::find(c.networks.begin(), c.networks.end(), kSimNetworkId) != c.networks.end();
  if (on_sim) cc.env["CYCLONEDDS_URI"] = CycloneUriFor(kSimInterface);  // sim sorts first: eth0
  for (const auto& [k, v] : c.env) cc.env[k] = v;  // the trial's env wins
  ConfineUser(b.spec.limits, &cc);  // the trial's (physics: {limits} is the server's own)
  cc.artifacts = c.collect;
  cc.artifacts_dir = std::string(kComponentsDir) + "/" + c.name;
  if (c.networks.empty()) {
    cc.no_network = true;
  } else {
    cc.hostname = c.name;
  }
  return cc;
}

// The trial's components, each at the level of its priority.
Status AddComponents(TreeBuilder& b, const RunLevels& levels) {
  for (const dsl::UserComponentSpec& c : b.spec.components) {
    auto& plugin = b.trial.Add<dsl::Plugin>(c.name, ComponentContainer(b, c), levels.of_component.at(c.priority));
    for (const std::string& n : c.networks) {
      if (n == kSimNetworkId) {
        plugin.On(*b.sim_net, b.nets.sim.Host(b.next_sim_host++), {c.name});
      } else if (b.mesh_net != nullptr) {
        plugin.On(*b.mesh_net, b.nets.mesh.Host(b.next_mesh_host++), {c.name});
      } else {
        return Error(ErrorCode::kInvalidArgument,
                     "component " + c.name + " joins mesh, which only a radio.model netem trial has", c.mark.ToString());
      }
    }
    if (!c.ready.empty()) plugin.ReadyOn(c.ready, dsl::Duration::Seconds(kComponentReadySeconds));
  }
  return Ok{};
}

// With network faults, each agent lives in its fault sidecar's network namespace (sidecars, then
// the injector's set-up step, then the agents).
void AddFaultSidecars(TreeBuilder& b, const RunLevels& levels) {
  auto& radios = b.trial.Add<dsl::Component>(std::string(kSidecarsGroupId), levels.sidecars);
  std::uint32_t host = kFirstDroneHost;
  for (const dsl::DroneSpec& d : b.spec.drones) {
    const std::string id = SidecarId(d.name);
    dsl::ContainerSpec sc = dsl::ContainerSpec::Image(b.options.faults_image, SidecarArgv());
    sc.name = b.Name(id);
    sc.hostname = d.name;
    sc.labels = b.Labels(id);
    sc.env = b.RunEnv();
    // tc and iptables-nft talk netlink: NET_ADMIN alone (no NET_RAW: the fault e2e test runs
    // both with just this); no-new-privileges holds, as root keeps its set across exec.
    sc.cap_drop = {"ALL"};
    sc.cap_add = {"NET_ADMIN"};
    sc.no_new_privileges = true;
    sc.user = "0:0";  // NET_ADMIN reaches no non-root user on Docker 20.10 (standard_images.hpp)
    sc.stop_timeout_s = 2;
    radios.Add<dsl::Plugin>(id, std::move(sc), levels.sidecars)
        .On(*b.sim_net, b.nets.sim.Host(host), {d.name})
        .On(*b.mesh_net, b.nets.mesh.Host(host), {d.name});
    ++host;
  }
  b.trial.Add<dsl::Step>(std::string(kFaultsStepId), levels.faults);
}

// One agent per drone: in its sidecar's namespace when there are sidecars, else on the networks.
void AddDrones(TreeBuilder& b, int level, bool sidecars) {
  auto& drones = b.trial.Add<dsl::Component>(std::string(kDronesGroupId), level);
  std::uint32_t host = kFirstDroneHost;
  for (const dsl::DroneSpec& d : b.spec.drones) {
    const std::string sim_ip = b.nets.sim.Host(host);
    const std::string mesh_ip = b.nets.mesh.Host(host);
    ++host;
    const auto own_agent = b.options.images.drone_agents.find(d.name);
    dsl::ContainerSpec agent = dsl::ContainerSpec::Image(
        own_agent != b.options.images.drone_agents.end() ? own_agent->second : b.options.images.agent,
        AgentArgv(b.spec, d));
    agent.name = b.Name(d.name);
    agent.labels = b.Labels(d.name);
    agent.env = b.RunEnv();
    agent.inputs = {b.world_input, b.Input(AirframeRelative(d))};
    agent.scratch_dirs = {std::string(kAgentStateDir)};
    Confine(b.spec.LimitsOf(&d), &agent);
    if (sidecars) {
      agent.network_of = SidecarId(d.name);  // Docker refuses a hostname here
      drones.Add<dsl::Plugin>(d.name, std::move(agent), level);
    } else {
      agent.hostname = d.name;
      auto& plugin = drones.Add<dsl::Plugin>(d.name, std::move(agent), level).On(*b.sim_net, sim_ip, {d.name});
      if (b.mesh_net != nullptr) plugin.On(*b.mesh_net, mesh_ip, {d.name});
    }
  }
}

void SetEndAndTimeout(const dsl::TrialSpec& spec, dsl::Trial& trial) {
  for (const dsl::EndSpec& e : spec.end) trial.EndOn(e.on, e.outcome, e.reason, e.from);
  dsl::TimeoutPolicy timeout = dsl::TimeoutPolicy::Sim(
      spec.timeout.sim, spec.timeout.wall.zero() ? DefaultWallGuard(spec) : spec.timeout.wall,
      std::string(kPhysicsId));
  timeout.outcome = spec.timeout.outcome;
  trial.SetTimeout(timeout);
}

}  // namespace

Result<std::unique_ptr<dsl::Trial>> PlanTrial(const dsl::TrialSpec& spec,
                                              const PlanOptions& options) {
  SWARMBOX_TRY(CheckPlanOptions(spec, options));
  const bool sidecars = NeedsFaultSidecars(spec) && !options.faults_image.empty();
  SWARMBOX_TRY(CheckImagesAndAddresses(spec, options));
  auto levels = PlanRunLevels(spec, sidecars);
  if (!levels) return levels.error();
  auto trial = std::make_unique<dsl::Trial>(spec.name, options.run_id);
  TreeBuilder b{.spec = spec, .options = options, .nets = options.subnets,
                .trial_id = options.trial_id.empty() ? spec.name : options.trial_id, .trial = *trial};
  // The world every container reads: the trial's, or the derived one (world_size_m, generated).
  b.world_input = options.world_path.empty() ? b.Input(spec.world)
                                             : dsl::InputFile{options.world_path, InContainer(spec.world)};
  b.next_sim_host = kFirstDroneHost + static_cast<std::uint32_t>(spec.drones.size());
  b.next_mesh_host = b.next_sim_host;
  AddNetworks(b);
  AddPhysics(b, levels->physics);
  AddExternalBrains(b, levels->brains);
  SWARMBOX_TRY(AddComponents(b, *levels));
  if (sidecars) AddFaultSidecars(b, *levels);
  AddDrones(b, levels->drones, sidecars);
  SetEndAndTimeout(spec, *trial);
  return trial;
}

}  // namespace swarmbox::runner
