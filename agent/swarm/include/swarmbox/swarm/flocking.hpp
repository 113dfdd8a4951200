// Flocking: Boids for the SAR swarm, in the form of Vasarhelyi et al., "Optimized flocking of
// autonomous drones in confined environments", Science Robotics 3(20), 2018 (below "V18"), with
// Reynolds cohesion and alignment added. One call per control step turns the drone's own state,
// its neighbours (as heard on the radio state topic, with their ages) and its current goal into a
// velocity setpoint for the flight stack.
//
// How the agent calls it (agent/app, once per control step, e.g. 50 Hz):
//
//   swarm::Flocking flock(params, swarm::Geofence::Centered(200, 200), obstacles);  // at start-up
//   ...
//   neighbours_.clear();                                     // a reserved std::vector, no realloc
//   for (const bus::DroneState& s : latest_states)           // keyed by drone, newest sample each
//     if (s.drone != self)
//       neighbours_.push_back({ToVec3(s.position_enu_m), ToVec3(s.velocity_enu_m_s),
//                              now_s - s.sim_time_ns * 1e-9});
//   swarm::FlockingOutput out = flock.Step({est.pos_m, est.vel_m_s, goal_m, neighbours_}, dt_s);
//   flight.SetVelocitySetpoint(out.velocity_m_s, yaw_rad);
//
// Terms (all horizontal, world ENU x/y; z is a separate altitude-hold channel). Distances to
// neighbours are 3-D (a drone 15 m below is not in the way), the pushes they cause horizontal:
//  - migration   v_flock toward the goal, slowing on the braking curve D near it (V18 eq. 4 / S6);
//  - repulsion   p_rep (r0_rep - r) along the line from each neighbour closer than r0_rep (V18 eq. 1);
//  - friction    velocity alignment with the V18 "smart" tolerance: only the part of the velocity
//                difference above the braking curve is damped (V18 eq. 2-3);
//  - alignment   Reynolds' linear alignment toward the neighbours' mean velocity (gain c_align);
//  - cohesion    Reynolds' attraction to the neighbours' centroid beyond r0_coh (while migrating,
//                scaled by the migration's speed over v_flock: it never holds a drone off its goal);
//  - shill       V18 virtual agents on the geofence walls and on obstacle faces, moving inward /
//                outward at v_shill: their push on a drone at rest (V18 eq. 5 with the drone's
//                velocity zero) from within WallStandoffM; and the commanded velocity's component
//                toward a wall or face held to the braking curve to r0_shill (the velocity part of
//                V18 eq. 5 as a limit on the command, not a feedback on the measured velocity,
//                which through the flight stack's lag swung the attitude: flocking.cpp ShillTerm);
//                only the normal component (drones slide along walls); near an obstacle the
//                migration term turns along its face (no head-on stall);
//  - limits      |v_xy| <= v_max, |v_z| <= v_z_max, |dv/dt| <= a_max (across steps).
//
// Neighbours: the position is dead-reckoned by velocity * age. A neighbour older than
// stale_timeout_s is dropped (a drone that went silent stops steering us after that). Of those
// within sensing_range_m only the `max_neighbours` nearest (default 7) steer: starlings interact
// with a fixed number of topological neighbours, six to seven, not with all birds within a
// distance (Ballerini et al., "Interaction ruling animal collective behavior depends on topological
// rather than metric distance", PNAS 105(4), 2008), which also keeps a step O(N) in the neighbours
// given and its terms O(1) in the swarm's size (issue 18). Freshness
// weight w = 1 up to fresh_age_s, falling linearly to 0 at stale_timeout_s, scales alignment,
// friction and cohesion; repulsion keeps full weight until the timeout (safety first).
//
// Allocation: none in Step(). Not thread-safe (one instance per drone, one caller).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

