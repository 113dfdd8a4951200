// swarmbox-agent: one drone's companion computer. Thin: parses the command line, builds the
// AgentNode (agent_node.hpp) and runs it. Exit codes: 0 done or SIGTERM/SIGINT (see LeaveNow
// below), 1 the Raft storage failed (event=raft_stopped), 2 bad usage/config, 3 the bus or the
// physics server is not there.
//
// Raft on the mesh (raft_host.hpp) is on when --members lists the trial's drones (same list on
// every drone, including this one); off when absent:
//   swarmbox-agent --name drone_1 --airframe trials/airframes/x500.yaml --sim-domain 10
//       --mesh-domain 11 --members drone_1,drone_2,drone_3 --seed 7
//       [--raft-dir DIR]            WAL + snapshot; default /tmp/swarmbox-raft/<name>; reuse it
//                                   on restart so the node rejoins with its durable log
//       [--raft-tick-ms 50] [--raft-heartbeat-ms 100] [--raft-election-timeout-ms 500]
//       [--raft-voters a,b,c]       the voting set (same on every drone, a subset of --members);
//                                   the other members are learners (agent/raft/README.md);
//                                   absent: every member votes
//       [--propose-every-ms N]      diagnostic: the leader proposes the next demo mission command
//                                   every N ms (0 = never), until the mission layer does
// Every *-ms timing is on the radio's clock: simulated ms with --radio-model channel (the physics
// server's simulated channel carries the mesh traffic through the lockstep; no mesh DDS domain),
// wall ms with --radio-model netem (default: the mesh DDS domain, --mesh-domain/--mesh-interface).
// Raft events (event=leader_elected, mission_state, victim_confirmed, raft_stopped) are printed
// on stdout with the agent's simulated time `t`. The mesh domain must differ from the sim one.
//
// What it flies (mission_options.hpp): --mission plan (default) flies --plan; --mission sar flies
// the SAR mission (SarBrain, sar_brain.hpp, on the brain SDK) and needs --members and --world:
//       --mission sar --world trials/worlds/open_field.yaml [--payload stretcher]
//       [--inference-latency-ms 40]
//       [--mission-tuning '{"scout_altitude_m": 12}']   SarBrain's tuning numbers (sar_brain.hpp)
// Which brain flies (brain_options.hpp, agent/brain/README.md): --brain builtin (default: the
// --mission above), library or external:
//       --brain library --brain-library librendezvous.so --brain-name rendezvous
//       [--brain-args '{"altitude_m": 12}']   a JSON object: Context::args
//       --brain external                      a brain process on offboard/<name>/input|output
//       [--brain-rate-hz HZ]                  default: every step (250 Hz); external 50 Hz
//       [--offboard-timeout-ms 1000] [--offboard-hold-ms 5000]   simulated: hold, then land
//       [--brain-wait-ms 3000] [--brain-start-ms 30000]          external: wall-clock bounds
// --name, --members, --seed, --airframe, --world and --payload go into every brain's Context.
// A library that does not load, has another ABI, lacks the name (the names it has are listed) or
// whose constructor throws exits 2 with the reason.
// Usage errors (unknown flag, bad value, a bad combination) exit 2, as the rest of bad input.
// With --members, the radio link is measured (agent/radio): every --ping-every-ms (default 200,
// 0 = off) each agent pings --ping-peers (default 3) other members, round-robin, and logs
// event=link per sampled peer every 2 s (radio clock).
#include <CLI/CLI.hpp>

#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <optional>
#include <string>

#include "agent_node.hpp"
#include "mission_options.hpp"
#include "swarmbox/common/version.hpp"

