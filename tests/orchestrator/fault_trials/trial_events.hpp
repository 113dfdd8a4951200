// What a fault trial's events.jsonl says, read back for the fault-trial tests and the `faults`
// benchmark: the agents' radio link lines, fault records, leader elections and commits. Pure
// except ReadEvents (one file).
//
//   auto events = ReadEvents(run.trial_dir + "/events.jsonl");
//   LinkSummary during = SummariseLinks(*events, applied_s + 5.0, removed_s);
//   std::vector<Failover> f = Failovers(*events);
//
// Times are the runner's wall clock (`wall_s`, seconds since the trial's Run) at which it read
// the line: the radio and Raft run on wall time, so this is the clock their figures mean.
#pragma once

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/result.hpp"

namespace swarmbox::fault_trials {

// One line of events.jsonl: a log event (component = the container, fields = its logfmt pairs) or
// an orchestrator record (component "orchestrator", or type "fault"/"mesh"/"mechanism").
struct TrialEvent {
  double wall_s = 0.0;
  std::string component;
  std::map<std::string, std::string> fields;  // scalar values as text
  std::vector<std::string> targets;           // a fault record's `targets`

  std::string Get(std::string_view key) const;  // "" when absent
  std::optional<double> Number(std::string_view key) const;
};

// Parses JSON lines; kProtocol with the line number for a line that is not a JSON object.
Result<std::vector<TrialEvent>> ParseEvents(std::string_view jsonl);
Result<std::vector<TrialEvent>> ReadEvents(const std::string& path);

// A fault record (type "fault") with the given fault id and phase ("requested", "applied",
// "remove_requested", "removed",
// "failed"); nullopt when there is none.
std::optional<TrialEvent> FindFaultRecord(const std::vector<TrialEvent>& events,
                                          std::string_view fault_id, std::string_view phase);

// The event=link lines with wall_s in [from_s, to_s), pooled over every (node, peer) pair.
// Windows of a pair before its first window with a pong are skipped (DDS discovery: the pings of a
// peer that is not matched yet are lost for a reason that is not the radio).
struct LinkSummary {
  std::size_t windows = 0;
  std::uint64_t sent = 0;
  std::uint64_t received = 0;
  double loss = 0.0;         // 1 - received / sent (0 when nothing was sent)
  double rtt_mean_ms = 0.0;  // over every received pong (window means weighted by count)
  double rtt_sd_ms = 0.0;    // pooled sample standard deviation of every received pong
  double rtt_p50_ms = 0.0;   // median of the windows' p50s (a robust centre)
  // The median of the windows' own standard deviations (windows with at least kMinPongsForSd
  // pongs) and how many windows that is: a robust spread. A busy host delays pongs in bursts (a
  // neighbour test's build or start): a few windows then hold delays of tens of ms that the pooled
  // sd takes in whole, while the median window is the link's own jitter.
  double rtt_sd_window_median_ms = 0.0;
  std::size_t sd_windows = 0;
  double pongs_per_sd_window = 0.0;  // mean pongs in those windows
  std::map<std::string, std::uint64_t> sent_by_node;
};
inline constexpr std::uint64_t kMinPongsForSd = 5;
LinkSummary SummariseLinks(const std::vector<TrialEvent>& events, double from_s, double to_s);

// Leader failovers: for every applied kill/stop of a drone that was the leader at the time (the
// latest leader_elected before the fault named it), the first later leader_elected naming another
// drone with a higher term.
struct Failover {
  std::string fault;          // the fault's id
  std::string old_leader;
  std::string new_leader;     // "" when none was elected before the trial ended
  std::uint64_t old_term = 0;
  std::uint64_t new_term = 0;
  double fault_wall_s = 0.0;
  double failover_ms = -1.0;  // -1 when no new leader
};
std::vector<Failover> Failovers(const std::vector<TrialEvent>& events);

// Raft commits a drone applied: events that carry `index` (mission_state, victim_confirmed,
// victim_status), in log order, per drone.
struct Commit {
  double wall_s = 0.0;
  std::uint64_t index = 0;
  std::string what;  // "mission_state state=SEARCH", "victim_confirmed id=3", ...
};
std::map<std::string, std::vector<Commit>> CommitsByDrone(const std::vector<TrialEvent>& events);
// The highest index a drone applied by wall time `at_s` (0 = none yet).
std::uint64_t IndexAt(const std::vector<Commit>& commits, double at_s);
// Indices where two drones applied different things: "index 12: scout_1 'mission_state
// state=SEARCH' vs scout_3 'victim_confirmed id=4'". Empty when the logs agree.
std::vector<std::string> Disagreements(const std::map<std::string, std::vector<Commit>>& commits);

// The leader the latest leader_elected line from any of `nodes` named by wall time `at_s`.
std::optional<std::string> LeaderSeenBy(const std::vector<TrialEvent>& events,
                                        const std::vector<std::string>& nodes, double at_s);

// The physics server's event=clock lines (rtf, late steps, lost drones) and event=drone_lost.
struct ClockLine {
  double wall_s = 0.0;
  double t_s = 0.0;
  double rtf = 0.0;
  std::uint64_t late = 0;
  std::uint64_t lost = 0;
};
std::vector<ClockLine> ClockLines(const std::vector<TrialEvent>& events);
std::size_t CountEvents(const std::vector<TrialEvent>& events, std::string_view event);

// Nearest-rank percentile of unsorted values (p in (0, 1]); -1 for none.
double Percentile(std::vector<double> values, double p);

}  // namespace swarmbox::fault_trials
