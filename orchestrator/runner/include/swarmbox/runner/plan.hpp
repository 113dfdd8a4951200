// PlanTrial: a TrialSpec -> the component tree of networks and containers it runs as.
//
// THE one place that maps a trial to containers: names, labels, subnets and fixed addresses, the
// images, and each program's command line (swarmbox-physics, swarmbox-agent). When a program's
// flags change, change PhysicsArgv()/AgentArgv() in plan.cpp and nothing else.
//
// Tree (run priority in brackets), radio.model channel (the default):
//   Trial <name>
//     Network sim [0]   physics <-> agents, never impaired; the channel's radio frames ride it
//     Plugin physics [1]  + --radio-model channel --radio-profile /swarmbox/trials/radios/<p>.yaml
//                         --radio-plan /swarmbox/radio_plan.json (both copied in as inputs)
//     Component drones [2]
//       Plugin <drone> [2]  one agent per drone, on sim (eth0) only, --radio-model channel
// radio.model netem (the real stack, as before the channel):
//   Trial <name>
//     Network sim [0]   physics <-> agents, never impaired
//     Network mesh [0]  agent <-> agent radio (netem applies here, fault injector's business)
//     Plugin physics [1]  ready on `event=ready`; collects truth.csv; stops itself at the
//                         trial's simulated timeout (--max-sim-time) with `event=stopped t=...`
//     Component drones [2]
//       Plugin <drone> [2]  one agent per drone, on sim (eth0) and mesh (eth1)
// Drones with an external brain (drones[].brain program/dockerfile/image) get its container first:
//     Component brains [after physics, before the drones]
//       Plugin <drone>-brain   on sim, role=brain, argv --drone --domain --members + the brain's
//                              args, CYCLONEDDS_URI bound to eth0 (the agents' sim domain)
// and the agent runs --brain external; a library brain runs in the agent (--brain library, the
// library at /swarmbox/brains/<basename> in an agent image packed with it). The trial's
// `components:` are Plugins <name> (role=component) at levels by their priority: below
// kDronesPriority before the physics server, equal with the drones, above after them.
// With network faults (network.mesh, radio or partition faults: NeedsFaultSidecars), instead:
//     Component sidecars [2]
//       Plugin <drone>-faults [2]  the fault sidecar (fault-tools image + swarmbox-netemd, CapDrop
//                                  ALL, CapAdd NET_ADMIN): owns the drone's network namespace
//                                  (sim eth0 + mesh eth1, the drone's fixed addresses)
//     Step faults [3]      bound by the runner to the FaultInjector: mechanism, network.mesh
//     Component drones [4]
//       Plugin <drone> [2]  the agent, in its sidecar's namespace (network_of), unprivileged
// Agents and physics: CapDrop ALL, no-new-privileges, read-only root filesystem (a volume at
// /swarmbox, a tmpfs at /tmp), memory and pids limits from the trial's `limits:` (LimitsOf).
// Agent flags: the shared contract (mission, --members in trial order, --seed, --raft-*, radio).
// Files: the world and airframe files are copied into every container under /swarmbox/trials/
// (same relative paths as in the trials folder); with world_size_m the world copied is the derived
// one (PlanOptions::world_path) at the world's path.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/dsl/trial.hpp"
#include "swarmbox/dsl/trial_spec.hpp"
#include "swarmbox/faults/physics_plan.hpp"
#include "swarmbox/runner/subnets.hpp"