namespace {
volatile std::sig_atomic_t g_stop = 0;
void OnSignal(int) { g_stop = 1; }

// Stopped by SIGTERM/SIGINT (a trial's end, a stop or restart fault): event=stopped is out and
// flushed. The process leaves without DDS's orderly goodbye. Deleting the participants announces
// each of the agent's endpoints' removal to every peer (the radio link alone has 2 writers per
// peer), so a swarm-wide stop costs O(N^2) messages on the cores the swarm shares: at 20 drones
// on 2 cores that took 0.5-0.7 s after the last event=stopped, against ~0.04 s for the processes'
// exit itself. Nothing is lost by leaving: logs are flushed line by line, every Raft WAL write is
// fsynced before its messages go out (leaving mid-write is the crash the WAL recovers from), and
// every QoS is keep-last, so a peer that stays up never blocks on this agent's readers; it drops
// them at the participant's lease expiry.
[[noreturn]] void LeaveNow() {
  std::fflush(stdout);
  std::fflush(stderr);
  std::_Exit(0);
}

namespace agent = swarmbox::agent;

// Exit codes (the banner above; ARCHITECTURE.md).
constexpr int kExitDone = 0;
constexpr int kExitRaftFailed = 1;
constexpr int kExitUsage = 2;
constexpr int kExitUnavailable = 3;

// The command line: the node's options, and the values that become options once parsed (their
// defaults are the help's).
struct CommandLine {
  agent::AgentOptions o;
  std::string start;
  double first_timeout_s = 10.0;
  double stall_timeout_s = 5.0;
  bool no_mesh = false;
  bool no_damping = false;
  std::string radio_model = "netem";
  std::string members;
  std::string voters;
  std::string mission_kind = "plan";
  std::string brain_kind = "builtin";
  bool mission_given = false;  // --mission on the command line
  bool plan_given = false;     // --plan on the command line
};

// The flags, in the help's order: the drone and its buses, the flight, Raft and the radio's probe
// (and the recording), the mission, the brain.
void AddBusOptions(CLI::App& app, CommandLine& c) {
  agent::AgentOptions& o = c.o;
  app.add_option("--name", o.name, "Drone name (as the physics server knows it)")->required();
  app.add_option("--airframe", o.airframe_path, "Airframe file (trials/airframes/*.yaml)")->required()->check(CLI::ExistingFile);
  app.add_option("--middleware", o.middleware, "DDS implementation")->check(CLI::IsMember({"cyclonedds", "fastdds"}))->capture_default_str();
  app.add_option("--sim-interface", o.sim_interface, "Network interface of the sim bus")->capture_default_str();
  app.add_option("--sim-domain", o.sim_domain, "DDS domain id of the sim bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_option("--sim-peer", o.sim_peers,
                 "Discover the sim bus by unicast to this host's participant 0 only (repeat: the physics server, "
                 "the brain); default: multicast");
  app.add_option("--mesh-interface", o.mesh_interface, "Network interface of the mesh (radio) bus")->capture_default_str();
  app.add_option("--mesh-domain", o.mesh_domain, "DDS domain id of the mesh bus")->check(CLI::Range(0, 232))->capture_default_str();
  app.add_flag("--no-mesh", c.no_mesh, "No radio: do not join the mesh bus (netem) nor send on the channel");
  app.add_option("--radio-model", c.radio_model, "How the drones talk: netem (the mesh DDS domain, wall clock) or channel (the physics server's simulated channel through the lockstep; no mesh domain, --mesh-* ignored)")->capture_default_str();
}

void AddFlightOptions(CLI::App& app, CommandLine& c) {
  agent::AgentOptions& o = c.o;
  app.add_option("--plan", o.plan, "Built-in flight plan: takeoff:H, hover:S, goto:X:Y:Z[:YAW_DEG], velocity:VX:VY:VZ:S, land")->capture_default_str();
  app.add_option("--preflight", o.preflight_s, "Simulated seconds on the ground before take-off")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--start", c.start, "Take-off spot x,y,z [m, ENU] (the trial's pose); default: first GPS fix");
  app.add_option("--payload-mass", o.payload_mass_kg, "Load carried at start [kg] (initial estimate)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--no-swing-damping", c.no_damping, "Disable slung-load swing damping");
  app.add_option("--sample-timeout,--first-sample-timeout", c.first_timeout_s, "Wall seconds to wait for the first sensor sample with no sign of the physics server (each sim/status message of its start begins the wait afresh)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--stall-timeout", c.stall_timeout_s, "Wall seconds without samples after which the run ends")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--exit-when-done", o.exit_when_done, "Exit as soon as the plan is complete");
}

void AddRaftOptions(CLI::App& app, CommandLine& c) {
  agent::AgentOptions& o = c.o;
  app.add_option("--members", c.members, "Raft: every drone of the trial, comma-separated (incl. this one); Raft is off when absent");
  app.add_option("--raft-voters", c.voters, "Raft: the voting set, comma-separated, a subset of --members (same on every drone); the others are learners. Default: every member votes");
  app.add_option("--raft-dir", o.raft.raft_dir, "Raft: WAL directory (default /tmp/swarmbox-raft/<name>)");
  app.add_option("--seed", o.raft.seed, "Raft: the trial's seed (election timeouts)")->capture_default_str();
  app.add_option("--raft-tick-ms", o.raft.tick_ms, "Raft: tick on the radio's clock (simulated ms with channel, wall ms with netem) [ms]")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--raft-heartbeat-ms", o.raft.heartbeat_ms, "Raft: heartbeat, a multiple of the tick [ms]")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--raft-election-timeout-ms", o.raft.election_timeout_ms, "Raft: election timeout, a multiple of the tick, > heartbeat [ms]")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--propose-every-ms", o.raft.propose_every_ms, "Raft diagnostic: the leader proposes a demo mission command every N ms (0 = never)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--ping-every-ms", o.ping_every_ms, "Radio: every N ms of the radio's clock (simulated with channel, wall with netem) ping --ping-peers other members and log event=link per sampled peer (needs --members; 0 = off)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--telemetry-hz", o.telemetry_hz, "Recording: publish this drone's telemetry (estimate, setpoint, flocking, Raft, links, sectors, detections, its log events) on sim/telemetry every 1/N simulated seconds; 0 = off. Nothing decides on it")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--ping-peers", o.ping_peers, "Radio: members pinged per --ping-every-ms round, round-robin (those heard in the last 5 s first, by name): the probe's cost is constant in the swarm's size")->check(CLI::PositiveNumber)->capture_default_str();
}

