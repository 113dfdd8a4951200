#include "swarmbox/flight/flight_config.hpp"

#include <array>
#include <cmath>
#include <utility>

namespace swarmbox::flight {
namespace {

Error Bad(const yaml::Node& at, const std::string& msg) {
  return Error(ErrorCode::kInvalidArgument, msg, at.Where());
}

Result<double> NumberAt(const yaml::Node& map, std::string_view key, const std::string& what) {
  const yaml::Node* n = map.Find(key);
  if (n == nullptr) return Bad(map, what + ": missing '" + std::string(key) + "'");
  return n->AsDouble();
}

Result<Vec3> Vec3At(const yaml::Node& n) {
  std::array<double, 3> a{};
  if (auto s = yaml::Decode(n, &a); !s) return s.error();
  return Vec3(a[0], a[1], a[2]);
}

Status ReadControl(const yaml::Node& control, FlightConfig* cfg) {
  if (!control.is_mapping()) return Bad(control, "control: expected a mapping");
  yaml::MapReader top(control, "control");
  if (const yaml::Node* n = top.Child("position")) {
    yaml::MapReader r(*n, "control.position");
    PositionParams& p = cfg->position;
    std::array<double, 3> xy{p.vel_p.x(), p.vel_i.x(), p.vel_d.x()};
    std::array<double, 3> z{p.vel_p.z(), p.vel_i.z(), p.vel_d.z()};
    double tilt_deg = p.tilt_max_rad * 180.0 / kPi;
    r.Optional("xy_p", &p.xy_p).Optional("z_p", &p.z_p).Optional("vel_xy_pid", &xy)
        .Optional("vel_z_pid", &z).Optional("vel_max_xy_mps", &cfg->limits.vel_max_xy_mps)
        .Optional("vel_max_up_mps", &cfg->limits.vel_max_up_mps)
        .Optional("vel_max_down_mps", &cfg->limits.vel_max_down_mps)
        .Optional("acc_max_xy_mps2", &cfg->limits.acc_max_xy_mps2)
        .Optional("acc_max_z_mps2", &cfg->limits.acc_max_z_mps2)
        .Optional("tilt_max_deg", &tilt_deg).Optional("thrust_min", &cfg->thrust_min_frac)
        .Optional("thrust_max", &cfg->thrust_max_frac)
        .Optional("integral_max_mps2", &p.integral_max_mps2);
    SWARMBOX_TRY(r.Finish());
    p.vel_p = Vec3(xy[0], xy[0], z[0]);
    p.vel_i = Vec3(xy[1], xy[1], z[1]);
    p.vel_d = Vec3(xy[2], xy[2], z[2]);
    p.tilt_max_rad = tilt_deg * kPi / 180.0;
    if (!(tilt_deg > 0.0 && tilt_deg < 89.0)) return Bad(*n, "control.position.tilt_max_deg must be in (0, 89)");
    if (!(cfg->thrust_min_frac >= 0.0 && cfg->thrust_min_frac < cfg->thrust_max_frac &&
          cfg->thrust_max_frac <= 1.0)) {
      return Bad(*n, "control.position: need 0 <= thrust_min < thrust_max <= 1");
    }
  }
  if (const yaml::Node* n = top.Child("attitude")) {
    yaml::MapReader r(*n, "control.attitude");
    std::array<double, 3> rate_max_deg{cfg->attitude.rate_max_radps.x() * 180.0 / kPi,
                                       cfg->attitude.rate_max_radps.y() * 180.0 / kPi,
                                       cfg->attitude.rate_max_radps.z() * 180.0 / kPi};
    r.Optional("roll_p", &cfg->attitude.p.x()).Optional("pitch_p", &cfg->attitude.p.y())
        .Optional("yaw_p", &cfg->attitude.p.z()).Optional("rate_max_deg_s", &rate_max_deg);
    SWARMBOX_TRY(r.Finish());
    cfg->attitude.rate_max_radps = Vec3(rate_max_deg[0], rate_max_deg[1], rate_max_deg[2]) * kPi / 180.0;
  }
  if (const yaml::Node* n = top.Child("rate")) {
    yaml::MapReader r(*n, "control.rate");
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
  }
  if (const yaml::Node* n = top.Child("takeoff")) {
    yaml::MapReader r(*n, "control.takeoff");
    r.Optional("speed_mps", &cfg->takeoff_speed_mps);
    SWARMBOX_TRY(r.Finish());
  }
  if (const yaml::Node* n = top.Child("land")) {
    yaml::MapReader r(*n, "control.land");
    r.Optional("speed_mps", &cfg->land_speed_mps).Optional("slow_speed_mps", &cfg->land_slow_speed_mps)
        .Optional("slow_below_m", &cfg->land_slow_below_m);
    SWARMBOX_TRY(r.Finish());
  }
  if (const yaml::Node* n = top.Child("swing_damping")) {
    yaml::MapReader r(*n, "control.swing_damping");
    r.Optional("enabled", &cfg->swing.enabled).Optional("gain", &cfg->swing.gain)
        .Optional("shaper", &cfg->swing.shaper)
        .Optional("full_gain_load_ratio", &cfg->swing.full_gain_load_ratio);
    SWARMBOX_TRY(r.Finish());
    if (!(cfg->swing.full_gain_load_ratio >= 0.0)) {
      return Bad(*n, "control.swing_damping.full_gain_load_ratio must be >= 0");
    }
  }
  if (const yaml::Node* n = top.Child("hover_thrust")) {
    yaml::MapReader r(*n, "control.hover_thrust");
    HoverThrustParams& h = cfg->hover_thrust;
    r.Optional("process_noise", &h.process_noise).Optional("init_std", &h.init_std)
        .Optional("gate_sd", &h.gate_sd).Optional("thrust_lag_s", &cfg->hover_thrust_lag_s);
    SWARMBOX_TRY(r.Finish());
    if (!(h.process_noise > 0.0 && h.init_std > 0.0 && h.gate_sd > 0.0 && cfg->hover_thrust_lag_s >= 0.0)) {
      return Bad(*n, "control.hover_thrust: process_noise, init_std, gate_sd must be > 0, thrust_lag_s >= 0");
    }
  }
  if (const yaml::Node* n = top.Child("estimator")) {
    yaml::MapReader r(*n, "control.estimator");
    EstimatorParams& e = cfg->estimator;
    r.Optional("acc_kp", &e.acc_kp).Optional("acc_ki", &e.acc_ki).Optional("mag_kp", &e.mag_kp)
        .Optional("accel_noise_mps2", &e.accel_noise_mps2).Optional("accel_bias_walk", &e.accel_bias_walk)
        .Optional("gps_acc_deadband_mps2", &e.gps_acc_deadband_mps2).Optional("gps_acc_tau_s", &e.gps_acc_tau_s)
        .Optional("max_pos_correction_mps", &e.max_pos_correction_mps)
        .Optional("max_vel_correction_mps2", &e.max_vel_correction_mps2)
        .Optional("gps_noise_h_m", &e.gps_noise_h_m).Optional("gps_noise_v_m", &e.gps_noise_v_m)
        .Optional("gps_noise_floor_h_m", &e.gps_noise_floor_h_m)
        .Optional("gps_noise_floor_v_m", &e.gps_noise_floor_v_m)
        .Optional("gps_delay_s", &e.gps_delay_s).Optional("gps_frame_walk_h", &e.gps_frame_walk_h)
        .Optional("gps_bias_walk_h", &e.gps_bias_walk_h).Optional("gps_bias_walk_v", &e.gps_bias_walk_v)
        .Optional("baro_std_m", &e.baro_std_m).Optional("tilt_ref_from_filter", &e.tilt_ref_from_filter);
    SWARMBOX_TRY(r.Finish());
  }
  return top.Finish();
}

}  // namespace

Result<FlightConfig> ParseFlightConfig(const yaml::Node& root, std::string source) {
  if (!root.is_mapping()) return Bad(root, "airframe: expected a mapping");
  FlightConfig cfg;
  cfg.source = std::move(source);
  if (const yaml::Node* n = root.Find("name")) {
    auto s = n->AsString();
    if (!s) return s.error();
    cfg.airframe = *s;
  }
  auto mass = NumberAt(root, "mass_kg", "airframe");
  if (!mass) return mass.error();
  cfg.mass_kg = *mass;
  if (!(cfg.mass_kg > 0.0)) return Bad(root, "airframe: mass_kg must be > 0");
  if (root.Find("base_height_m") != nullptr) {
    auto bh = NumberAt(root, "base_height_m", "airframe");
    if (!bh) return bh.error();
    cfg.base_height_m = *bh;
  }

  const yaml::Node* motor = root.Find("motor");
  if (motor == nullptr || !motor->is_mapping()) return Bad(root, "airframe: missing 'motor' mapping");
  auto k = NumberAt(*motor, "motor_constant", "motor");
  auto km = NumberAt(*motor, "moment_constant", "motor");
  auto wmax = NumberAt(*motor, "max_rot_velocity_rad_s", "motor");
  if (!k) return k.error();
  if (!km) return km.error();
  if (!wmax) return wmax.error();

  const yaml::Node* rotors = root.Find("rotors");
  if (rotors == nullptr || !rotors->is_sequence()) return Bad(root, "airframe: missing 'rotors' list");
  for (const yaml::Node& r : rotors->items()) {
    const yaml::Node* pos = r.Find("position_m");
    const yaml::Node* dir = r.Find("direction");
    if (pos == nullptr || dir == nullptr) return Bad(r, "rotor: needs position_m and direction");
    auto p = Vec3At(*pos);
    if (!p) return p.error();
    auto d = dir->AsString();
    if (!d) return d.error();
    if (*d != "ccw" && *d != "cw") return Bad(*dir, "rotor direction must be ccw or cw, got '" + *d + "'");
    RotorGeometry g;
    g.pos_m = *p;
    g.spin_dir = *d == "ccw" ? 1 : -1;
    g.motor_constant = *k;
    g.moment_constant = *km;
    g.max_rot_velocity = *wmax;
    cfg.rotors.push_back(g);
  }

  // Sensor noise figures for the estimator (defaults if the file has none).
  if (const yaml::Node* sensors = root.Find("sensors")) {
    if (const yaml::Node* gps = sensors->Find("gps")) {
      if (const yaml::Node* h = gps->Find("horizontal_std_m")) {
        auto v = h->AsDouble();
        if (!v) return v.error();
        cfg.estimator.gps_pos_h_std_m = *v;
      }
      if (const yaml::Node* h = gps->Find("vertical_std_m")) {
        auto v = h->AsDouble();
        if (!v) return v.error();
        cfg.estimator.gps_pos_v_std_m = *v;
      }
      if (const yaml::Node* h = gps->Find("velocity_std_m_s")) {
        auto v = h->AsDouble();
        if (!v) return v.error();
        cfg.estimator.gps_vel_std_mps = *v;
      }
    }
  }
  if (const yaml::Node* payloads = root.Find("payloads")) {
    if (!payloads->is_sequence()) return Bad(*payloads, "payloads: expected a list");
    for (const yaml::Node& p : payloads->items()) {
      SlungPayload sp;
      if (const yaml::Node* n = p.Find("name")) {
        auto s = n->AsString();
        if (!s) return s.error();
        sp.name = *s;
      }
      auto m = NumberAt(p, "mass_kg", "payload");
      auto l = NumberAt(p, "sling_length_m", "payload");
      if (!m) return m.error();
      if (!l) return l.error();
      sp.mass_kg = *m;
      sp.sling_length_m = *l;
      if (const yaml::Node* h = p.Find("hook_m")) {
        auto v = Vec3At(*h);
        if (!v) return v.error();
        sp.hook_m = *v;
      }
      cfg.payloads.push_back(sp);
    }
  }
  if (const yaml::Node* control = root.Find("control"); control != nullptr && !control->is_null()) {
    SWARMBOX_TRY(ReadControl(*control, &cfg));
  }
  cfg.position.vel_max_xy_mps = cfg.limits.vel_max_xy_mps;
  cfg.position.vel_max_up_mps = cfg.limits.vel_max_up_mps;
  cfg.position.vel_max_down_mps = cfg.limits.vel_max_down_mps;
  return cfg;
}

Result<FlightConfig> LoadFlightConfig(const std::string& path) {
  auto doc = yaml::ParseFile(path);
  if (!doc) return doc.error();
  return ParseFlightConfig(*doc, path);
}

}  // namespace swarmbox::flight
