// KinematicSwarm: a seeded kinematic model of N drones running swarm::Flocking, for the flocking
// tests and the `swarmbox-bench flocking` suite.
//
// Each drone's velocity follows its commanded velocity with a first-order lag (tau_s); positions
// integrate it. The radio is modelled as in the agent: every drone broadcasts its state
// (bus::DroneState) at broadcast_hz, staggered, each packet lost with probability `loss`; a drone
// sees each other drone's last received packet with its age. A removed drone stops moving and
// broadcasting (killed) and disappears from the metrics; the others see its last packet grow old.
#pragma once

#include <cstdint>
#include <random>
#include <vector>

#include "swarmbox/swarm/flock_metrics.hpp"
#include "swarmbox/swarm/flocking.hpp"

namespace swarmbox::swarm::testing {

struct KinematicSwarmConfig {
  int agents = 20;
  std::uint64_t seed = 1;
  double start_box_m = 60.0;         // random starts, uniform in a square of this side, centred at 0
  double min_start_spacing_m = 5.0;  // rejection sampling keeps starts at least this far apart
  double start_speed_max_m_s = 2.0;  // random initial horizontal velocities up to this speed
  double altitude_m = 20.0;
  double dt_s = 0.05;                // control step [s]
  double tau_s = 0.3;                // velocity response lag [s]
  double broadcast_hz = 10.0;
  double loss = 0.0;                 // radio packet loss probability
  FlockingParams params;
  Geofence fence = Geofence::Centered(2000, 2000);
  std::vector<ObstacleFootprint> obstacles;
  Vec3 goal_m = Vec3(600, 300, 20);  // common migration goal (z: altitude to hold)
};

class KinematicSwarm {
 public:
  explicit KinematicSwarm(const KinematicSwarmConfig& config);

  void Step();
  void Remove(int agent);                 // kill: no more motion or broadcasts
  void SetGoal(const Vec3& goal_m) { goal_m_ = goal_m; }

  double time_s() const { return t_s_; }
  int alive_count() const;
  bool alive(int agent) const { return alive_[static_cast<std::size_t>(agent)]; }
  const Vec3& position(int agent) const { return pos_[static_cast<std::size_t>(agent)]; }
  // Positions and velocities of the living drones only.
  std::vector<Vec3> AlivePositions() const;
  std::vector<Vec3> AliveVelocities() const;
  FlockMetrics Metrics(const FlockMetricsParams& params) const;

 private:
  struct Packet {
    bool valid = false;
    double t_s = 0.0;
    Vec3 pos = Vec3::Zero();
    Vec3 vel = Vec3::Zero();
  };

  KinematicSwarmConfig config_;
  std::mt19937_64 rng_;
  std::vector<Flocking> flock_;
  std::vector<Vec3> pos_;
  std::vector<Vec3> vel_;
  std::vector<bool> alive_;
  std::vector<Packet> last_packet_;
  std::vector<double> next_broadcast_s_;
  std::vector<NeighbourState> scratch_;
  Vec3 goal_m_;
  double t_s_ = 0.0;
};

}  // namespace swarmbox::swarm::testing
