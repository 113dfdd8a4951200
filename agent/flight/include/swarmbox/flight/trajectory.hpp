// Smooth setpoint handling: turns a jumping target (a new waypoint, a new velocity) into a
// reference (position, velocity, acceleration) that respects the velocity and acceleration
// limits, for the position controller to track with feed-forward.
//
// Position targets: the reference moves along the way to the target with the speed that still
// lets it stop there (v = min(v_max, sqrt(2 a_max d), k d)), changing velocity by at most a_max;
// the horizontal and vertical limits (up/down) are applied to the whole vector, so the path stays
// straight. Velocity targets: the reference velocity ramps at a_max; the reference position
// integrates it. Pure, allocation-free.
//
//   Trajectory tr(limits);  tr.Reset(pos_now, vel_now);
//   tr.SetPositionTarget(goal);
//   TrajectoryPoint ref = tr.Step(dt_s);   // ref.pos_m, ref.vel_m_s, ref.acc_m_s2
#pragma once

#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

struct TrajectoryLimits {
  double vel_max_xy_m_s = 5.0;
  double vel_max_up_m_s = 3.0;
  double vel_max_down_m_s = 1.5;
  double acc_max_xy_m_s2 = 3.0;
  double acc_max_z_m_s2 = 2.0;
  double approach_gain = 2.5;      // k: the final approach is first-order with this rate [1/s]
};

struct TrajectoryPoint {
  Vec3 pos_m = Vec3::Zero();
  Vec3 vel_m_s = Vec3::Zero();
  Vec3 acc_m_s2 = Vec3::Zero();
};

class Trajectory {
 public:
  explicit Trajectory(const TrajectoryLimits& limits = {}) : limits_(limits) {}
  void SetLimits(const TrajectoryLimits& limits) { limits_ = limits; }
  const TrajectoryLimits& limits() const { return limits_; }

  // Restarts the reference at the vehicle's state (on mode changes, at take-off).
  void Reset(const Vec3& pos_m, const Vec3& vel_m_s);
  void SetPositionTarget(const Vec3& pos_m);
  void SetVelocityTarget(const Vec3& vel_m_s);
  TrajectoryPoint Step(double dt_s);

  const TrajectoryPoint& reference() const { return ref_; }
  const Vec3& target() const { return target_; }
  // The reference has arrived (position mode: at the target and at rest).
  bool Settled(double tol_m = 0.01) const;

 private:
  // Scales v so that its horizontal and vertical parts respect the limits (direction kept).
  Vec3 LimitVelocity(const Vec3& v) const;
  // Position mode: the velocity toward target_ that can still brake to a stop on it (limited).
  Vec3 ApproachVelocity() const;

  TrajectoryLimits limits_;
  TrajectoryPoint ref_;
  Vec3 target_ = Vec3::Zero();
  bool velocity_mode_ = false;
};

}  // namespace swarmbox::flight
