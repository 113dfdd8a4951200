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
}  // namespace

int main(int argc, char** argv) {
  swarmbox::agent::AgentOptions o;
  CLI::App app{"swarmbox-agent: one drone's flight stack on the SwarmBox bus (lockstep with swarmbox-physics)"};
  std::string start;
  double first_timeout_s = 10.0, stall_timeout_s = 5.0;
  bool no_mesh = false, no_damping = false;
  app.set_version_flag("--version", swarmbox::VersionLine("swarmbox-agent"),
                       "Print the version, git commit and build type, and exit");
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
  app.add_flag("--no-mesh", no_mesh, "No radio: do not join the mesh bus (netem) nor send on the channel");
  std::string radio_model = "netem";
  app.add_option("--radio-model", radio_model, "How the drones talk: netem (the mesh DDS domain, wall clock) or channel (the physics server's simulated channel through the lockstep; no mesh domain, --mesh-* ignored)")->capture_default_str();
  app.add_option("--plan", o.plan, "Built-in flight plan: takeoff:H, hover:S, goto:X:Y:Z[:YAW_DEG], velocity:VX:VY:VZ:S, land")->capture_default_str();
  app.add_option("--preflight", o.preflight_s, "Simulated seconds on the ground before take-off")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--start", start, "Take-off spot x,y,z [m, ENU] (the trial's pose); default: first GPS fix");
  app.add_option("--payload-mass", o.payload_mass_kg, "Load carried at start [kg] (initial estimate)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_flag("--no-swing-damping", no_damping, "Disable slung-load swing damping");
  app.add_option("--sample-timeout,--first-sample-timeout", first_timeout_s, "Wall seconds to wait for the first sensor sample with no sign of the physics server (each sim/status message of its start begins the wait afresh)")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--stall-timeout", stall_timeout_s, "Wall seconds without samples after which the run ends")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_flag("--exit-when-done", o.exit_when_done, "Exit as soon as the plan is complete");
  std::string members;
  app.add_option("--members", members, "Raft: every drone of the trial, comma-separated (incl. this one); Raft is off when absent");
  std::string voters;
  app.add_option("--raft-voters", voters, "Raft: the voting set, comma-separated, a subset of --members (same on every drone); the others are learners. Default: every member votes");
  app.add_option("--raft-dir", o.raft.raft_dir, "Raft: WAL directory (default /tmp/swarmbox-raft/<name>)");
  app.add_option("--seed", o.raft.seed, "Raft: the trial's seed (election timeouts)")->capture_default_str();
  app.add_option("--raft-tick-ms", o.raft.tick_ms, "Raft: tick on the radio's clock (simulated ms with channel, wall ms with netem) [ms]")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--raft-heartbeat-ms", o.raft.heartbeat_ms, "Raft: heartbeat, a multiple of the tick [ms]")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--raft-election-timeout-ms", o.raft.election_timeout_ms, "Raft: election timeout, a multiple of the tick, > heartbeat [ms]")->check(CLI::PositiveNumber)->capture_default_str();
  app.add_option("--propose-every-ms", o.raft.propose_every_ms, "Raft diagnostic: the leader proposes a demo mission command every N ms (0 = never)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--ping-every-ms", o.ping_every_ms, "Radio: every N ms of the radio's clock (simulated with channel, wall with netem) ping --ping-peers other members and log event=link per sampled peer (needs --members; 0 = off)")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--telemetry-hz", o.telemetry_hz, "Recording: publish this drone's telemetry (estimate, setpoint, flocking, Raft, links, sectors, detections, its log events) on sim/telemetry every 1/N simulated seconds; 0 = off. Nothing decides on it")->check(CLI::NonNegativeNumber)->capture_default_str();
  app.add_option("--ping-peers", o.ping_peers, "Radio: members pinged per --ping-every-ms round, round-robin (those heard in the last 5 s first, by name): the probe's cost is constant in the swarm's size")->check(CLI::PositiveNumber)->capture_default_str();
  std::string mission_kind = "plan";
  app.add_option("--mission", mission_kind, "What to fly: plan (the built-in --plan) or sar (the SAR mission; needs --members and --world)")->capture_default_str();
  app.add_option("--world", o.mission.world_path, "SAR: the world file (only its geofence and home are read)");
  app.add_option("--payload", o.mission.payload, "SAR: this drone's airframe payload NAME lies on the ground under it (the lifter)");
  app.add_option("--inference-latency-ms", o.mission.inference_latency_ms, "SAR: simulated perception latency [ms]")->capture_default_str();
  std::string brain_kind = "builtin";
  app.add_option("--brain", brain_kind, "Who flies: builtin (--mission), library (--brain-library/--brain-name) or external (a brain process on the offboard topics)")->capture_default_str();
  app.add_option("--brain-library", o.brain.library_path, "library: the brain's shared library (.so)");
  app.add_option("--brain-name", o.brain.name, "library: the SWARMBOX_BRAIN name in it");
  app.add_option("--brain-args", o.brain.args_json, "The brain's arguments: a JSON object (Context::args)")->capture_default_str();
  app.add_option("--brain-rate-hz", o.brain.rate_hz, "Brain steps per simulated second; a whole number of lockstep steps (default: every step; external: 50)")->check(CLI::PositiveNumber);
  app.add_option("--offboard-timeout-ms", o.brain.offboard_timeout_ms, "Offboard failsafe: simulated ms without an answer before the drone holds")->capture_default_str();
  app.add_option("--offboard-hold-ms", o.brain.offboard_hold_ms, "Offboard failsafe: simulated ms of holding before it lands")->capture_default_str();
  app.add_option("--brain-wait-ms", o.brain.wait_ms, "external: wall-clock ms to wait for an answer before event=brain_unresponsive")->capture_default_str();
  app.add_option("--brain-start-ms", o.brain.start_ms, "external: wall-clock ms to wait for the first answer")->capture_default_str();
  app.add_option("--brain-neighbours", o.brain.neighbours, "Input::neighbours holds at most N other drones: the nearest (chosen every 200 ms), sorted by name; drones silent 3 s are dropped")->check(CLI::PositiveNumber)->capture_default_str();
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
    return 2;           // bad usage (ARCHITECTURE.md exit codes), not CLI11's own codes
  }

  o.mesh = !no_mesh;
  o.swing_damping = !no_damping;
  o.first_sample_timeout = std::chrono::milliseconds(static_cast<long>(first_timeout_s * 1000.0));
  o.stall_timeout = std::chrono::milliseconds(static_cast<long>(stall_timeout_s * 1000.0));
  if (!start.empty()) {
    double x = 0, y = 0, z = 0;
    char tail = 0;
    if (std::sscanf(start.c_str(), "%lf,%lf,%lf%c", &x, &y, &z, &tail) != 3) {
      std::fprintf(stderr, "swarmbox-agent: --start '%s': expected x,y,z in metres\n", start.c_str());
      return 2;
    }
    o.has_start = true;
    o.start_m = swarmbox::flight::Vec3(x, y, z);
  }
  if (!members.empty()) {
    auto list = swarmbox::agent::ParseMembers(members, o.name);
    if (!list) {
      std::fprintf(stderr, "swarmbox-agent: %s\n", list.error().ToString().c_str());
      return 2;
    }
    o.raft.members = std::move(*list);
    if (!voters.empty()) {
      auto voting = swarmbox::agent::ParseVoters(voters, o.raft.members);
      if (!voting) {
        std::fprintf(stderr, "swarmbox-agent: %s\n", voting.error().ToString().c_str());
        return 2;
      }
      o.raft.voters = std::move(*voting);
    }
    if (o.raft.raft_dir.empty()) o.raft.raft_dir = swarmbox::agent::DefaultRaftDir(o.name);
  }
  if (auto model = swarmbox::agent::ParseRadioModel(radio_model)) {
    o.radio_model = *model;
  } else {
    std::fprintf(stderr, "swarmbox-agent: %s\n", model.error().ToString().c_str());
    return 2;
  }
  if (auto kind = swarmbox::agent::ParseMissionKind(mission_kind)) {
    o.mission.kind = *kind;
  } else {
    std::fprintf(stderr, "swarmbox-agent: %s\n", kind.error().ToString().c_str());
    return 2;
  }
  if (auto kind = swarmbox::agent::ParseBrainKind(brain_kind)) {
    o.brain.kind = *kind;
  } else {
    std::fprintf(stderr, "swarmbox-agent: %s\n", kind.error().ToString().c_str());
    return 2;
  }
  if (swarmbox::Status s = swarmbox::agent::ValidateBrainOptions(o.brain, app.count("--mission") > 0, app.count("--plan") > 0); !s) {
    std::fprintf(stderr, "swarmbox-agent: %s\n", s.error().ToString().c_str());
    return 2;
  }
  // --world and --payload are the SAR mission's with the builtin brain, any brain's Context otherwise.
  if (o.brain.kind == swarmbox::agent::BrainKind::kBuiltin) {
    if (swarmbox::Status s = swarmbox::agent::ValidateMissionOptions(o.mission, !o.raft.members.empty(), app.count("--plan") > 0); !s) {
      std::fprintf(stderr, "swarmbox-agent: %s\n", s.error().ToString().c_str());
      return 2;
    }
  } else if (!o.mission.world_path.empty() && !std::filesystem::is_regular_file(o.mission.world_path)) {
    std::fprintf(stderr, "swarmbox-agent: --world '%s': no such file\n", o.mission.world_path.c_str());
    return 2;
  }
  o.stop = &g_stop;
  std::signal(SIGTERM, OnSignal);
  std::signal(SIGINT, OnSignal);
  auto node = swarmbox::agent::AgentNode::Create(o);
  if (!node) {
    std::fprintf(stderr, "swarmbox-agent: %s\n", node.error().ToString().c_str());
    return node.error().code() == swarmbox::ErrorCode::kInvalidArgument ||
                   node.error().code() == swarmbox::ErrorCode::kNotFound
               ? 2
               : 3;
  }
  swarmbox::Status s = (*node)->Run();
  if (!s) {
    std::printf("%s\n", swarmbox::LogEvent(0.0, o.name, "error").Add("reason", s.error().ToString()).str().c_str());
    std::fprintf(stderr, "swarmbox-agent: %s\n", s.error().ToString().c_str());
    return (*node)->raft_failed() ? 1 : 3;
  }
  if (g_stop != 0) LeaveNow();
  return 0;
}