void AddMissionOptions(CLI::App& app, CommandLine& c) {
  agent::AgentOptions& o = c.o;
  app.add_option("--mission", c.mission_kind, "What to fly: plan (the built-in --plan) or sar (the SAR mission; needs --members and --world)")->capture_default_str();
  app.add_option("--world", o.mission.world_path, "SAR: the world file (only its geofence and home are read)");
  app.add_option("--payload", o.mission.payload, "SAR: this drone's airframe payload NAME lies on the ground under it (the lifter)");
  app.add_option("--inference-latency-ms", o.mission.inference_latency_ms, "SAR: simulated perception latency [ms]")->capture_default_str();
  app.add_option("--mission-tuning", o.mission.tuning_json, "SAR: the mission's tuning numbers, a JSON object, e.g. '{\"scout_altitude_m\": 12}'");
}

void AddBrainOptions(CLI::App& app, CommandLine& c) {
  agent::BrainOptions& b = c.o.brain;
  app.add_option("--brain", c.brain_kind, "Who flies: builtin (--mission), library (--brain-library/--brain-name) or external (a brain process on the offboard topics)")->capture_default_str();
  app.add_option("--brain-library", b.library_path, "library: the brain's shared library (.so)");
  app.add_option("--brain-name", b.name, "library: the SWARMBOX_BRAIN name in it");
  app.add_option("--brain-args", b.args_json, "The brain's arguments: a JSON object (Context::args)")->capture_default_str();
  app.add_option("--brain-rate-hz", b.rate_hz, "Brain steps per simulated second; a whole number of lockstep steps (default: every step; external: 50)")->check(CLI::PositiveNumber);
  app.add_option("--offboard-timeout-ms", b.offboard_timeout_ms, "Offboard failsafe: simulated ms without an answer before the drone holds")->capture_default_str();
  app.add_option("--offboard-hold-ms", b.offboard_hold_ms, "Offboard failsafe: simulated ms of holding before it lands")->capture_default_str();
  app.add_option("--brain-wait-ms", b.wait_ms, "external: wall-clock ms to wait for an answer before event=brain_unresponsive")->capture_default_str();
  app.add_option("--brain-start-ms", b.start_ms, "external: wall-clock ms to wait for the first answer")->capture_default_str();
  app.add_option("--brain-neighbours", b.neighbours, "Input::neighbours holds at most N other drones: the nearest (chosen every 200 ms), sorted by name; drones silent 3 s are dropped")->check(CLI::PositiveNumber)->capture_default_str();
}

// Parses argv into `c`. An exit code when the program ends here: --help and --version (0, CLI11's
// output), bad usage (2, not CLI11's own codes).
std::optional<int> ParseCommandLine(int argc, char** argv, CommandLine& c) {
  CLI::App app{"swarmbox-agent: one drone's flight stack on the SwarmBox bus (lockstep with swarmbox-physics)"};
  app.set_version_flag("--version", swarmbox::VersionLine("swarmbox-agent"),
                       "Print the version, git commit and build type, and exit");
  AddBusOptions(app, c);
  AddFlightOptions(app, c);
  AddRaftOptions(app, c);
  AddMissionOptions(app, c);
  AddBrainOptions(app, c);
  try {
    app.parse(argc, argv);
  } catch (const CLI::CallForHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForAllHelp& e) {
    return app.exit(e);
  } catch (const CLI::CallForVersion& e) {
    return app.exit(e);
  } catch (const CLI::ParseError& e) {
    (void)app.exit(e);  // prints the message and the usage hint
    return kExitUsage;  // bad usage (ARCHITECTURE.md exit codes), not CLI11's own codes
  }
  c.mission_given = app.count("--mission") > 0;
  c.plan_given = app.count("--plan") > 0;
  return std::nullopt;
}

