// Airframe: a multirotor's physical description, read from trials/airframes/<name>.yaml.
//
//   Result<Airframe> af = LoadAirframe("trials/airframes/x500.yaml");
//   if (!af) { fprintf(stderr, "%s\n", af.error().ToString().c_str()); return 2; }  // file:line:col
//
// Rotor model (PX4 Gazebo MulticopterMotorModel conventions): the actuator value u in [0,1]
// commands omega_cmd = u * max_rot_velocity_rad_s; the rotor follows it as a first-order lag with
// time_constant_up_s (speeding up) / time_constant_down_s (slowing down); thrust along body +z is
// motor_constant * omega^2 [N]; the yaw reaction torque on the body is
// -dir * moment_constant * thrust [N m] about body +z, dir = +1 for a ccw rotor (seen from above),
// -1 for cw; rotor drag is -|omega| * rotor_drag_coefficient * v_perp [N] (v_perp: air-relative
// velocity of the rotor hub perpendicular to the rotor axis). The rotor list order is the actuator
// order.
//
// The YAML also carries a top-level `control:` mapping owned by the flight stack (controller
// gains); it is kept untouched in Airframe::control and never interpreted here.
#pragma once

#include <string>
#include <vector>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/physics/types.hpp"

namespace swarmbox::physics {

struct RotorSpec {
  Vec3 position_m;       // hub position in the body frame (FLU) [m]
  bool ccw = true;       // spin direction seen from above (+z): true = counter-clockwise
};

struct MotorSpec {
  double motor_constant = 0;          // thrust = motor_constant * omega^2 [N/(rad/s)^2]
  double moment_constant = 0;         // yaw torque / thrust [m]
  double time_constant_up_s = 0;      // first-order lag when speeding up [s]
  double time_constant_down_s = 0;    // first-order lag when slowing down [s]
  double max_rot_velocity_rad_s = 0;  // omega at u = 1 [rad/s]
  double rotor_drag_coefficient = 0;  // [N/((rad/s)(m/s))]
  double rolling_moment_coefficient = 0;  // torque -|omega| c v_perp [N m/((rad/s)(m/s))]
};

// Noise models. Every `*_std` is one standard deviation of white Gaussian noise per axis and per
// sample; biases are drawn once per drone (N(0, bias_std)) and then random-walk with
// bias_walk_std per sqrt(s). Rates are [Hz] of simulated time.
struct ImuSpec {
  double rate_hz = 250;
  double accel_noise_std_m_s2 = 0.02;
  double accel_bias_std_m_s2 = 0.05;
  double accel_bias_walk_std_m_s2 = 0.001;   // per sqrt(s)
  double gyro_noise_std_rad_s = 0.002;
  double gyro_bias_std_rad_s = 0.003;
  double gyro_bias_walk_std_rad_s = 0.0001;  // per sqrt(s)
};
struct BaroSpec {
  double rate_hz = 50;
  double noise_std_pa = 1.5;   // ~0.12 m at sea level
};
struct MagSpec {
  double rate_hz = 100;
  double noise_std_gauss = 0.005;
};
// What kind of solution the receiver delivers (sensors.gps.fix in the airframe YAML).
enum class GpsFix {
  kStandalone,  // a single-frequency standalone receiver (u-blox M8/M9 class)
  kRtk,         // RTK fixed with a base station's corrections (u-blox ZED-F9P)
};
struct GpsSpec {
  double rate_hz = 10;
  double horizontal_std_m = 0.8;   // total 1-sigma error of a fix, per horizontal axis
  double vertical_std_m = 1.5;
  double velocity_std_m_s = 0.1;   // per axis
  GpsFix fix = GpsFix::kStandalone;
  double rtk_baseline_km = 1.0;    // rtk: distance to the base station (the datasheet's ppm term)
};
// Makes `gps` an RTK-fixed ZED-F9P receiver `baseline_km` from its base: fix, baseline and the
// accuracy the datasheet gives for it (horizontal/vertical_std_m; see sensor_models.hpp
// RtkAccuracy). What the airframe parser does for `fix: rtk`.
void SetRtkFix(GpsSpec* gps, double baseline_km);
// The ZED-F9P's highest navigation rate in RTK mode [Hz] (datasheet UBX-17051259).
inline constexpr double kRtkMaxRateHz = 20.0;
// Downward camera: pinhole looking along body -z; image "up" is body +x (forward), image right is
// body -y (right). Rendered on demand (World::RenderCamera) at rate_hz by the caller.
struct CameraSpec {
  int width_px = 320;
  int height_px = 240;
  double hfov_rad = 1.2;           // horizontal field of view
  double rate_hz = 5;
  double noise_std = 4.0;          // Gaussian pixel noise, 8-bit levels (at unit analog gain)
  // Exposure time in full daylight [ms]; auto-exposure lengthens it as the light falls (up to 8x,
  // then raises the analog gain, and the noise with it, up to 4x). Motion blur is the image's
  // motion from the body rates over the exposure. 0: no motion blur.
  double exposure_ms = 0.0;
  double vignetting = 0.0;         // [0, 1): brightness lost in the image corners (radial, r^2)
  Vec3 offset_m{0, 0, -0.05};      // camera centre in the body frame [m]
};

// The stretcher-like slung payload (x8_heavy): its own rigid box body hanging on a sling from the
// hook, ball-jointed at the hook. sling_length_m is hook -> payload centre of mass.
struct PayloadSpec {
  std::string name;                // e.g. "stretcher"
  double mass_kg = 0;
  Vec3 size_m;                     // box, x along the stretcher's length
  Vec3 hook_m;                     // hook point in the drone body frame [m]
  double sling_length_m = 0;       // hook -> payload centre [m]
  double attach_tolerance_m = 0.5; // Attach() succeeds within sling_length_m +- this
};

struct Airframe {
  std::string name;
  std::string source;              // the file it came from ("" if built in code)
  double mass_kg = 0;              // drone without payload
  Vec3 inertia_kg_m2;              // principal moments (Ixx, Iyy, Izz) in the body frame
  Vec3 collision_box_m;            // collision box size [m], centred at collision_offset_m
  Vec3 collision_offset_m;
  double base_height_m = 0;        // body origin height above ground when landed [m]
  Vec3 body_drag_coefficient;      // quadratic body drag per body axis: F = -c |v| v [N/(m/s)^2]
  double hard_landing_speed_m_s = 1.5;  // ground impact above this: event=hard_landing
  double crash_speed_m_s = 4.0;         // any impact above this: event=crash, motors dead
  MotorSpec motor;
  std::vector<RotorSpec> rotors;
  ImuSpec imu;
  BaroSpec baro;
  MagSpec mag;
  GpsSpec gps;
  CameraSpec camera;
  std::vector<PayloadSpec> payloads;    // what this airframe can carry (x8_heavy: the stretcher)
  yaml::Node control;                   // flight-stack gains, passed through untouched (may be null)

  // Hover rotor speed with every rotor equal, for total mass mass_kg + extra_mass_kg [rad/s].
  double HoverRotorSpeed(double extra_mass_kg = 0, double gravity_m_s2 = 9.80665) const;
};

Result<Airframe> ParseAirframe(const yaml::Node& root, std::string source = {});
Result<Airframe> LoadAirframe(const std::string& path);

}  // namespace swarmbox::physics
