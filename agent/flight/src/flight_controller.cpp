#include "swarmbox/flight/flight_controller.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

namespace swarmbox::flight {
namespace {

constexpr double kArriveTol_m = 0.3;
constexpr double kArriveSpeed_mps = 0.3;
constexpr double kYawRateLimit_radps = 1.5;
constexpr double kAngAccelCutoff_hz = 30.0;

bool Flying(FlightMode m) {
  return m == FlightMode::kTakeoff || m == FlightMode::kHold || m == FlightMode::kPosition ||
         m == FlightMode::kVelocity || m == FlightMode::kTrajectory || m == FlightMode::kLand;
}

bool NoInfinity(const Vec3& v) { return !std::isinf(v.x()) && !std::isinf(v.y()) && !std::isinf(v.z()); }

bool ExactlyAllSet(const Vec3& v) { return v.allFinite(); }
bool AllUnset(const Vec3& v) { return std::isnan(v.x()) && std::isnan(v.y()) && std::isnan(v.z()); }

}  // namespace

std::string_view FlightModeName(FlightMode mode) {
  switch (mode) {
    case FlightMode::kInit: return "init";
    case FlightMode::kIdle: return "idle";
    case FlightMode::kTakeoff: return "takeoff";
    case FlightMode::kHold: return "hold";
    case FlightMode::kPosition: return "position";
    case FlightMode::kVelocity: return "velocity";
    case FlightMode::kTrajectory: return "trajectory";
    case FlightMode::kLand: return "land";
    case FlightMode::kLanded: return "landed";
  }
  return "unknown";
}

std::string_view FlightEventName(FlightEventKind kind) {
  switch (kind) {
    case FlightEventKind::kReady: return "flight_ready";
    case FlightEventKind::kTakeoff: return "takeoff";
    case FlightEventKind::kHover: return "hover";
    case FlightEventKind::kArrived: return "arrived";
    case FlightEventKind::kLanding: return "landing";
    case FlightEventKind::kLanded: return "landed";
    case FlightEventKind::kModeChange: return "mode";
    case FlightEventKind::kGpsLost: return "gps_lost";
    case FlightEventKind::kGpsRecovered: return "gps_recovered";
    case FlightEventKind::kRejected: return "setpoint_rejected";
  }
  return "unknown";
}

Setpoint Setpoint::FromTrajectory(const TrajectoryTarget& t) {
  const bool no_yawspeed = std::isnan(t.yawspeed_radps);
  const bool yaw_ok = !std::isinf(t.yaw_rad);
  if (ExactlyAllSet(t.pos_m) && AllUnset(t.vel_mps) && AllUnset(t.acc_mps2) && no_yawspeed && yaw_ok) {
    return Position(t.pos_m, t.yaw_rad);
  }
  if (AllUnset(t.pos_m) && ExactlyAllSet(t.vel_mps) && AllUnset(t.acc_mps2) && no_yawspeed && yaw_ok) {
    return Velocity(t.vel_mps, t.yaw_rad);
  }
  return Trajectory(t);
}

Result<FlightController> FlightController::Create(const FlightConfig& config,
                                                  const ControllerOptions& options) {
  auto mixer = Mixer::Create(config.rotors);
  if (!mixer) return mixer.error().Context("airframe " + config.airframe);
  if (!(options.control_dt_s > 0.0)) {
    return Error(ErrorCode::kInvalidArgument, "control_dt_s must be > 0");
  }
  const double hover_frac = (config.mass_kg + options.payload_mass_kg) * kGravity_mps2 / mixer->max_thrust_n();
  if (hover_frac > config.thrust_max_frac) {
    return Error(ErrorCode::kInvalidArgument,
                 "airframe " + config.airframe + " cannot hover with " +
                     std::to_string(config.mass_kg + options.payload_mass_kg) + " kg: needs " +
                     std::to_string(hover_frac * 100.0) + " % of its maximum thrust");
  }
  return FlightController(config, options, std::move(*mixer));
}

FlightController::FlightController(const FlightConfig& config, const ControllerOptions& options, Mixer mixer)
    : config_(config), options_(options), mixer_(std::move(mixer)) {
  EstimatorParams ep = config_.estimator;
  if (options_.has_start_pos) {
    ep.has_initial_pos = true;
    ep.initial_pos_m = options_.start_pos_m;
  }
  estimator_ = Estimator(ep);
  PositionParams pp = config_.position;
  pp.thrust_min_n = config_.thrust_min_frac * mixer_.max_thrust_n();
  pp.thrust_max_n = config_.thrust_max_frac * mixer_.max_thrust_n();
  // The controller may chase the reference a little faster than the reference itself moves.
  pp.vel_max_xy_mps = 1.2 * config_.limits.vel_max_xy_mps;
  pp.vel_max_up_mps = 1.2 * config_.limits.vel_max_up_mps;
  pp.vel_max_down_mps = 1.2 * config_.limits.vel_max_down_mps;
  position_.SetParams(pp);
  attitude_.SetGains(config_.attitude);
  rate_.SetGains(config_.rate);
  trajectory_.SetLimits(config_.limits);
  // Hover thrust estimate: between half the empty vehicle and the most the position loop may ask.
  HoverThrustParams hp = config_.hover_thrust;
  hp.min_hover = 0.5 * config_.mass_kg * kGravity_mps2 / mixer_.max_thrust_n();
  hp.max_hover = config_.thrust_max_frac;
  hte_.SetParams(hp);
  hte_.Reset(HoverThrustFor(config_.mass_kg + options_.payload_mass_kg));
  mass_kg_ = MassFor(hte_.hover_thrust());
  output_.count = mixer_.rotor_count();

  // Swing damping: needs a slung payload in the airframe and both switches on.
  const airframe::PayloadSpec* payload = nullptr;
  for (const airframe::PayloadSpec& p : config_.payloads) {
    if (options_.payload_name[0] == '\0' || p.name == options_.payload_name) {
      payload = &p;
      break;
    }
  }
  damping_on_ = payload != nullptr && config_.swing.enabled && options_.swing_damping;
  if (damping_on_) {
    // Pivot at the hook; the swing period of the pendulum under a position-held drone.
    const double length = payload->sling_length_m;
    swing_.Configure(length, config_.mass_kg);
    if (config_.swing.shaper) {
      const double period = 2.0 * kPi * std::sqrt(length / kGravity_mps2);
      shaper_.Configure(period, 0.0, options_.control_dt_s);
    }
  }
}

double FlightController::HoverThrustFor(double mass_kg) const {
  return mass_kg * kGravity_mps2 / mixer_.max_thrust_n();
}

double FlightController::MassFor(double hover_thrust) const {
  return hover_thrust * mixer_.max_thrust_n() / kGravity_mps2;
}

void FlightController::SetPayloadMass(double payload_mass_kg) {
  if (!(payload_mass_kg >= 0.0) || !std::isfinite(payload_mass_kg)) return;
  options_.payload_mass_kg = payload_mass_kg;
  // A prior as uncertain as a fresh start: the estimator corrects it within seconds when the
  // announced load is not what the drone lifts (a refused hook, a heavier evacuee).
  hte_.SetPrior(HoverThrustFor(config_.mass_kg + payload_mass_kg), config_.hover_thrust.init_std);
  mass_kg_ = MassFor(hte_.hover_thrust());
}

void FlightController::Emit(FlightEventKind kind, double t_s) {
  FlightEvent e;
  e.kind = kind;
  e.t_s = t_s;
  e.mode = mode_;
  e.pos_m = estimator_.state().pos_m;
  if (ev_count_ == kEventCapacity) {  // full: drop the oldest
    ev_head_ = (ev_head_ + 1) % kEventCapacity;
    --ev_count_;
  }
  events_[(ev_head_ + ev_count_) % kEventCapacity] = e;
  ++ev_count_;
}

bool FlightController::PopEvent(FlightEvent* out) {
  if (ev_count_ == 0) return false;
  *out = events_[ev_head_];
  ev_head_ = (ev_head_ + 1) % kEventCapacity;
  --ev_count_;
  return true;
}

void FlightController::SetMode(FlightMode mode, double t_s) {
  if (mode == mode_) return;
  mode_ = mode;
  mode_since_s_ = t_s;
  Emit(FlightEventKind::kModeChange, t_s);
}

void FlightController::ResetControllers() {
  position_.ResetIntegral();
  rate_.ResetIntegral();
  swing_.Reset();
}

void FlightController::StartTrajectoryHere() {
  const StateEstimate& s = estimator_.state();
  trajectory_.Reset(s.pos_m, s.vel_mps);
  if (shaper_.configured()) shaper_.Reset(trajectory_.reference());
}

bool FlightController::Command(const Setpoint& sp) {
  const double t = t_s_;
  const bool finite = sp.value.allFinite();
  const bool on_ground = mode_ == FlightMode::kIdle || mode_ == FlightMode::kLanded;
  if (!finite || mode_ == FlightMode::kInit) {
    Emit(FlightEventKind::kRejected, t);
    return false;
  }
  if (!std::isnan(sp.yaw_rad)) yaw_sp_rad_ = WrapPi(sp.yaw_rad);
  switch (sp.kind) {
    case Setpoint::Kind::kTakeoff: {
      if (!on_ground || !(sp.value.z() > 0.0)) {
        Emit(FlightEventKind::kRejected, t);
        return false;
      }
      const StateEstimate& s = estimator_.state();
      home_z_m_ = s.pos_m.z();
      yaw_sp_rad_ = YawOf(s.att);
      ResetControllers();
      hte_.Reset(HoverThrustFor(config_.mass_kg + options_.payload_mass_kg));
      mass_kg_ = MassFor(hte_.hover_thrust());
      thrust_lagged_n_ = 0.0;
      hte_in_air_ = false;
      airborne_s_ = 0.0;
      trajectory_.Reset(s.pos_m, Vec3::Zero());
      if (shaper_.configured()) shaper_.Reset(trajectory_.reference());
      TrajectoryLimits lim = config_.limits;
      lim.vel_max_up_mps = std::min(lim.vel_max_up_mps, config_.takeoff_speed_mps);
      trajectory_.SetLimits(lim);
      trajectory_.SetPositionTarget(s.pos_m + Vec3(0.0, 0.0, sp.value.z()));
      SetMode(FlightMode::kTakeoff, t);
      Emit(FlightEventKind::kTakeoff, t);
      return true;
    }
    case Setpoint::Kind::kPosition:
    case Setpoint::Kind::kVelocity:
    case Setpoint::Kind::kHold:
    case Setpoint::Kind::kLand:
    case Setpoint::Kind::kTrajectory:
      break;
  }
  if (on_ground) {
    Emit(FlightEventKind::kRejected, t);
    return false;
  }
  if (sp.kind == Setpoint::Kind::kTrajectory) return CommandTrajectory(sp.trajectory, t);
  trajectory_.SetLimits(config_.limits);
  // The reference generator did not run in Land and Trajectory: restart it where the drone is.
  if (mode_ == FlightMode::kLand || mode_ == FlightMode::kTrajectory) StartTrajectoryHere();
  switch (sp.kind) {
    case Setpoint::Kind::kPosition:
      trajectory_.SetPositionTarget(sp.value);
      arrived_reported_ = false;
      SetMode(FlightMode::kPosition, t);
      return true;
    case Setpoint::Kind::kVelocity:
      trajectory_.SetVelocityTarget(sp.value);
      SetMode(FlightMode::kVelocity, t);
      return true;
    case Setpoint::Kind::kHold: {
      // Stop where braking at the acceleration limit ends.
      const TrajectoryPoint& r = trajectory_.reference();
      const double v = r.vel_mps.norm();
      const double a = std::max(0.1, std::min(config_.limits.acc_max_xy_mps2, config_.limits.acc_max_z_mps2));
      trajectory_.SetPositionTarget(r.pos_m + r.vel_mps * (v / (2.0 * a)));
      SetMode(FlightMode::kHold, t);
      return true;
    }
    case Setpoint::Kind::kLand: {
      const StateEstimate& s = estimator_.state();
      land_xy_m_ = trajectory_.reference().pos_m;
      land_xy_m_.z() = s.pos_m.z();
      land_vz_mps_ = std::min(0.0, s.vel_mps.z());
      landed_timer_s_ = 0.0;
      SetMode(FlightMode::kLand, t);
      Emit(FlightEventKind::kLanding, t);
      return true;
    }
    case Setpoint::Kind::kTakeoff:
    case Setpoint::Kind::kTrajectory:
      break;
  }
  Emit(FlightEventKind::kRejected, t);
  return false;
}

bool FlightController::CommandTrajectory(const TrajectoryTarget& target, double t_s) {
  if (!NoInfinity(target.pos_m) || !NoInfinity(target.vel_mps) || !NoInfinity(target.acc_mps2) ||
      std::isinf(target.yaw_rad) || std::isinf(target.yawspeed_radps)) {
    Emit(FlightEventKind::kRejected, t_s);
    return false;
  }
  const StateEstimate& s = estimator_.state();
  const bool continuing = mode_ == FlightMode::kTrajectory;
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const bool unset = std::isnan(target.pos_m[a]) && std::isnan(target.vel_mps[a]) && std::isnan(target.acc_mps2[a]);
    if (unset && !(continuing && traj_held_[i])) {
      // Hold where braking at the acceleration limit from the estimated velocity ends (as Hold).
      const double acc_max = std::max(0.1, a < 2 ? config_.limits.acc_max_xy_mps2 : config_.limits.acc_max_z_mps2);
      const double v = s.vel_mps[a];
      traj_hold_m_[a] = s.pos_m[a] + v * std::abs(v) / (2.0 * acc_max);
    }
    traj_held_[i] = unset;
  }
  if (!std::isnan(target.yaw_rad)) yaw_sp_rad_ = WrapPi(target.yaw_rad);
  traj_ = target;
  if (mode_ == FlightMode::kLand) StartTrajectoryHere();  // for a later Position/Hold, as they do
  SetMode(FlightMode::kTrajectory, t_s);
  return true;
}

