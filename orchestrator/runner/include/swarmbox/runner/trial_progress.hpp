// TrialProgress: what the live progress line of `swarmbox run` shows, as a pure fold over the
// trial's log lines (no clock, no I/O; Monitor feeds it every line and draws it).
//
//   TrialProgress p;
//   p.OnLine("physics", "t=20.000 node=physics event=clock rtf=0.98 steps=5000 late=0 lost=0");
//   p.OnLine("scout_1", "t=2.1 node=scout_1 event=leader_elected term=1 leader=scout_1");
//   RenderProgress(p, {.timeout_sim_s = 600, .wall_s = 21, .live = 5, .components = 5});
//   // "sim 20.0/600.0s  rtf 0.98  wall 21.0s  leader scout_1  live 5/5"
//
// What each field folds (the agents' and physics server's contract events, agent/app/README.md):
//   sim_s       the largest `t=` of any line [s]
//   rtf         `rtf=` of the latest physics `event=clock` (the achieved real-time factor)
//   stage       `state=` of the committed mission phase, `event=mission_state` with the largest
//               `index=` (every agent applies the same log: the swarm's stage, not one drone's);
//               COMPLETE after `event=mission_complete`
//   leader      `leader=` of `event=leader_elected` with the largest `term=`
//   sightings   `event=sighting_reported` without `retry=` (a scout's first report of a find)
//   confirmed   distinct `id=` of `event=victim_confirmed` (committed in the Raft log)
//   rescued     distinct `id=` of `event=victim_status status=rescued`
//   joining     the physics server's start (physics_server/app/joining.hpp): the latest
//               `event=joining joined= expected= missing=`, then `event=joined` (done, with
//               `lost=` and `wait_s=`)
// Lines that are not logfmt events are ignored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>

namespace swarmbox::runner {

// The physics server's start as its lines said.
struct JoiningProgress {
  std::int64_t joined = 0;
  std::int64_t expected = 0;
  std::string missing;  // as the server printed it: at most 10 names, then "+N"; "" = none
  bool done = false;    // event=joined: the first step completed
  std::int64_t lost = 0;  // done: drones given up at the start (named in `missing`)
  double wait_s = 0;      // done: wall seconds the start took on the server
};

struct TrialProgress {
  double sim_s = 0;
  std::optional<double> rtf;
  std::string stage;  // "" = no mission_state yet
  std::int64_t stage_index = -1;
  std::string leader;  // "" = no leader elected yet
  std::int64_t leader_term = -1;
  int sightings = 0;
  std::set<std::int64_t> confirmed;
  std::set<std::int64_t> rescued;
  std::optional<JoiningProgress> joining;  // nullopt: no joining line (a quick complete start)

  void OnLine(std::string_view component, std::string_view line);
};

struct ProgressFrame {
  double timeout_sim_s = 0;  // 0 = none
  double wall_s = 0;
  std::size_t live = 0;        // containers running now
  std::size_t components = 0;  // containers of the trial
};

// "sim 41.2/600.0s  rtf 0.98  wall 43.0s  stage SEARCH  leader scout_2  victims sighted 3
// confirmed 2 rescued 1  live 5/5": rtf, stage, leader and victims only once known; while the
// physics server's start goes on, "joining 37/101" after the wall time.
std::string RenderProgress(const TrialProgress& progress, const ProgressFrame& frame);

// The drones that did not join, for the reason of a trial that ends badly: "drones that did not
// join: scout_16,scout_40,+54 (joined 37/101)" while the start was still going on, "... (lost at
// the start, joined 99/101)" when the server gave them up; nullopt when every drone joined or no
// joining line came.
std::optional<std::string> NotJoinedNote(const TrialProgress& progress);

// The runner's line when the start completed: "joined 101/101 in 6.2 s" (the server's wait), with
// "; lost at the start: scout_16,scout_40" when it gave some up; nullopt before.
std::optional<std::string> JoinedLine(const TrialProgress& progress);

}  // namespace swarmbox::runner