namespace swarmbox::runner {

struct Images {
  // Images{physics, agent}: the two every trial runs (the rest are filled by their makers).
  Images(std::string physics_image = {}, std::string agent_image = {})  // NOLINT(google-explicit-constructor)
      : physics(std::move(physics_image)), agent(std::move(agent_image)) {}
  std::string physics;  // "swarmbox/physics:<content hash>"
  std::string agent;    // "swarmbox/agent:<content hash>"
  // The trial's own software (user_images.hpp makes them): per drone with a library brain, the
  // agent image with that library at kBrainsDir/<basename>; per drone with an external brain, the
  // brain's image; per component, its image. PlanTrial fails naming what is missing.
  std::map<std::string, std::string> drone_agents;
  std::map<std::string, std::string> brains;
  std::map<std::string, std::string> components;
};

// `swarmbox run --view [ADDR:PORT]`: the physics server's live view (record::LiveServer on
// 0.0.0.0:kViewContainerPort in its container) published on the host at host_ip:host_port.
inline constexpr int kViewContainerPort = 8765;
struct ViewBinding {
  std::string host_ip = "127.0.0.1";
  int host_port = kViewContainerPort;
  std::string url() const { return "http://" + host_ip + ":" + std::to_string(host_port) + "/"; }
};
// "ADDR:PORT", "ADDR" (port 8765) or "" (127.0.0.1:8765); ADDR an IPv4 address, PORT 1..65535.
// kInvalidArgument saying what is expected otherwise.
Result<ViewBinding> ParseViewAddress(std::string_view text);

struct PlanOptions {
  std::string run_id;
  std::string trial_id;  // "" = the trial's name
  Images images;
  // The fault sidecar image ("swarmbox/faults:<content hash>", with swarmbox-netemd: fault_image.hpp).
  // "" plans no sidecars even when the trial impairs the mesh (what `swarmbox compose` exports:
  // compose carries out no faults); the runner always passes it for such trials.
  std::string faults_image;
  TrialSubnets subnets;
  std::string trials_dir;  // absolute host path the spec's references resolve against
  // radio.model channel: the radio plan JSON on the host (radio_schedule.hpp; the runner writes it
  // into the trial folder), copied to kRadioPlanPath and passed as --radio-plan. "" = none (the
  // physics server then runs the channel with no mesh impairment and no scheduled faults).
  std::string radio_plan_path;
  // world_size_m: the derived world on the host (derived_world.hpp; the runner writes it into the
  // trial folder), copied in where the trial's world would be, so every container reads it.
  // "" = the trial's world file from trials_dir.
  std::string world_path;
  // swarmbox run --view: the physics server serves the live view, published on the host here.
  std::optional<ViewBinding> view;
};

// The shortest text that reads back as `v` (std::to_chars): numbers in argv and derived files.
std::string ShortestNumber(double v);

inline constexpr std::string_view kPhysicsId = "physics";
inline constexpr std::string_view kDronesGroupId = "drones";
inline constexpr std::string_view kSimNetworkId = "sim";
inline constexpr std::string_view kMeshNetworkId = "mesh";
// Agents and the physics server run with a read-only root filesystem: all they write goes to an
// anonymous volume at /swarmbox (the input files, truth.csv, the Raft WAL: it survives a restart
// fault and is readable after the stop, unlike a tmpfs) or to a small tmpfs at /tmp (scratch).
inline constexpr std::string_view kContainerVolumeDir = "/swarmbox";
inline constexpr std::string_view kContainerTrialsDir = "/swarmbox/trials";
inline constexpr std::string_view kContainerOutDir = "/swarmbox/out";
inline constexpr std::string_view kTruthCsvPath = "/swarmbox/out/truth.csv";
// The recording (record:, ARCHITECTURE.md "Recordings"), collected into the trial folder.
inline constexpr std::string_view kRecordingPath = "/swarmbox/out/recording.mcap";
inline constexpr std::string_view kAgentStateDir = "/swarmbox/state";  // --raft-dir <it>/raft
inline constexpr std::string_view kRadioPlanPath = "/swarmbox/radio_plan.json";  // in physics
inline constexpr std::string_view kRadioPlanFile = "radio_plan.json";            // trial folder
inline constexpr std::string_view kScratchTmpfsDir = "/tmp";
inline constexpr std::int64_t kScratchTmpfsMib = 16;
inline constexpr std::string_view kPhysicsReadyPattern = "event=ready";
inline constexpr std::string_view kSidecarsGroupId = "sidecars";
inline constexpr std::string_view kBrainsGroupId = "brains";
// Where a library brain lies in the agent's image (and so in its container).
inline constexpr std::string_view kBrainsDir = "/swarmbox/brains";
// Where a packed program (external brain, component) lies in its image.
inline constexpr std::string_view kProgramDirInImage = "/usr/local/bin";
// A component's collected files: <trial folder>/components/<name>/<basename>.
inline constexpr std::string_view kComponentsDir = "components";
inline constexpr int kComponentReadySeconds = 60;  // as the physics server's readiness
// The agent's wall-clock bounds on an external brain (the contract's --brain-wait-ms and
// --brain-start-ms defaults): with an external brain the physics server waits longer than these
// for a step's answer (--step-timeout) and a first answer (--join-timeout), so the agent's own
// liveness rule decides, not the server's lost-drone rule.
inline constexpr int kAgentBrainWaitMs = 3000;
inline constexpr int kAgentBrainStartMs = 30000;
inline constexpr double kExternalBrainStepTimeoutS = kAgentBrainWaitMs / 1000.0 + 2.0;
inline constexpr double kExternalBrainJoinTimeoutS = kAgentBrainStartMs / 1000.0 + 15.0;
// With radio.model channel the physics server's lost-drone rule is only a liveness net: drones the
// trial takes out leave the lockstep at their simulated time (the radio plan), an agent that exits
// fails the trial through the runner (Monitor::ExitRule), so only a hung agent is left for it, and a
// wall-clock stall of a live agent on a loaded host must not drop it: 5 s did, once, for
// ReproducibleE2e's "cores busy" run while another e2e test ran on the same two cores (scout_1 lost
// at 4.2 s simulated), and 100 agents on two cores stall longer than 10. The server waits this long
// (its own default, 1 s, stays for netem trials, whose failover tests time the loss).
inline constexpr double kChannelStepTimeoutS = 30.0;
// How long an agent the runner starts waits for its first sample with no sign of the physics
// server at all (--sample-timeout; the agent's own default, 10 s, is for a hand-started agent).
// In a 40-100 drone start an agent's first discovery announcement can be lost in the start's
// burst of discovery traffic; Cyclone announces again every SPDPInterval (10 s,
// bus/cyclone_config.hpp), so 10 s of patience lost such agents (the 40-drone start of issue 18).
// The runner bounds the start itself (the server gives up a drone that has not answered
// --join-timeout after the latest join, and the trial then names the drones that did not join).
inline constexpr double kAgentStartPatienceS = 60.0;
// How long an agent the runner starts waits for its next sample once the lockstep has moved before
// it ends its run (--stall-timeout; the agent's own default is 5 s): a step waits for every drone,
// so on a loaded 2-core host a 100-drone server is starved for longer than a small fleet's (at load
// ~70, 101 agents and a second trial on the host, the three first drones' 5 s ran out at 4 simulated
// s, 2026-11-27). 5 s plus 0.15 s per drone: 6.5 s for 10 drones, 20 s for 100. The runner sees
// a dead server by its container's exit; this bound only keeps an agent from flying on without it.
double AgentStallTimeoutS(std::size_t drones);
// The external brain's container id: "<drone>-brain".
std::string BrainId(std::string_view drone);
// The brain container's DNS alias on sim, which its agent names with --sim-peer: "brain-scout-2"
// for scout_2 (the resolver refuses '_' in a host name, as "scout_2-brain" has; drone names have no
// '-', so the alias stays unique).
std::string BrainHostName(std::string_view drone);
// The CYCLONEDDS_URI an external brain or a component on sim gets: bus::CycloneXml on
// `interface` (multicast discovery and message sizes tuned for 100 participants; bus/README.md).
// participant_index 0 for an external brain: the well-known port its agent names (--sim-peer);
// -1 (none) for a component. A component discovers the physics server (which also hears
// multicast) and the brains, not the agents: they announce themselves to the server only.
std::string CycloneUriFor(std::string_view interface, int participant_index = -1);
inline constexpr std::string_view kFaultsStepId = "faults";
// The agents' interfaces in their (or their sidecar's) namespace.
inline constexpr std::string_view kSimInterfaceName = "eth0";
inline constexpr std::string_view kMeshInterfaceName = "eth1";

// The argv a sensor or environment fault execs in the physics container (the orchestrator links
// no DDS): swarmbox-physics --send-command <target|-> <command> <args...> on the sim bus the
// physics server runs on (PhysicsArgv's interface, domain and middleware).
std::vector<std::string> PhysicsCommandArgv(dsl::Middleware middleware, const faults::WorldCommandCall& call);

// Whether the trial impairs the mesh (network.mesh, radio or partition faults) with radio.model
// netem, so every agent gets a fault sidecar (the channel impairs in the physics server: never).
bool NeedsFaultSidecars(const dsl::TrialSpec& spec);
// The sidecar's component id: "<drone>-faults".
std::string SidecarId(std::string_view drone);

// The wall-clock guard when the trial file gives none: [s]. rtf > 0: sim/rtf * 1.5 + 120;
// rtf == 0 (as fast as possible): sim * 3 + 120.
dsl::Duration DefaultWallGuard(const dsl::TrialSpec& spec);

// Reads the masses of the trial's payloads from their airframe files (I/O), which also checks
// that each drone's airframe has its payload: kInvalidArgument at the drone's mark otherwise.
// Keys "<airframe>/<payload>", values [kg].
Result<std::map<std::string, double>> LoadPayloadMasses(const dsl::TrialSpec& spec,
                                                        const std::string& trials_dir);

// radio.model channel: that the radio profile file exists under trials_dir (I/O; the loader checks
// a profile the trial file names at its key, this also the default one). kInvalidArgument with
// the path otherwise. netem: Ok.
Status CheckRadioProfile(const dsl::TrialSpec& spec, const std::string& trials_dir);

Result<std::unique_ptr<dsl::Trial>> PlanTrial(const dsl::TrialSpec& spec,
                                              const PlanOptions& options);

}  // namespace swarmbox::runner