PositionSetpoint FlightController::TrajectoryStep(const StateEstimate& s, double dt_s, double* yawspeed_ff_radps) {
  PositionSetpoint psp;
  const auto or0 = [](double v) { return std::isnan(v) ? 0.0 : v; };
  // The target's velocities (setpoints and feed-forwards) within the airframe's limits, as the
  // reference of the other kinds: horizontal by norm, vertical up/down.
  Vec3 vel(or0(traj_.vel_mps.x()), or0(traj_.vel_mps.y()), or0(traj_.vel_mps.z()));
  const TrajectoryLimits& lim = config_.limits;
  const double vxy = vel.head<2>().norm();
  if (vxy > lim.vel_max_xy_mps) vel.head<2>() *= lim.vel_max_xy_mps / vxy;
  vel.z() = std::clamp(vel.z(), -lim.vel_max_down_mps, lim.vel_max_up_mps);
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    psp.vel_mps[a] = vel[a];
    psp.acc_mps2[a] = or0(traj_.acc_mps2[a]);
    psp.pos_m[a] = s.pos_m[a];  // unused unless the axis is position-controlled
    if (traj_held_[i]) {
      psp.axes[i] = AxisControl::kPosition;
      psp.pos_m[a] = traj_hold_m_[a];
    } else if (!std::isnan(traj_.pos_m[a])) {
      psp.axes[i] = AxisControl::kPosition;
      psp.pos_m[a] = traj_.pos_m[a];
    } else if (!std::isnan(traj_.vel_mps[a])) {
      psp.axes[i] = AxisControl::kVelocity;
    } else {
      psp.axes[i] = AxisControl::kAcceleration;
      psp.vel_mps[a] = 0.0;
    }
  }
  psp.vel_cap_xy_mps = lim.vel_max_xy_mps;
  psp.vel_cap_up_mps = lim.vel_max_up_mps;
  psp.vel_cap_down_mps = lim.vel_max_down_mps;
  // Heading: yaw (set at the command), else turn at yawspeed, else keep.
  *yawspeed_ff_radps = 0.0;
  if (std::isnan(traj_.yaw_rad) && !std::isnan(traj_.yawspeed_radps)) {
    const double rate = std::clamp(traj_.yawspeed_radps, -kYawRateLimit_radps, kYawRateLimit_radps);
    yaw_sp_rad_ = WrapPi(yaw_sp_rad_ + rate * dt_s);
    *yawspeed_ff_radps = rate;
  }
  psp.yaw_rad = yaw_sp_rad_;
  psp.yawspeed_radps = *yawspeed_ff_radps;
  return psp;
}

