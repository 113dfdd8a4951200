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
#pragma once

#include <span>

#include <Eigen/Core>

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

}  // namespace swarmbox::swarm
