// Flock metrics: how well a swarm snapshot flocks, for tests, benchmarks and trial metrics.
//
//   FlockMetrics m = ComputeFlockMetrics(positions, velocities, {.separation_m = 3, .link_range_m = 40});
//   // m.safety == 1: no pair closer than 3 m; m.order > 0.9: aligned; m.union_ == 1: one group
//
// Definitions (after V18's order parameters, Vasarhelyi et al. 2018, and the order / safety /
// union metrics used to score flocks, e.g. Olfati-Saber 2006 and follow-ups):
//  - safety      fraction of pairs (i<j) whose distance is >= separation_m (1 = nobody too close);
//  - order       mean over pairs of the cosine between horizontal velocities (V18 phi_corr),
//                pairs with a near-zero velocity (< 0.1 m/s) count as 0;
//  - union_      1 - (C - 1) / (N - 1), C = connected components of the graph "distance <=
//                link_range_m" (1 = one connected group, 0 = everyone alone);
//  - min_distance_m, mean_nearest_m (mean nearest-neighbour distance), max_nearest_m.
// Positions and velocities in world ENU [m], [m/s]; distances are 3-D.
//
// FlockMetricsLog: the Raft leader's `event=flock_metrics` line, once per simulated second, from its
// member table (every member's latest word: agent/swarm member_table.hpp), so the metrics reach
// the trial's logs and its plots.html (orchestrator/report trial_plots.hpp):
//
//   FlockMetricsLog flock_log({.separation_m = 3, .link_range_m = 60});
//   if (auto line = flock_log.Sample(now_s, "scout_2", table.Roster(now_s))) log(*line);
//   // t=12.000 node=scout_2 event=flock_metrics members=4 order=0.912 safety=1.000 union=1.000
//   //          components=1 min_m=14.21 mean_nearest_m=20.37
#pragma once

#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/swarm/leader_planner.hpp"

namespace swarmbox::swarm {

struct FlockMetricsParams {
  double separation_m = 3.0;
  double link_range_m = 40.0;
};

struct FlockMetrics {
  double safety = 1.0;
  double order = 1.0;
  double union_ = 1.0;
  int components = 1;
  double min_distance_m = 0.0;
  double mean_nearest_m = 0.0;
  double max_nearest_m = 0.0;
};

// Aborts when the spans differ in length. Allocates (a small union-find): not for control loops.
FlockMetrics ComputeFlockMetrics(std::span<const Eigen::Vector3d> positions_m,
                                 std::span<const Eigen::Vector3d> velocities_m_s,
                                 const FlockMetricsParams& params);

// The leader's flock_metrics line from a roster, at most once per period_s of simulated time.
//   - members: roster entries heard within max_age_s (the member timeout: a silent member is gone);
//   - positions: each member's latest position in the table, which holds x and y only, so the
//     distances (safety, union, min_m, mean_nearest_m) are horizontal, at z = 0;
//   - velocities: the change of a member's position between two samples, over the change of its
//     word's time (t - age_s); a member without two different words yet counts as still, so
//     the first sample's order counts it 0 (as a hovering drone).
// Deterministic in its inputs (simulated time only). Cost per sample: O(N^2) pairs of
// ComputeFlockMetrics over the N members, O(N) otherwise; nothing between samples. Allocates
// (reuses its buffers after the first sample).
class FlockMetricsLog {
 public:
  explicit FlockMetricsLog(FlockMetricsParams params = {}, double period_s = 1.0, double max_age_s = 6.0)
      : params_(params), period_s_(period_s), max_age_s_(max_age_s) {}

  // The line when a sample is due at t_s (the first at once, then every period_s) and at least two
  // members are fresh; nullopt otherwise. `node`: this drone (the line's node).
  std::optional<LogEvent> Sample(double t_s, std::string_view node, std::span<const RosterEntry> roster);

 private:
  struct Track {
    std::string name;
    double word_t_s = 0;  // the word's simulated time at the previous sample
    Eigen::Vector2d position_m = Eigen::Vector2d::Zero();
    Eigen::Vector2d velocity_m_s = Eigen::Vector2d::Zero();
    bool seen = false;
  };
  FlockMetricsParams params_;
  double period_s_;
  double max_age_s_;
  std::optional<double> due_s_;
  std::vector<Track> tracks_;  // by roster index (a roster entry keeps its place)
  std::vector<Eigen::Vector3d> positions_m_;
  std::vector<Eigen::Vector3d> velocities_m_s_;
};

}  // namespace swarmbox::swarm
