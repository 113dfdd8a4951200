// Per-trial metrics: the one definition of each metric, used by the runner for result.json's
// "metrics", by results.csv and by report.html (pure: feed events and truth rows, read Values();
// ReadTrialMetrics in trial_record.hpp feeds it a trial folder).
//
// Every metric is optional: a trial whose logs have no event a metric needs gets an empty cell,
// never an invented value.
//   mission_time_s        t of the first event=mission_complete
//   first_detection_s     t of the first victim_detected / victim_confirmed / sighting_reported
//   detections            distinct victims detected or confirmed (their `id`, or `victim`, field;
//                         such events without one count one each; sighting_reported only sets
//                         first_detection_s); empty when the trial logged no perception event
//                         and no mission_state
//   victims_confirmed     distinct victims in victim_confirmed events (same rule): the ending
//                         line's `victims=` (mission_complete counts the mission's victims, which
//                         are the confirmed ones)
//   min_separation_m      smallest 3-D distance between two drones at the same truth.csv time
//                         (needs >= 2 drones)
//   collisions            event=collision count (0 when the physics log is there)
//   leader_changes        times the elected leader differed from the previous term's leader
//                         (distinct (term, leader) pairs of event=leader_elected, in term order)
//   failover_s            longest time from losing the leader (the leader's node logging
//                         raft_stopped/stopped/crash, or a fault event targeting it) to the next
//                         leader_elected
//   radio_rtt_ms          mean RTT over event=link lines: rtt_ms_mean weighted by `received`
//   radio_loss            1 - sum(received) / sum(sent) over event=link lines (the mean of `loss`
//                         for lines without counts)
//   victims_rescued       distinct victims (`id`) in event=victim_status status=rescued: the ending
//                         line's `rescued=`; empty like detections
//   false_alarms_rejected distinct candidates in event=rejected (the leader's planner: a sighting
//                         the fused evidence of a revisit rejected); empty like detections
//   false_victims_confirmed  confirmed victims (event=victim_confirmed x= y=) farther than
//                         kFalseVictimRadiusM from every victim of the world (OnWorldVictim; the
//                         trial folder's world.yaml): empty when the world's victims are unknown
//   false_victims_rescued the rescued ones among those (same condition)
//   victims_missed        victims of the world with no rescued victim confirmed within
//                         kFalseVictimRadiusM of them (same condition); a mission trial met issue
//                         #19's target when it succeeded with victims_missed and
//                         false_victims_rescued both 0
// The agents log victim_confirmed/victim_status with `id=` (agent/raft node_driver.cpp) and
// sighting_reported without one (agent/swarm scout_behaviour.cpp); `victim=` is also accepted.
#pragma once

#include <array>
#include <cstdint>
#include <map>
#include <optional>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::report {

// A confirmed victim this far or farther from every victim of the world is a false one [m].
inline constexpr double kFalseVictimRadiusM = 3.0;

// The metric columns, in results.csv order.
const std::vector<std::string>& MetricNames();

using MetricValues = std::map<std::string, std::optional<double>>;

class TrialMetrics {
 public:
  // One logfmt line of `component`'s log (lines without `event` are ignored).
  void OnLogEvent(std::string_view component, const LogfmtFields& fields);
  // One orchestrator record from events.jsonl (component "orchestrator" or a fault injector):
  // `event`, `target`, and the wall/sim time it happened at (`t_s`, simulated when known).
  void OnOrchestratorEvent(std::string_view event, std::string_view target, std::optional<double> t_s);
  // One truth.csv sample.
  void OnTruth(double t_s, std::string_view drone, double x_m, double y_m, double z_m);
  // One victim of the world (ground truth, from the trial's world.yaml), for the false_* metrics.
  void OnWorldVictim(double x_m, double y_m) { world_victims_.push_back({x_m, y_m}); }
  // Says that the physics server's log was read (collisions are then 0, not unknown).
  void SawPhysicsLog() { physics_log_ = true; }

  MetricValues Values();

 private:
  // OnLogEvent's events: the perception's detections and confirmations, a new Raft term's
  // leader, a radio link measurement.
  void OnVictimEvent(const std::string& e, std::optional<double> t, const LogfmtFields& fields);
  void OnLeaderElected(std::optional<double> t, const LogfmtFields& fields);
  void OnLinkEvent(const LogfmtFields& fields);
  // Values' parts: the perception's counts, those against the world's victims, Raft's leaders.
  void PerceptionValues(MetricValues* v) const;
  void WorldVictimValues(MetricValues* v) const;
  void LeaderValues(MetricValues* v);
  void FlushTruthTime();

  std::optional<double> mission_time_s_;
  std::optional<double> first_detection_s_;
  bool perception_seen_ = false;
  std::set<std::string> detected_;
  std::set<std::string> confirmed_;
  std::set<std::string> rescued_;
  std::set<std::string> rejected_;                                  // candidate ids
  std::map<std::string, std::array<double, 2>> confirmed_at_;      // victim id -> x, y
  std::vector<std::array<double, 2>> world_victims_;
  std::uint64_t anonymous_detections_ = 0;
  std::uint64_t anonymous_confirmed_ = 0;
  bool physics_log_ = false;
  std::uint64_t collisions_ = 0;
  // leader_elected: term -> (t, leader)
  std::map<std::int64_t, std::pair<double, std::string>> terms_;
  std::vector<std::pair<double, std::string>> leader_losses_;  // (t, node that stopped)
  double link_rtt_sum_ = 0;  // sum of rtt_ms_mean x pings answered
  double link_rtt_w_ = 0;
  double link_sent_ = 0;     // pings sent (a line without counts weighs 1)
  double link_lost_ = 0;
  // truth: samples of the current time step
  std::optional<double> truth_t_;
  std::vector<std::array<double, 3>> truth_points_;
  std::optional<double> min_sep_;
};

}  // namespace swarmbox::report
