// TrialSpec: the trial model, what a trial file says (ARCHITECTURE.md "A trial description").
//
// The YAML format and the C++ builder below produce the same value; the runner turns it into a
// component tree (swarmbox::runner::PlanTrial). The builder reads like the file:
//
//   TrialSpec t = TrialSpec::Named("sar-search")
//                     .Seed(42)
//                     .World("worlds/open_field.yaml")
//                     .Drone("scout_1", "x500", {0, 0, 0})
//                     .Drone("lifter", "x8_heavy", {0, -10, 0}, "stretcher")
//                     .Mission({.kind = MissionKind::kSar})
//                     .Mesh("{delay_ms: 100, jitter_ms: 20, loss: 0.05}")
//                     .Fault("{at: 30s, kill: raft_leader}")
//                     .EndOn("event=mission_complete", Outcome::kSuccess)
//                     .EndOn("event=collision", Outcome::kFailure, "collision")
//                     .Timeout(Duration::Minutes(10));
//   t.Brain("scout_1", BrainSpec::Library("/abs/librendezvous.so", "rendezvous"))
//    .Component(UserComponentSpec::Program("ground", "/abs/ground_station"));
//
// Faults: the `faults:` list is parsed and checked by swarmbox_faults (faults::ParseFaults, the
// fault injector's own schema: at/at_wall/on, duration, kill/stop/pause/restart/radio/partition/
// gps_dropout/gps_degrade/imu_bias/wind_gust, targets) and carried out by the fault injector.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/duration.hpp"
#include "swarmbox/dsl/outcome.hpp"
#include "swarmbox/faults/fault_spec.hpp"
#include "swarmbox/faults/netem_spec.hpp"
#include "swarmbox/dsl/user_software.hpp"
#include "swarmbox/worlds/generator.hpp"

namespace swarmbox::dsl {

enum class Middleware { kCycloneDds, kFastDds };
std::string_view MiddlewareName(Middleware middleware);  // "cyclonedds", "fastdds"

// Per-container limits (`limits: {memory_mib, pids}`), Docker's HostConfig.Memory and PidsLimit.
// The trial's apply to every agent and the physics server; a drone's own `limits:` (and
// `physics: {limits: ...}`) overrides single keys: 0 there = the trial's value. A container over
// its memory limit is OOM-killed, and the trial fails saying so (result.json's oom_killed).
struct ContainerLimits {
  int memory_mib = 0;  // [MiB], >= 6 (Docker's minimum)
  int pids = 0;        // processes and threads, >= 16
};
// Measured on trials/sar_search.yaml (4 drones, rtf 0, 232 simulated s; cgroup v1 peaks): an
// agent peaks at 10-11 MiB (9-10 MiB RSS) and 18 tasks, the physics server at 98 MiB with page
// cache (47 MiB RSS) and 9 tasks. The defaults leave 5x (physics) to 50x (agents) in memory and
// 14x in tasks for bigger worlds and swarms (DDS's buffers grow with the peers).
inline constexpr ContainerLimits kDefaultLimits{512, 256};

struct DroneSpec {
  std::string name;                 // [a-z][a-z0-9_]*, unique in the trial
  std::string airframe;             // trials/airframes/<airframe>.yaml
  std::array<double, 3> pose{};     // start position [m], world frame (x east, y north, z up)
  std::string payload;              // "" = none
  ContainerLimits limits;           // overrides of the trial's `limits:` (0 = the trial's)
  yaml::Mark mark;                  // where the drone was declared
  BrainSpec brain;                  // what flies it (`brain:`; builtin = `mission:`)
};

struct EndSpec {
  std::string on;                      // regex on a log line (see dsl::EndCondition)
  Outcome outcome = Outcome::kSuccess;
  std::string reason;                  // "" = the pattern
  std::string from;                    // a component ("physics", a drone); "" = any
};

// What the agents fly (`mission:`). kSar: the SAR mission (agents need the world file and their
// peers); kPlan: every agent flies the built-in flight plan `plan` (the demo, smoke tests).
enum class MissionKind { kSar, kPlan };
std::string_view MissionKindName(MissionKind kind);  // "sar", "plan"

inline constexpr std::string_view kDefaultFlightPlan = "takeoff:5,hover:10,land";

struct MissionSpec {
  MissionKind kind = MissionKind::kSar;
  std::string plan = std::string(kDefaultFlightPlan);  // kind plan only
  int inference_latency_ms = 40;                       // simulated perception latency [ms], >= 0
  // kind sar only: the SAR mission's tuning numbers by name (`tuning: {scout_altitude_m: 12}`), a
  // mapping of plain numbers in the order written; null = the mission's defaults. Which names
  // exist is the agent's to say (SarTuningKeys, agent/app/sar_brain.hpp: an unknown one stops the
  // agent with the known ones); the loader checks the shape and refuses `start` (the drone's pose).
  yaml::Node tuning = yaml::Node();  // initialised: {kind, plan, latency} need not name it (-Wextra)

