// A trial's quantities over simulated time, as plots.html draws them (pure: feed the logs' event
// lines and truth.csv's rows, take the series; ReadTrialSeries in trial_record.hpp feeds it a
// trial folder).
//
//   TrialSeriesBuilder b;                              // truth.csv sampled once per 1 s
//   b.OnLogEvent("scout_1", ParseLogfmt(line));        // every line of logs/<component>.log
//   b.OnTruth(row);                                    // truth.csv rows in file (time) order
//   TrialSeries s = b.Finish();
//
// What each series is, and where it comes from (every time is the simulated `t` / `t_s`):
//   altitude_m       truth.csv z_m per drone (ENU up, above the ground plane) [m]
//   speed_m_s        truth.csv |(vx, vy, vz)| per drone [m/s]
//   nearest_m        per drone, the 3-D distance to the nearest other drone at the same truth time [m]
//                    (all pairs of one sampled row group: O(N^2) once per sample period, not per row)
//   radio_loss       per node, each event=link burst (the node's lines at one t, one per sampled
//                    peer): 1 - sum(received) / sum(sent) [0..1]
//   radio_rtt_ms     per node and burst: rtt_ms_mean weighted by `received` [ms]
//   raft_term        per node, the term of its event=leader_elected lines (a step line)
//   raft_leader      per node, who it took for the leader from each event=leader_elected on, until
//                    its next one or its raft_stopped / stopped line
//   battery          per node, event=battery fraction= (the agent logs it once per simulated second) [0..1]
//   mission_stage    per node, event=mission_stage stage= from each line to the next
//   flock            `order`, `safety`, `union` of event=flock_metrics (the Raft leader logs them once
//                    per simulated second from its member table, agent/swarm flock_metrics.hpp) [0..1]
// Series and lanes are sorted by name; a series' points by time. Nothing is invented: a trial
// without an event gives an empty list for what it feeds.
#pragma once

#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::report {

struct SeriesPoint {
  double t_s = 0;
  double value = 0;
};

// One line of a chart: a drone's, a node's or a metric's values over time.
struct Series {
  std::string name;
  std::vector<SeriesPoint> points;  // sorted by t_s
};

// A state held from t0_s to t1_s (a mission stage, the leader a node followed).
struct StateSpan {
  double t0_s = 0;
  double t1_s = 0;
  std::string label;
};

// One row of a state chart: a node's states over time.
struct Lane {
  std::string name;
  std::vector<StateSpan> spans;  // in time order, not overlapping
};

struct TrialSeries {
  double t_end_s = 0;  // the latest time any input had
  std::vector<Series> altitude_m;
  std::vector<Series> speed_m_s;
  std::vector<Series> nearest_m;
  std::vector<Series> radio_loss;
  std::vector<Series> radio_rtt_ms;
  std::vector<Series> raft_term;
  std::vector<Lane> raft_leader;
  std::vector<Series> battery;
  std::vector<Lane> mission_stage;
  std::vector<Series> flock;  // "order", "safety", "union"
};

// One truth.csv row (the columns plots need).
struct TruthRow {
  double t_s = 0;
  std::string drone;
  double x_m = 0, y_m = 0, z_m = 0;
  double vx_m_s = 0, vy_m_s = 0, vz_m_s = 0;
  bool has_velocity = true;  // false: the file has no velocity columns (no speed series)
  // The attitude (world from body) and the body rates, when the file has them (the physics
  // server's does): what a camera replay renders from (perception_scenes.hpp ReplayTrial).
  bool has_attitude = false;
  double qw = 1, qx = 0, qy = 0, qz = 0;
  double p_rad_s = 0, q_rad_s = 0, r_rad_s = 0;
};

class TrialSeriesBuilder {
 public:
  // truth_period_s: truth.csv is sampled at the first row group at or after each multiple of it
  // (truth.csv has 50 rows per drone per second; a plot needs a few hundred points).
  explicit TrialSeriesBuilder(double truth_period_s = 1.0) : truth_period_s_(truth_period_s) {}

  // One logfmt line of `component`'s log (lines without `event` or `t` are ignored).
  void OnLogEvent(std::string_view component, const LogfmtFields& fields);
  // One truth.csv row; rows come in file order (time order, every drone of a time together).
  void OnTruth(const TruthRow& row);

  TrialSeries Finish();

 private:
  struct LinkBurst {
    double t_s = -1;
    double sent = 0, received = 0, loss_sum = 0, loss_n = 0, rtt_sum = 0, rtt_w = 0;
  };
  void FlushTruthGroup();
  // One event=link line: starts the node's next burst when its time differs from the current one.
  void OnLinkEvent(const std::string& node, double t_s, const LogfmtFields& fields);
  void FlushLink(const std::string& node, LinkBurst& burst);
  void SeeTime(double t_s);

  double truth_period_s_;
  double t_end_s_ = 0;
  std::optional<double> truth_due_s_;
  std::optional<double> group_t_s_;
  std::vector<TruthRow> group_;
  std::map<std::string, Series> altitude_, speed_, nearest_, loss_, rtt_, term_, battery_, flock_;
  std::map<std::string, LinkBurst> link_;
  std::map<std::string, Lane> leader_, stage_;
};

}  // namespace swarmbox::report
