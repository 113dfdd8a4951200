// SensorSample: what a drone's flight controller sees at one control step.
//
// Each sensor updates at its own rate (Airframe::imu/baro/mag/gps rate_hz); between updates the
// last value is repeated with `fresh == false`. Values carry the noise and biases configured in
// the airframe, drawn from a per-drone generator seeded from the world seed, so a run is
// reproducible. Frames: body FLU, world ENU.
#pragma once

#include <cstdint>

#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

struct ImuSample {
  bool fresh = false;
  Vec3 accel_m_s2;      // specific force in body FLU (at rest, level: (0, 0, +g)) [m/s^2]
  Vec3 gyro_rad_s;      // body rates in body FLU [rad/s]
};

struct BaroSample {
  bool fresh = false;
  double pressure_pa = 0;     // static pressure (ISA from home_alt_m + z) [Pa]
  double altitude_m = 0;      // altitude above the world origin (ENU z) from the noisy pressure [m]
  double temperature_c = 15;  // ISA temperature at altitude [deg C]
};

struct MagSample {
  bool fresh = false;
  Vec3 field_gauss;     // Earth field in body FLU [gauss]
};

struct GpsSample {
  bool fresh = false;   // a new fix (or a new no-fix report) arrived at this step
  bool valid = false;   // false while the GPS drops out (no fix): position/velocity meaningless
  int fix_type = 0;     // 0 no fix, 3 3D fix
  Vec3 position_m;      // ENU relative to the world home [m]
  Vec3 velocity_m_s;    // ENU [m/s]
  double lat_deg = 0;   // WGS84, flat-earth around home
  double lon_deg = 0;
  double alt_m = 0;     // AMSL [m]
  double h_acc_m = 0;   // the receiver's reported accuracy (u-blox hAcc, PX4's eph): total
                        // 1-sigma error per horizontal axis of this fix [m] (the airframe's,
                        // the RTK model's for `fix: rtk`, or degraded)
  double v_acc_m = 0;   // the same vertically (vAcc, epv) [m]
};

struct SensorSample {
  std::int64_t time_ns = 0;   // simulated time of the sample
  std::uint64_t step = 0;     // control step index (lockstep: the command answers this step)
  ImuSample imu;
  BaroSample baro;
  MagSample mag;
  GpsSample gps;
};

// Ground truth of one drone (truth.csv, tests). Not for the flight stack's control loop.
struct DroneTruth {
  Vec3 position_m;            // body origin, ENU [m]
  Vec3 velocity_m_s;          // ENU [m/s]
  Quat attitude;              // body -> world
  Vec3 body_rates_rad_s;      // body FLU [rad/s]
  Vec3 accel_m_s2;            // world ENU acceleration over the last control step [m/s^2]
  double rotor_speed_rad_s[8] = {};  // first rotor_count entries valid
  int rotor_count = 0;
  bool payload_attached = false;
  double payload_swing_rad = 0;      // sling angle from the vertical (0 when no payload attached)
  Vec3 payload_position_m;           // payload centre, if the drone has one
  Quat payload_attitude;             // payload box -> world, if the drone has one
  double payload_mass_kg = 0;        // the payload body's simulated mass, attached or not [kg]
  bool crashed = false;
  bool lost = false;
};

}  // namespace swarmbox::physics
