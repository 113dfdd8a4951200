// The airframe model: one multirotor's description, read from trials/airframes/<name>.yaml once and
// validated once, for both programs: the physics server simulates it (ODE bodies, rotors, sensors,
// the rendered camera, slung payloads), the agent configures its flight stack, perception and
// mission from it (agent/flight FlightConfigFrom, agent/app). One struct per concept: the camera
// (CameraSpec), a payload (PayloadSpec), where a payload lies on the ground (PayloadOnGround).
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
// The file is read strictly: an unknown top-level key is an error. Each top-level section has one
// reader in src/airframe.cpp (the kSections table: collision, impact, motor, rotors, sensors,
// camera, stereo, payloads); a new section is a field here, a parse function in its own file, and
// one row in that table (airframe/README.md, "Adding a section"; `stereo:` is built so). The top-level
// `control:` mapping is owned by the flight stack (controller gains): it is kept untouched in
// Airframe::control and interpreted only by agent/flight (FlightConfigFrom).
#pragma once

#include <string>
#include <string_view>
#include <vector>

#include "swarmbox/airframe/stereo_spec.hpp"
#include "swarmbox/airframe/thermal_spec.hpp"
#include "swarmbox/airframe/vec3.hpp"
#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::airframe {

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
// Total 1-sigma error of a fix per axis [m].
struct GpsAccuracy {
  double h;  // per horizontal axis
  double v;  // vertical
};
// RTK fixed, u-blox ZED-F9P (datasheet UBX-17051259, "Performance"): 0.01 m + 1 ppm of the
// baseline, CEP horizontally, R50 vertically; per axis a circular Gaussian's CEP is 1.1774 sigma,
// a 1-D R50 0.6745 sigma (at 1 km: h 0.0093 m, v 0.0163 m). The physics server's GPS error model
// splits this total (physics_server/src/sensor_models.hpp).
inline constexpr double kRtkConstantM = 0.01;
inline constexpr double kRtkPpm = 1e-6;
inline constexpr double kCepPerSigma = 1.1774;  // sqrt(2 ln 2): CEP of a circular Gaussian
inline constexpr double kR50PerSigma = 0.6745;  // median |x| of a 1-D Gaussian
GpsAccuracy RtkAccuracy(double baseline_km);
// Makes `gps` an RTK-fixed ZED-F9P receiver `baseline_km` from its base: fix, baseline and the
// accuracy the datasheet gives for it (horizontal/vertical_std_m = RtkAccuracy). What the airframe
// parser does for `fix: rtk`.
void SetRtkFix(GpsSpec* gps, double baseline_km);
// The ZED-F9P's highest navigation rate in RTK mode [Hz] (datasheet UBX-17051259).
inline constexpr double kRtkMaxRateHz = 20.0;
// Downward camera (`camera:`): pinhole looking along body -z; image "up" is body +x (forward), image
// right is body -y (right). The physics server renders it on demand (World::RenderCamera) at
// rate_hz, or with trigger_distance_m by distance travelled (physics_server/app/camera_trigger.hpp);
// the agent geolocates its detections with offset_m. Valid: 16..4096 pixels a side,
// 0 < hfov_rad < 0.9 pi, rate_hz > 0, noise_std, exposure_ms, trigger_distance_m and
// trigger_interval_max_s >= 0, 0 <= vignetting < 1.
struct CameraSpec {
  int width_px = 320;
  int height_px = 240;
  double hfov_rad = 1.2;           // horizontal field of view
  double rate_hz = 5;              // the frame rate; with trigger_distance_m its upper bound [Hz]
  // Distance-triggered capture (PX4 TRIG_MODE 3, TRIG_DISTANCE): a frame once the camera has moved
  // this far horizontally since the last one [m]; 0: every frame of rate_hz.
  double trigger_distance_m = 0;
  // With trigger_distance_m: a frame at least this often while the drone does not move (hover,
  // climb, hold) [s]; 0: none.
  double trigger_interval_max_s = 0;
  double noise_std = 4.0;          // Gaussian pixel noise, 8-bit levels (at unit analog gain)
  // Exposure time in full daylight [ms]; auto-exposure lengthens it as the light falls (up to 8x,
  // then raises the analog gain, and the noise with it, up to 4x). Motion blur is the image's
  // motion from the body rates over the exposure. 0: no motion blur.
  double exposure_ms = 0.0;
  double vignetting = 0.0;         // [0, 1): brightness lost in the image corners (radial, r^2)
  Vec3 offset_m{0, 0, -0.05};      // camera centre in the body frame [m]
};

// A payload the airframe can carry (`payloads:` list; x8_heavy: the stretcher): its own rigid box
// body hanging on a sling from the hook, ball-jointed at the hook. sling_length_m is hook ->
// payload centre of mass. The physics server simulates it; the flight stack damps its swing.
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
  bool has_camera = false;              // the file has a `camera:` mapping (else `camera` is the default)
  StereoSpec stereo;                    // `stereo:` (OAK-D Pro depth); absent: stereo.enabled == false
  ThermalSpec thermal;                  // `thermal:` (FLIR Boson 320 LWIR); absent: thermal.enabled == false
  std::vector<PayloadSpec> payloads;    // what this airframe can carry (x8_heavy: the stretcher)
  yaml::Node control;                   // flight-stack gains, passed through untouched (may be null)

  // Hover rotor speed with every rotor equal, for total mass mass_kg + extra_mass_kg [rad/s].
  double HoverRotorSpeed(double extra_mass_kg = 0, double gravity_m_s2 = 9.80665) const;
  // The payload named `payload_name`; kInvalidArgument "airframe <name> has no payload '<payload_name>'".
  Result<const PayloadSpec*> FindPayload(std::string_view payload_name) const;
};

// Where a payload that starts on the ground lies (not hanging): laid flat beside the drone on the
// world -y side, (collision box y + payload y) / 2 + kGroundPayloadGapM from the spawn point, resting
// on the ground. The physics server places it there (World::AddDrone); the SAR lifter flies to it.
inline constexpr double kGroundPayloadGapM = 0.5;
struct GroundPlacement {
  double offset_x_m = 0;      // payload centre - spawn ground point, world ENU [m]
  double offset_y_m = 0;
  double half_height_m = 0;   // payload centre above the ground [m]
};
GroundPlacement PayloadOnGround(const Airframe& af, const PayloadSpec& payload);

Result<Airframe> ParseAirframe(const yaml::Node& root, std::string source = {});
Result<Airframe> LoadAirframe(const std::string& path);

}  // namespace swarmbox::airframe