// --start x,y,z [m].
swarmbox::Status ResolveStart(const std::string& start, agent::AgentOptions& o) {
  if (start.empty()) return swarmbox::Ok{};
  double x = 0, y = 0, z = 0;
  char tail = 0;
  if (std::sscanf(start.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3) {
    return swarmbox::Error(swarmbox::ErrorCode::kInvalidArgument, "--start '" + start + "': expected x,y,z in metres");
  }
  o.has_start = true;
  o.start_m = swarmbox::flight::Vec3(x, y, z);
  return swarmbox::Ok{};
}

// --members, --raft-voters and --raft-dir's default.
swarmbox::Status ResolveRaft(const CommandLine& c, agent::AgentOptions& o) {
  if (c.members.empty()) return swarmbox::Ok{};
  auto list = agent::ParseMembers(c.members, o.name);
  if (!list) return list.error();
  o.raft.members = std::move(*list);
  if (!c.voters.empty()) {
    auto voting = agent::ParseVoters(c.voters, o.raft.members);
    if (!voting) return voting.error();
    o.raft.voters = std::move(*voting);
  }
  if (o.raft.raft_dir.empty()) o.raft.raft_dir = agent::DefaultRaftDir(o.name);
  return swarmbox::Ok{};
}

// --radio-model, --mission and --brain, and their combinations with the other flags.
swarmbox::Status ResolveKinds(const CommandLine& c, agent::AgentOptions& o) {
  auto model = agent::ParseRadioModel(c.radio_model);
  if (!model) return model.error();
  o.radio_model = *model;
  auto mission = agent::ParseMissionKind(c.mission_kind);
  if (!mission) return mission.error();
  o.mission.kind = *mission;
  auto brain = agent::ParseBrainKind(c.brain_kind);
  if (!brain) return brain.error();
  o.brain.kind = *brain;
  SWARMBOX_TRY(agent::ValidateBrainOptions(o.brain, c.mission_given, c.plan_given));
  // --world and --payload are the SAR mission's with the builtin brain, any brain's Context otherwise.
  if (o.brain.kind == agent::BrainKind::kBuiltin) {
    SWARMBOX_TRY(agent::ValidateMissionOptions(o.mission, !o.raft.members.empty(), c.plan_given));
  } else if (!o.mission.tuning_json.empty()) {
    return swarmbox::Error(swarmbox::ErrorCode::kInvalidArgument, "--mission-tuning is for --mission sar (--brain builtin)");
  } else if (!o.mission.world_path.empty() && !std::filesystem::is_regular_file(o.mission.world_path)) {
    return swarmbox::Error(swarmbox::ErrorCode::kInvalidArgument, "--world '" + o.mission.world_path + "': no such file");
  }
  return swarmbox::Ok{};
}

// The node's options from the parsed command line, in the order of their checks; the first
// problem is the error (bad usage).
swarmbox::Status ResolveOptions(CommandLine& c) {
  agent::AgentOptions& o = c.o;
  o.mesh = !c.no_mesh;
  o.swing_damping = !c.no_damping;
  o.first_sample_timeout = std::chrono::milliseconds(static_cast<long>(c.first_timeout_s * 1000.0));
  o.stall_timeout = std::chrono::milliseconds(static_cast<long>(c.stall_timeout_s * 1000.0));
  SWARMBOX_TRY(ResolveStart(c.start, o));
  SWARMBOX_TRY(ResolveRaft(c, o));
  return ResolveKinds(c, o);
}

// Builds the node and runs it until its end or SIGTERM/SIGINT; the exit code.
int RunNode(agent::AgentOptions& o) {
  o.stop = &g_stop;
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  auto node = agent::AgentNode::Create(o);
  if (!node) {
    std::fprintf(stderr, "swarmbox-agent: %s\n", node.error().ToString().c_str());
    return node.error().code() == swarmbox::ErrorCode::kInvalidArgument ||
                   node.error().code() == swarmbox::ErrorCode::kNotFound
               ? kExitUsage
               : kExitUnavailable;
  }
  swarmbox::Status s = (*node)->Run();
  if (!s) {
    std::printf("%s\n", swarmbox::LogEvent(0.0, o.name, "error").Add("reason", s.error().ToString()).str().c_str());
    std::fprintf(stderr, "swarmbox-agent: %s\n", s.error().ToString().c_str());
    return (*node)->raft_failed() ? kExitRaftFailed : kExitUnavailable;
  }
  if (g_stop != 0) LeaveNow();
  return kExitDone;
}

}  // namespace

int main(int argc, char** argv) {
  CommandLine command_line;
  if (std::optional<int> exit_code = ParseCommandLine(argc, argv, command_line)) return *exit_code;
  if (swarmbox::Status s = ResolveOptions(command_line); !s) {
    std::fprintf(stderr, "swarmbox-agent: %s\n", s.error().ToString().c_str());
    return kExitUsage;
  }
  return RunNode(command_line.o);
}