namespace swarmbox::swarm {

using Vec2 = Eigen::Vector2d;
using Vec3 = Eigen::Vector3d;

// A neighbour as heard on the radio (bus::DroneState), world ENU.
struct NeighbourState {
  Vec3 position_m = Vec3::Zero();    // at the time of the sample [m]
  Vec3 velocity_m_s = Vec3::Zero();  // [m/s]
  double age_s = 0.0;                // now - sample time [s] (simulated time; >= 0)
};

// Axis-aligned rectangular geofence in world ENU [m].
struct Geofence {
  double min_x_m = -1e9;
  double max_x_m = 1e9;
  double min_y_m = -1e9;
  double max_y_m = 1e9;
  // The world's geofence convention (WorldConfig): |x| <= size_x/2, |y| <= size_y/2.
  static Geofence Centered(double size_x_m, double size_y_m) {
    return {-size_x_m / 2, size_x_m / 2, -size_y_m / 2, size_y_m / 2};
  }
  bool Contains(const Vec2& p) const {
    return p.x() >= min_x_m && p.x() <= max_x_m && p.y() >= min_y_m && p.y() <= max_y_m;
  }
};

// A vertical prism obstacle seen from above: a rectangle (yawed about its centre) [m, ENU].
struct ObstacleFootprint {
  Vec2 center_m = Vec2::Zero();
  Vec2 half_size_m = Vec2::Zero();  // half extents along the obstacle's own x and y
  double yaw_rad = 0.0;             // ENU yaw of the obstacle's x axis
};

struct FlockingParams {
  // Migration (self-propulsion toward the goal).
  double v_flock_m_s = 4.0;       // preferred cruise speed [m/s]
  double a_mig_m_s2 = 1.0;        // braking-curve deceleration toward the goal [m/s^2]
  double p_mig_1_s = 0.6;         // braking-curve linear gain near the goal [1/s]
  // Repulsion (V18 r0_rep, p_rep).
  double r0_rep_m = 10.0;
  double p_rep_1_s = 1.2;
  // Friction alignment (V18 r0_frict, C_frict, v_frict, p_frict, a_frict).
  double r0_frict_m = 20.0;
  double c_frict = 0.1;
  double v_frict_m_s = 0.6;
  double p_frict_1_s = 1.5;
  double a_frict_m_s2 = 2.0;
  // Reynolds alignment and cohesion.
  double c_align = 0.3;           // gain on (mean neighbour velocity - own velocity) [-]
  double r0_coh_m = 14.0;         // no attraction while the centroid is closer than this [m]
  double p_coh_1_s = 0.15;
  double v_coh_max_m_s = 2.0;     // cap on the cohesion term [m/s]
  // Shill agents (V18 r0_shill, v_shill, p_shill, a_shill) at the geofence and obstacles.
  double r0_shill_m = 4.0;        // stand-off distance from walls and obstacle faces [m]
  double v_shill_m_s = 6.0;
  double p_shill_1_s = 1.0;
  double a_shill_m_s2 = 2.5;
  double c_shill = 2.0;
  double obstacle_slide_range_m = 12.0;  // migration turns along an obstacle face within this [m]
  // Neighbourhood.
  double sensing_range_m = 60.0;  // neighbours further than this are ignored [m]
  int max_neighbours = 7;         // only the nearest this many steer (Ballerini 2008), > 0
  double fresh_age_s = 0.5;       // full weight up to this age [s]
  double stale_timeout_s = 2.0;   // dropped beyond this age [s]
  // Limits and altitude channel.
  double v_max_m_s = 6.0;         // horizontal speed limit [m/s]
  double a_max_m_s2 = 3.0;        // limit on the change of the commanded velocity [m/s^2]
  double v_z_max_m_s = 2.0;       // vertical speed limit [m/s]
  double p_z_1_s = 0.8;           // altitude-hold gain toward goal z [1/s]
};

struct FlockingInput {
  Vec3 position_m = Vec3::Zero();    // own estimated position, world ENU [m]
  Vec3 velocity_m_s = Vec3::Zero();  // own estimated velocity [m/s]
  Vec3 goal_m = Vec3::Zero();        // migration target (x, y) and the altitude to hold (z) [m]
  std::span<const NeighbourState> neighbours;
  bool migrate = true;               // false: hold the goal altitude, no migration term
};

struct FlockingOutput {
  Vec3 velocity_m_s = Vec3::Zero();  // the setpoint for the flight stack, world ENU [m/s]
  // The horizontal terms before limiting, for logs and tests [m/s].
  Vec2 migration = Vec2::Zero();
  Vec2 repulsion = Vec2::Zero();
  Vec2 friction = Vec2::Zero();
  Vec2 alignment = Vec2::Zero();
  Vec2 cohesion = Vec2::Zero();
  Vec2 shill = Vec2::Zero();
  int neighbours_used = 0;           // the nearest (<= max_neighbours) in range and fresher than the timeout
};

// The V18 braking curve D(r, a, p) [m/s]: the speed from which one can stop within distance r with
// deceleration a, linear (gain p) near r = 0. Zero for r <= 0.
double BrakingCurve(double r_m, double a_m_s2, double p_1_s);

// The clearance from a geofence wall inside which its shill agent pushes a drone at rest inward:
// r0_shill plus the distance over which BrakingCurve reaches v_shill (12.45 m with the defaults).
// A drone cannot hold a spot closer to the fence than this [m].
double WallStandoffM(const FlockingParams& k);

class Flocking {
 public:
  // Aborts (SWARMBOX_CHECK) on a non-positive limit or timeout: that is a configuration bug.
  Flocking(const FlockingParams& params, const Geofence& fence,
           std::vector<ObstacleFootprint> obstacles = {});

  // One control step of dt_s > 0 [s].
  FlockingOutput Step(const FlockingInput& in, double dt_s);

  // Forgets the previous command (the acceleration limit starts from `velocity_m_s`).
  void Reset(const Vec3& velocity_m_s) {
    last_command_m_s_ = velocity_m_s;
    has_last_ = true;
  }

  const FlockingParams& params() const { return params_; }
  const Geofence& fence() const { return fence_; }

 private:
  // Step's terms (allocation-free, in this translation unit): migration toward the goal, sliding
  // around obstacles; repulsion from every close neighbour while the nearest are picked into
  // nearest_; friction, alignment and cohesion with those; the walls' and obstacles' shill push.
  Vec2 MigrationTerm(const FlockingInput& in, const Vec2& p) const;
  void ScanNeighbours(const FlockingInput& in, const Vec2& p, FlockingOutput* out);
  void FollowNeighbours(const FlockingInput& in, const Vec2& p, const Vec2& v,
                        FlockingOutput* out) const;
  Vec2 ShillTerm(const Vec2& p) const;
  Vec2 WallLimit(const Vec2& p, Vec2 v) const;
  // fn(clearance_m, away_normal) for each geofence wall and obstacle footprint.
  template <typename Fn>
  void ForEachWall(const Vec2& p, Fn&& fn) const;

  FlockingParams params_;
  Geofence fence_;
  std::vector<ObstacleFootprint> obstacles_;
  Vec3 last_command_m_s_ = Vec3::Zero();
  bool has_last_ = false;
  struct Near {
    double r_m;          // 3-D distance to the dead-reckoned position
    std::size_t index;   // in FlockingInput::neighbours
  };
  std::vector<Near> nearest_;  // Step's scratch, capacity max_neighbours + 1 (no allocation)
};

}  // namespace swarmbox::swarm
