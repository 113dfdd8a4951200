// Swing damping for a slung payload (x8_heavy with the stretcher), from the vehicle's own motion.
//
// Two complementary parts, both optional:
//  1. InputShaper: a zero-vibration-derivative (ZVD) shaper on the position reference. The
//     reference is convolved with three impulses (1, 2K, K^2)/(1+K)^2 at 0, T/2, T (T the swing
//     period), so the commanded motion carries (almost) no energy at the pendulum frequency.
//     ZVD tolerates about +-20 % error in the period, enough for the drone/payload coupling.
//  2. SwingObserver + active damping: the cable's horizontal pull shows up in the accelerometer
//     (thrust is along body z, so the body x/y specific force is the cable force perpendicular to
//     body z, plus a little drag, divided by the drone's mass). From it and the attitude the
//     observer measures the sling direction; a pendulum model driven by the drone's own
//     acceleration (s'' = -(g/L) s - a_hook/L, s = horizontal payload offset / L) filters it and
//     gives the swing rate. Moving the hook with the swing (a = k s', k = gain * sqrt(g L),
//     like a crane operator) adds damping ratio ~ gain/2 to the pendulum.
// No cable sensor: only IMU, attitude and the estimated acceleration and mass are used.
// The load is the flight controller's estimate (hover thrust estimate minus the empty vehicle):
// it sizes the cable tension in the observer and, through LoadScaledDampingGain, the active
// damping, so a light load (the empty stretcher) is not driven by its own noisy swing estimate.
//
//   SwingObserver obs;  obs.Configure(sling_length_m, drone_mass_kg);
//   obs.Update(imu_specific_force_body, attitude, accel_world, payload_mass_kg, dt_s);
//   Vec3 a_ff = obs.DampingAcceleration(gain);   // add to the acceleration feed-forward
#pragma once

#include <cstddef>
#include <vector>

#include "swarmbox/flight/trajectory.hpp"
#include "swarmbox/flight/types.hpp"

namespace swarmbox::flight {

// Active damping gain for the estimated load [kg] under a drone of drone_mass_kg: `gain` from a
// payload/drone mass ratio of `full_ratio` up, proportionally less below it (0 for no load;
// full_ratio <= 0: always `gain`). The swing rate is observed through the cable's pull on the
// drone, so its error grows as drone mass / payload mass (x8_heavy: 1.5x with the 80 kg loaded
// stretcher, 8x with the 15 kg empty one); at full gain the empty stretcher's noisy estimate
// drives the hook into a 20 deg swing that the ZVD shaper alone keeps under 4 deg.
double LoadScaledDampingGain(double gain, double payload_mass_kg, double drone_mass_kg, double full_ratio);

class InputShaper {
 public:
  // period_s: the swing period to cancel; damping_ratio of the pendulum (0 for undamped);
  // dt_s: the fixed step Shape() is called with. Allocates the delay line (call at start-up).
  void Configure(double period_s, double damping_ratio, double dt_s);
  bool configured() const { return !buffer_.empty(); }
  // Restarts the delay line filled with `p` (no motion in flight).
  void Reset(const TrajectoryPoint& p);
  // One step: pushes the raw reference and returns the shaped one. No allocation.
  TrajectoryPoint Shape(const TrajectoryPoint& raw);
  double delay_s() const { return delay_s_; }

 private:
  std::vector<TrajectoryPoint> buffer_;  // ring, capacity = T/dt + 1
  std::size_t head_ = 0;                 // index of the newest sample
  std::size_t half_ = 0;                 // T/2 in steps
  std::size_t full_ = 0;                 // T in steps
  double a0_ = 1.0, a1_ = 0.0, a2_ = 0.0;
  double delay_s_ = 0.0;
};

class SwingObserver {
 public:
  void Configure(double sling_length_m, double drone_mass_kg);
  bool configured() const { return length_m_ > 0.0; }
  void Reset();
  // f_body: IMU specific force, body FLU [m/s^2]; att: body -> world; acc_world: the drone's
  // estimated acceleration, ENU [m/s^2]; payload_mass_kg: estimated load (<= 0: none, observer
  // rests); dt_s: step [s].
  void Update(const Vec3& f_body, const Quat& att, const Vec3& acc_world, double payload_mass_kg,
              double dt_s);
  // Swinging part of the horizontal payload offset over sling length (world x, y; z = 0),
  // ~ the swing angles [rad]; swing_angle_rad() adds the steady lean.
  const Vec3& swing() const { return s_; }
  const Vec3& measured_swing() const { return s_meas_; }
  double swing_angle_rad() const;
  // Hook acceleration that damps the swing: gain * sqrt(g L) * s' (world, horizontal) [m/s^2].
  Vec3 DampingAcceleration(double gain) const;

 private:
  double length_m_ = 0.0;
  double drone_mass_kg_ = 0.0;
  Vec3 s_ = Vec3::Zero();
  Vec3 s_dot_ = Vec3::Zero();
  Vec3 s_meas_ = Vec3::Zero();
  Vec3 offset_ = Vec3::Zero();   // steady lean (not swinging)
  bool active_ = false;
};

}  // namespace swarmbox::flight
