#include "swarmbox/flight/flight_config.hpp"

#include <array>
#include <cmath>
#include <utility>

namespace swarmbox::flight {
namespace {

Error Bad(const yaml::Node& at, const std::string& msg) {
  return Error(ErrorCode::kInvalidArgument, msg, at.Where());
}

// One reader per `control:` section, listed in ReadControl.
Status ReadPosition(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.position");
  PositionParams& p = cfg->position;
  std::array<double, 3> xy{p.vel_p.x(), p.vel_i.x(), p.vel_d.x()};
  std::array<double, 3> z{p.vel_p.z(), p.vel_i.z(), p.vel_d.z()};
  double tilt_deg = p.tilt_max_rad * 180.0 / kPi;
  r.Optional("xy_p", &p.xy_p).Optional("z_p", &p.z_p).Optional("vel_xy_pid", &xy)
      .Optional("vel_z_pid", &z).Optional("vel_max_xy_m_s", &cfg->limits.vel_max_xy_m_s)
      .Optional("vel_max_up_m_s", &cfg->limits.vel_max_up_m_s)
      .Optional("vel_max_down_m_s", &cfg->limits.vel_max_down_m_s)
      .Optional("acc_max_xy_m_s2", &cfg->limits.acc_max_xy_m_s2)
      .Optional("acc_max_z_m_s2", &cfg->limits.acc_max_z_m_s2)
      .Optional("tilt_max_deg", &tilt_deg).Optional("thrust_min", &cfg->thrust_min_frac)
      .Optional("thrust_max", &cfg->thrust_max_frac)
      .Optional("integral_max_m_s2", &p.integral_max_m_s2);
  SWARMBOX_TRY(r.Finish());
  p.vel_p = Vec3(xy[0], xy[0], z[0]);
  p.vel_i = Vec3(xy[1], xy[1], z[1]);
  p.vel_d = Vec3(xy[2], xy[2], z[2]);
  p.tilt_max_rad = tilt_deg * kPi / 180.0;
  if (!(tilt_deg > 0.0 && tilt_deg < 89.0)) return Bad(n, "control.position.tilt_max_deg must be in (0, 89)");
  if (!(cfg->thrust_min_frac >= 0.0 && cfg->thrust_min_frac < cfg->thrust_max_frac &&
        cfg->thrust_max_frac <= 1.0)) {
    return Bad(n, "control.position: need 0 <= thrust_min < thrust_max <= 1");
  }
  return Ok{};
}

Status ReadAttitude(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.attitude");
  std::array<double, 3> rate_max_deg{cfg->attitude.rate_max_rad_s.x() * 180.0 / kPi,
                                     cfg->attitude.rate_max_rad_s.y() * 180.0 / kPi,
                                     cfg->attitude.rate_max_rad_s.z() * 180.0 / kPi};
  r.Optional("roll_p", &cfg->attitude.p.x()).Optional("pitch_p", &cfg->attitude.p.y())
      .Optional("yaw_p", &cfg->attitude.p.z()).Optional("rate_max_deg_s", &rate_max_deg);
  SWARMBOX_TRY(r.Finish());
  cfg->attitude.rate_max_rad_s = Vec3(rate_max_deg[0], rate_max_deg[1], rate_max_deg[2]) * kPi / 180.0;
  return Ok{};
}

Status ReadRate(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.rate");
  RateGains& g = cfg->rate;
  std::array<double, 3> roll{g.p.x(), g.i.x(), g.d.x()}, pitch{g.p.y(), g.i.y(), g.d.y()},
      yaw{g.p.z(), g.i.z(), g.d.z()}, lim{g.integrator_limit.x(), g.integrator_limit.y(),
                                          g.integrator_limit.z()};
  r.Optional("roll_pid", &roll).Optional("pitch_pid", &pitch).Optional("yaw_pid", &yaw)
      .Optional("integrator_limit", &lim);
  SWARMBOX_TRY(r.Finish());
  g.p = Vec3(roll[0], pitch[0], yaw[0]);
  g.i = Vec3(roll[1], pitch[1], yaw[1]);
  g.d = Vec3(roll[2], pitch[2], yaw[2]);
  g.integrator_limit = Vec3(lim[0], lim[1], lim[2]);
  return Ok{};
}

Status ReadTakeoff(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.takeoff");
  r.Optional("speed_m_s", &cfg->takeoff_speed_m_s);
  return r.Finish();
}

Status ReadLand(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.land");
  r.Optional("speed_m_s", &cfg->land_speed_m_s).Optional("slow_speed_m_s", &cfg->land_slow_speed_m_s)
      .Optional("slow_below_m", &cfg->land_slow_below_m);
  return r.Finish();
}

Status ReadSwingDamping(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.swing_damping");
  r.Optional("enabled", &cfg->swing.enabled).Optional("gain", &cfg->swing.gain)
      .Optional("shaper", &cfg->swing.shaper)
      .Optional("full_gain_load_ratio", &cfg->swing.full_gain_load_ratio);
  SWARMBOX_TRY(r.Finish());
  if (!(cfg->swing.full_gain_load_ratio >= 0.0)) {
    return Bad(n, "control.swing_damping.full_gain_load_ratio must be >= 0");
  }
  return Ok{};
}

Status ReadHoverThrust(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.hover_thrust");
  HoverThrustParams& h = cfg->hover_thrust;
  r.Optional("process_noise", &h.process_noise).Optional("init_std", &h.init_std)
      .Optional("gate_sd", &h.gate_sd).Optional("thrust_lag_s", &cfg->hover_thrust_lag_s);
  SWARMBOX_TRY(r.Finish());
  if (!(h.process_noise > 0.0 && h.init_std > 0.0 && h.gate_sd > 0.0 && cfg->hover_thrust_lag_s >= 0.0)) {
    return Bad(n, "control.hover_thrust: process_noise, init_std, gate_sd must be > 0, thrust_lag_s >= 0");
  }
  return Ok{};
}

Status ReadEstimator(const yaml::Node& n, FlightConfig* cfg) {
  yaml::MapReader r(n, "control.estimator");
  EstimatorParams& e = cfg->estimator;
  r.Optional("acc_kp", &e.acc_kp).Optional("acc_ki", &e.acc_ki).Optional("mag_kp", &e.mag_kp)
      .Optional("accel_noise_m_s2", &e.accel_noise_m_s2).Optional("accel_bias_walk", &e.accel_bias_walk)
      .Optional("gps_acc_deadband_m_s2", &e.gps_acc_deadband_m_s2).Optional("gps_acc_tau_s", &e.gps_acc_tau_s)
      .Optional("max_pos_correction_m_s", &e.max_pos_correction_m_s)
      .Optional("max_vel_correction_m_s2", &e.max_vel_correction_m_s2)
      .Optional("gps_noise_h_m", &e.gps_noise_h_m).Optional("gps_noise_v_m", &e.gps_noise_v_m)
      .Optional("gps_noise_floor_h_m", &e.gps_noise_floor_h_m)
      .Optional("gps_noise_floor_v_m", &e.gps_noise_floor_v_m)
      .Optional("gps_delay_s", &e.gps_delay_s).Optional("gps_frame_walk_h", &e.gps_frame_walk_h)
      .Optional("gps_bias_walk_h", &e.gps_bias_walk_h).Optional("gps_bias_walk_v", &e.gps_bias_walk_v)
      .Optional("baro_std_m", &e.baro_std_m).Optional("tilt_ref_from_filter", &e.tilt_ref_from_filter);
  return r.Finish();
}

Status ReadControl(const yaml::Node& control, FlightConfig* cfg) {
  if (!control.is_mapping()) return Bad(control, "control: expected a mapping");
  using SectionReader = Status (*)(const yaml::Node&, FlightConfig*);
  const std::pair<const char*, SectionReader> sections[] = {
      {"position", ReadPosition},
      {"attitude", ReadAttitude},
      {"rate", ReadRate},
      {"takeoff", ReadTakeoff},
      {"land", ReadLand},
      {"swing_damping", ReadSwingDamping},
      {"hover_thrust", ReadHoverThrust},
      {"estimator", ReadEstimator},
  };
  yaml::MapReader top(control, "control");
  for (const auto& [key, read] : sections) {
    if (const yaml::Node* n = top.Child(key)) SWARMBOX_TRY(read(*n, cfg));
  }
  return top.Finish();
}

}  // namespace

Result<FlightConfig> FlightConfigFrom(const airframe::Airframe& af) {
  FlightConfig cfg;
  cfg.airframe = af.name;
  cfg.source = af.source;
  cfg.mass_kg = af.mass_kg;
  cfg.base_height_m = af.base_height_m;
  for (const airframe::RotorSpec& r : af.rotors) {
    RotorGeometry g;
    g.pos_m = Vec3(r.position_m.x, r.position_m.y, r.position_m.z);
    g.spin_dir = r.ccw ? 1 : -1;
    g.motor_constant = af.motor.motor_constant;
    g.moment_constant = af.motor.moment_constant;
    g.max_rot_velocity = af.motor.max_rot_velocity_rad_s;
    cfg.rotors.push_back(g);
  }
  // Sensor noise figures for the estimator: the standalone receiver's accuracy (its defaults are
  // the airframe's). With fix: rtk the estimator keeps its standalone prior, as it always has.
  if (af.gps.fix == airframe::GpsFix::kStandalone) {
    cfg.estimator.gps_pos_h_std_m = af.gps.horizontal_std_m;
    cfg.estimator.gps_pos_v_std_m = af.gps.vertical_std_m;
  }
  cfg.estimator.gps_vel_std_m_s = af.gps.velocity_std_m_s;
  cfg.payloads = af.payloads;
  if (!af.control.is_null()) SWARMBOX_TRY(ReadControl(af.control, &cfg));
  cfg.position.vel_max_xy_m_s = cfg.limits.vel_max_xy_m_s;
  cfg.position.vel_max_up_m_s = cfg.limits.vel_max_up_m_s;
  cfg.position.vel_max_down_m_s = cfg.limits.vel_max_down_m_s;
  return cfg;
}

Result<FlightConfig> ParseFlightConfig(const yaml::Node& root, std::string source) {
  auto af = airframe::ParseAirframe(root, std::move(source));
  if (!af) return af.error();
  return FlightConfigFrom(*af);
}

Result<FlightConfig> LoadFlightConfig(const std::string& path) {
  auto af = airframe::LoadAirframe(path);
  if (!af) return af.error();
  return FlightConfigFrom(*af);
}

}  // namespace swarmbox::flight