  // The tuning as a JSON object (yaml::EmitJson), what the agent's --mission-tuning takes; "" when
  // there is none (null or an empty mapping).
  std::string TuningJson() const;
};

// Raft timings of every agent (`raft:`), on wall-clock time. The defaults are chosen to stay stable
// on the sar_search radio (100 ms +- 20 ms one-way, 5% loss), following etcd's guidance (heartbeat
// about the round-trip time, election timeout several heartbeats):
//   heartbeat 200 ms   = the round trip (2 x 100 ms), so followers hear the leader every RTT;
//   election  1500 ms  = 7.5 heartbeats: a follower campaigns only after ~7 heartbeats in a row were
//                        lost or late (0.05^7 ~ 8e-10 per window at 5% loss; the worst one-way delay,
//                        ~160 ms at 3 sigma, is far below it), while failover stays ~1.5-3 s
//                        (timeouts randomised in [T, 2T)).
//   tick 50 ms         the service's resolution; both timings must be multiples of it.
// `voters` (default 5): the size of the voting set at swarm scale, the first `voters` drones in
// trial order (the runner's --raft-voters); every other drone is a Raft learner (follows the
// mission log, never votes; agent/raft/README.md). 0, or at least the drone count: every drone
// votes (as in trials of up to 5 drones).
struct RaftSpec {
  int tick_ms = 50;
  int heartbeat_ms = 200;
  int election_timeout_ms = 1500;
  int voters = 5;
};

// The radio between drones (`radio:`, ARCHITECTURE.md "Two networks per trial, two radio models"):
//   model channel  the simulated channel next to the physics world, on simulated time (default):
//                  no mesh network and no fault sidecars; network.mesh, radio faults and
//                  partitions at simulated times go to the physics server in the radio plan
//                  (runner/radio_schedule.hpp);
//   model netem    the real stack over the `mesh` Docker network, impaired from fault sidecars,
//                  on the wall clock (meaningful at rtf 1 only).
// `profile`: the channel's radio profile, a name (trials/radios/<NAME>.yaml) or a path relative to
// the trials directory ending in .yaml (RadioProfileFile). Every ping_every_ms (0 = off; simulated
// ms with channel, wall ms with netem) each agent pings ping_peers (>= 1) of its peers, round-robin
// (agent/radio LinkProbe), and logs event=link lines per sampled peer.
enum class RadioModel { kChannel, kNetem };
std::string_view RadioModelName(RadioModel model);  // "channel", "netem"
inline constexpr std::string_view kDefaultRadioProfile = "wifi_5ghz_mesh";

struct RadioLinkSpec {
  int ping_every_ms = 200;
  int ping_peers = 3;
  RadioModel model = RadioModel::kChannel;
  std::string profile = std::string(kDefaultRadioProfile);
};
// The profile's file relative to the trials directory: "radios/<name>.yaml" for a name, the path
// itself for a path (it has a '/' or ends in ".yaml").
std::string RadioProfileFile(const RadioLinkSpec& radio);

// `record:` the trial's recording, RUN_DIR/.../recording.mcap (ARCHITECTURE.md "Recordings"),
// written by the physics server: true poses every 1/rate_hz simulated s (and the agents' telemetry
// at the same rate), camera frames at camera_hz per drone scaled by camera_scale and JPEG-encoded
// at jpeg_quality. `swarmbox run --no-record` turns it off as `enabled: false` does.
struct RecordSpec {
  bool enabled = true;
  double rate_hz = 10.0;      // > 0, at most 250 (the lockstep rate)
  double camera_hz = 1.0;     // >= 0 (0: no camera channel)
  double camera_scale = 0.5;  // (0, 1]
  int jpeg_quality = 75;      // [1, 100]
};

struct TimeoutSpec {
  Duration sim;                         // simulated time; zero = none
  Duration wall;                        // wall-clock guard; zero = derived from sim and rtf
  Outcome outcome = Outcome::kTimeout;  // what running out of simulated time means
};

// A `drones:` item with `count:` (drone_groups.hpp), as written: its drones are in
// TrialSpec::drones already (<name>_1 .. <name>_<count>).
struct DroneGroup {
  std::string name;
  int count = 0;
};

struct TrialSpec {
  std::string name;  // [a-z0-9][a-z0-9_.-]*, at most 40 characters; used in folder/Docker names
  std::uint64_t seed = 0;
  Middleware middleware = Middleware::kCycloneDds;
  std::string world;  // relative to the trials directory (generated: worlds/generated_<kind>.yaml, no file)
  // `world: {generate: ...}` (worlds/generator.hpp): the runner generates the world (seeded by the
  // trial seed unless the recipe gives one) and writes it as the derived world, as world_size_m.
  std::optional<worlds::GenerateSpec> world_generate;
  // `world_size_m: [X, Y]`: the world's geofence set to X x Y m (the SAR search area); {0, 0} = the
  // world file's own. The runner writes the derived world into the trial folder and every container
  // reads that one (runner/derived_world.hpp).
  std::array<double, 2> world_size_m{};
  double rtf = 1.0;   // real-time factor, 0 = as fast as possible
  std::vector<DroneSpec> drones;  // groups expanded, in file order
  std::vector<DroneGroup> groups;  // the groups they came from (for summaries)
  MissionSpec mission;
  RaftSpec raft;
  RadioLinkSpec radio;
  RecordSpec record;
  faults::MeshImpairment mesh;  // network.mesh, parsed by swarmbox_faults (tc netem semantics)
  yaml::Node mesh_node;         // network.mesh as written (null = an unimpaired radio)
  std::vector<faults::Fault> faults;
  yaml::Node faults_node;  // the `faults:` list as written (null = none)
  std::vector<EndSpec> end;
  TimeoutSpec timeout;
  ContainerLimits limits = kDefaultLimits;  // every agent and the physics server
  ContainerLimits physics_limits;           // physics.limits: overrides (0 = the trial's)
  std::vector<UserComponentSpec> components;  // `components:` (user_software.hpp)

