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
// Lines that are not logfmt events are ignored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <set>
#include <string>
#include <string_view>

namespace swarmbox::runner {

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

  void OnLine(std::string_view component, std::string_view line);
};

struct ProgressFrame {
  double timeout_sim_s = 0;  // 0 = none
  double wall_s = 0;
  std::size_t live = 0;        // containers running now
  std::size_t components = 0;  // containers of the trial
};

// "sim 41.2/600.0s  rtf 0.98  wall 43.0s  stage SEARCH  leader scout_2  victims sighted 3
// confirmed 2 rescued 1  live 5/5": rtf, stage, leader and victims only once known.
std::string RenderProgress(const TrialProgress& progress, const ProgressFrame& frame);

}  // namespace swarmbox::runner