void FlightController::DisarmedOutput() {
  output_.armed = false;
  output_.u.fill(0.0);
  last_thrust_n_ = 0.0;
  thrust_lagged_n_ = 0.0;
}

const ActuatorOutput& FlightController::Step(const SensorSample& sample) {
  double dt = last_t_s_ < 0.0 ? options_.control_dt_s : sample.t_s - last_t_s_;
  if (!(dt > 0.0) || dt > 0.1) dt = options_.control_dt_s;
  last_t_s_ = sample.t_s;
  t_s_ = sample.t_s;
  estimator_.SetAtRest(!Flying(mode_));
  const StateEstimate& s = estimator_.Update(sample);

  if (mode_ == FlightMode::kInit) {
    if (s.valid) {
      mode_ = FlightMode::kIdle;
      mode_since_s_ = t_s_;
      gps_ok_ = s.gps_ok;
      Emit(FlightEventKind::kReady, t_s_);
    }
    DisarmedOutput();
    return output_;
  }
  if (s.gps_ok != gps_ok_) {
    gps_ok_ = s.gps_ok;
    Emit(gps_ok_ ? FlightEventKind::kGpsRecovered : FlightEventKind::kGpsLost, t_s_);
  }
  if (!Flying(mode_)) {
    DisarmedOutput();
    ResetControllers();
    return output_;
  }
  airborne_s_ += dt;

  // Hover thrust (effective mass) estimate, PX4's mc_hover_thrust_estimator: the vertical
  // acceleration against the vertical thrust that produced it, once clear of the ground. The
  // thrust goes through the rotors' lag first (what the rotors deliver, not what was asked).
  const Vec3 body_z = s.att * Vec3::UnitZ();
  const double lag_s = config_.hover_thrust_lag_s;
  thrust_lagged_n_ += (lag_s > 0.0 ? std::min(1.0, dt / lag_s) : 1.0) * (last_thrust_n_ - thrust_lagged_n_);
  // In the air (latched until the next take-off): 0.5 m above the take-off point, or sinking
  // (an airborne start whose first thrust was too low for its load).
  if (airborne_s_ > 1.0 && (s.pos_m.z() - home_z_m_ > 0.5 || s.vel_mps.z() < -0.3)) hte_in_air_ = true;
  if (hte_in_air_ && thrust_lagged_n_ > 0.0) {
    hte_.Predict(dt);
    const double thrust_z = thrust_lagged_n_ * body_z.z() / mixer_.max_thrust_n();
    // De-weight fast vertical (drag, prop wash) and horizontal flight, as PX4 (HTE_VZ_THR 2 m/s,
    // HTE_VXY_THR 10 m/s).
    const double scale = std::max({1.0, std::abs(s.vel_mps.z()) - 2.0 + 1.0, s.vel_mps.head<2>().norm() - 10.0 + 1.0});
    hte_.Fuse(s.accel_mps2.z(), thrust_z, dt, scale);
    mass_kg_ = MassFor(hte_.hover_thrust());
  }

  // Yaw setpoint slews to the wanted heading.
  const double yaw_now = YawOf(s.att);
  (void)yaw_now;

  // Reference for this step.
  PositionSetpoint psp;
  psp.yaw_rad = yaw_sp_rad_;
  double yawspeed_ff_radps = 0.0;
  if (mode_ == FlightMode::kTrajectory) {
    psp = TrajectoryStep(s, dt, &yawspeed_ff_radps);
    telemetry_.reference.pos_m = psp.pos_m;
    telemetry_.reference.vel_mps = psp.vel_mps;
    telemetry_.reference.acc_mps2 = psp.acc_mps2;
  } else if (mode_ == FlightMode::kLand) {
    const double height = s.pos_m.z() - home_z_m_;
    const double v_target = height < config_.land_slow_below_m ? config_.land_slow_speed_mps : config_.land_speed_mps;
    const double dv = config_.limits.acc_max_z_mps2 * 0.5 * dt;
    land_vz_mps_ = std::clamp(-v_target, land_vz_mps_ - dv, land_vz_mps_ + dv);
    psp.axes = {AxisControl::kPosition, AxisControl::kPosition, AxisControl::kVelocity};
    psp.pos_m = land_xy_m_;
    psp.vel_mps = Vec3(0.0, 0.0, land_vz_mps_);
    telemetry_.reference.pos_m = land_xy_m_;
    telemetry_.reference.vel_mps = psp.vel_mps;
    telemetry_.reference.acc_mps2.setZero();
    // Touch-down: asked to descend, not descending, thrust well under hover, for 1 s.
    const bool still = std::abs(s.vel_mps.z()) < 0.15 && land_vz_mps_ < -0.1;
    const bool low_thrust = last_thrust_n_ < 0.85 * mass_kg_ * kGravity_mps2;
    landed_timer_s_ = (t_s_ - mode_since_s_ > 1.0 && still && low_thrust) ? landed_timer_s_ + dt : 0.0;
    if (landed_timer_s_ > 1.0) {
      SetMode(FlightMode::kLanded, t_s_);
      Emit(FlightEventKind::kLanded, t_s_);
      DisarmedOutput();
      ResetControllers();
      return output_;
    }
  } else {
    TrajectoryPoint ref = trajectory_.Step(dt);
    if (shaper_.configured()) {
      const TrajectoryPoint shaped = shaper_.Shape(ref);
      ref.pos_m.head<2>() = shaped.pos_m.head<2>();
      ref.vel_mps.head<2>() = shaped.vel_mps.head<2>();
      ref.acc_mps2.head<2>() = shaped.acc_mps2.head<2>();
    }
    telemetry_.reference = ref;
    if (mode_ == FlightMode::kVelocity) {
      psp.axes = {AxisControl::kVelocity, AxisControl::kVelocity, AxisControl::kVelocity};
    }
    psp.pos_m = ref.pos_m;
    psp.vel_mps = ref.vel_mps;
    psp.acc_mps2 = ref.acc_mps2;

    const bool near = (s.pos_m - trajectory_.target()).norm() < kArriveTol_m &&
                      s.vel_mps.norm() < kArriveSpeed_mps && trajectory_.Settled(0.05);
    if (mode_ == FlightMode::kTakeoff && near) {
      trajectory_.SetLimits(config_.limits);
      SetMode(FlightMode::kHold, t_s_);
      Emit(FlightEventKind::kHover, t_s_);
    } else if (mode_ == FlightMode::kPosition && near && !arrived_reported_) {
      arrived_reported_ = true;
      Emit(FlightEventKind::kArrived, t_s_);
    }
  }

  // Swing damping from the vehicle's own motion.
  if (damping_on_) {
    if (sample.imu_fresh) {
      swing_.Update(sample.accel_mps2, s.att, s.accel_mps2, mass_kg_ - config_.mass_kg, dt);
    }
    if (mode_ != FlightMode::kLand || s.pos_m.z() - home_z_m_ > 2.0) {
      const double gain = LoadScaledDampingGain(config_.swing.gain, mass_kg_ - config_.mass_kg, config_.mass_kg,
                                                config_.swing.full_gain_load_ratio);
      psp.acc_mps2 += swing_.DampingAcceleration(gain);
      // (velocity counterpart left out: it fights the position loop into a slow oscillation)
    }
    telemetry_.swing_estimate_rad = swing_.swing_angle_rad();
  }

  const PositionOutput po = position_.Update(s, psp, mass_kg_, dt);
  telemetry_.position = po;
  telemetry_.mass_estimate_kg = mass_kg_;
  telemetry_.hover_thrust = hte_.hover_thrust();
  telemetry_.hover_thrust_std = std::sqrt(hte_.variance());
  if (!po.valid) {
    // Non-finite estimate or setpoint: nothing sane to fly. Keep the last output, report once.
    return output_;
  }
  const Vec3 rate_sp = attitude_.Update(s.att, po.att_sp, yawspeed_ff_radps);

  // Angular acceleration for the D term: differentiated, low-passed rate.
  const double alpha = dt / (dt + 1.0 / (2.0 * kPi * kAngAccelCutoff_hz));
  ang_accel_ += alpha * ((s.rate_radps - last_rate_) / dt - ang_accel_);
  last_rate_ = s.rate_radps;
  const bool on_ground_phase = airborne_s_ < 0.5;
  const Vec3 torque_norm = rate_.Update(s.rate_radps, rate_sp, ang_accel_, dt, on_ground_phase);
  const Vec3 torque_nm = torque_norm.cwiseProduct(mixer_.torque_scale_nm());
  const MixerOutput mo = mixer_.Mix(torque_nm, po.thrust_n);
  rate_.SetSaturation(mo.sat_positive, mo.sat_negative);

  double achieved = 0.0;
  for (std::size_t i = 0; i < mixer_.rotor_count(); ++i) achieved += mo.thrust_n[i];
  last_thrust_n_ = achieved;
  output_.armed = true;
  output_.u = mo.u;
  telemetry_.rate_sp_radps = rate_sp;
  telemetry_.torque_nm = torque_nm;
  return output_;
}

}  // namespace swarmbox::flight