  std::string trials_dir;  // where world and airframe references resolve ("" = not checked)
  yaml::Node document;     // the resolved description (after --set), written as trial.yaml

  // --- the C++ builder ---
  static TrialSpec Named(std::string name);
  TrialSpec& Seed(std::uint64_t seed);
  TrialSpec& Using(Middleware middleware);
  TrialSpec& World(std::string world);
  TrialSpec& WorldSize(double x_m, double y_m);
  TrialSpec& Rtf(double rtf);
  TrialSpec& Drone(std::string name, std::string airframe, std::array<double, 3> pose,
                   std::string payload = {});
  // network.mesh in flow syntax, e.g. "{delay_ms: 100, jitter_ms: 20, loss: 0.05}". Aborts with
  // the parser's message on a malformed literal (a bug in the calling code).
  TrialSpec& Mesh(std::string_view flow_yaml);
  // One fault in the trial file's flow syntax, e.g. "{at: 30s, kill: raft_leader}". Aborts with
  // the parser's message on a malformed literal (a bug in the calling code).
  TrialSpec& Fault(std::string_view flow_yaml);
  TrialSpec& EndOn(std::string pattern, Outcome outcome, std::string reason = {},
                   std::string from = {});
  TrialSpec& Mission(MissionSpec value);
  TrialSpec& Raft(RaftSpec value);
  TrialSpec& Radio(RadioLinkSpec value);
  TrialSpec& Record(RecordSpec value);
  TrialSpec& Timeout(Duration sim, Outcome outcome = Outcome::kTimeout, Duration wall = {});

  TrialSpec& Limits(ContainerLimits value);
  // The brain of a drone added before (aborts naming the drone when there is none: a bug in the
  // calling code). Paths are taken as given (relative ones against the working directory).
  TrialSpec& Brain(std::string_view drone_name, BrainSpec brain);
  // One more `components:` entry (checked when the trial is planned or validated).
  TrialSpec& Component(UserComponentSpec component);

  const DroneSpec* FindDrone(std::string_view drone_name) const;
  const UserComponentSpec* FindComponent(std::string_view component_name) const;
  bool HasExternalBrain() const;
  bool HasWorldSize() const { return world_size_m[0] > 0 && world_size_m[1] > 0; }
  // Whether every container reads a world the runner writes (world_size_m or a generated world).
  bool HasDerivedWorld() const { return HasWorldSize() || world_generate.has_value(); }
  // The limits a container runs with: the drone's (nullptr = the physics server's) overrides over
  // the trial's.
  ContainerLimits LimitsOf(const DroneSpec* drone) const;
};

// The YAML document of a spec (what LoadTrial would read back to an equal spec).
yaml::Node ToDocument(const TrialSpec& spec);

}  // namespace swarmbox::dsl
