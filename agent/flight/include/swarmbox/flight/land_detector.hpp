// LandDetector: whether the drone is on the ground, clear of it, or has touched down (the role of
// PX4's land_detector module, MulticopterLandDetector, reduced to what this stack flies: take-off
// from a known spot, land straight down).
//
// Three answers, each from named thresholds:
//   - GroundContactPhase(airborne_s): the first ground_contact_s after arming; the rate loop keeps
//     its integrators still then (PX4 freezes them while landed / maybe_landed).
//   - InAir(...): latched until Reset() (take-off) once the drone has been armed in_air_after_s
//     and is in_air_height_m above the take-off point, or sinking faster than sinking_m_s (an
//     airborne start whose first thrust was too low for its load). The hover thrust estimator
//     learns only then (PX4 feeds mc_hover_thrust_estimator the land detector's in-air state).
//   - UpdateTouchdown(...): in Land, after land_settle_s in the mode, asked to descend faster than
//     descend_cmd_m_s, moving vertically slower than vz_max_m_s and with the collective thrust below
//     low_thrust_ratio of the weight (of the estimated mass), for trigger_time_s in a row: landed.
//
//   LandDetector ld;                                  // params: PX4-like defaults below
//   at take-off: ld.Reset();     at the Land command: ld.StartLanding();
//   each step in the air: if (ld.InAir(airborne_s, height_m, vz_m_s)) { feed the estimator }
//   in Land: if (ld.UpdateTouchdown(dt, in_land_s, vz, vz_cmd, thrust_n, mass_kg)) { disarm }
//
// Pure: no allocation, no exceptions, deterministic; units [s], [m], [m/s], [N], z up.
#pragma once

namespace swarmbox::flight {

struct LandDetectorParams {
  double trigger_time_s = 1.0;      // landed conditions held this long (PX4 LNDMC_TRIG_TIME)
  double land_settle_s = 1.0;       // time in Land before a touch-down may be detected [s]
  double vz_max_m_s = 0.15;         // "not moving vertically" below this (role of PX4 LNDMC_Z_VEL_MAX)
  double descend_cmd_m_s = 0.1;     // asked to descend faster than this (PX4: the descend flag)
  double low_thrust_ratio = 0.85;   // thrust below this fraction of the weight (role of PX4 LNDMC_LOW_T_THR)
  double in_air_after_s = 1.0;      // armed at least this long before "in air" [s]
  double in_air_height_m = 0.5;     // above the take-off point: in the air [m]
  double sinking_m_s = 0.3;         // or sinking faster than this [m/s]
  double ground_contact_s = 0.5;    // after arming: still in ground contact (rate integrators held) [s]
};

class LandDetector {
 public:
  LandDetector() = default;
  explicit LandDetector(const LandDetectorParams& params) : params_(params) {}

  const LandDetectorParams& params() const { return params_; }

  // A take-off: not in the air yet.
  void Reset() { in_air_ = false; }
  // The Land command: the touch-down timer starts over.
  void StartLanding() { landed_timer_s_ = 0.0; }

  bool GroundContactPhase(double airborne_s) const { return airborne_s < params_.ground_contact_s; }
  // Latches true (until Reset) from the armed time, the height above the take-off point and the
  // vertical velocity (up +).
  bool InAir(double airborne_s, double height_m, double vz_m_s);
  bool in_air() const { return in_air_; }

  // One step in Land: time in the mode, estimated and commanded vertical velocity (up +), the
  // collective thrust delivered last step and the estimated mass whose weight it is compared with.
  // True once landed.
  bool UpdateTouchdown(double dt_s, double in_land_s, double vz_m_s, double vz_cmd_m_s, double thrust_n,
                       double mass_kg);

 private:
  LandDetectorParams params_;
  bool in_air_ = false;
  double landed_timer_s_ = 0.0;
};

}  // namespace swarmbox::flight
