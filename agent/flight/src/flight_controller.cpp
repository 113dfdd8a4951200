#include "swarmbox/flight/flight_controller.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

namespace swarmbox::flight {
namespace {

// Every threshold of the step, named. Where PX4 has a parameter for the same role it is cited.
constexpr double kMaxStepGap_s = 0.1;         // a longer gap between samples is a restart: use control_dt_s
constexpr double kArriveTol_m = 0.3;          // "arrived" within this of the target (role of PX4 NAV_ACC_RAD)
constexpr double kArriveSpeed_m_s = 0.3;      // and slower than this
constexpr double kArriveSettled_m = 0.05;     // with the reference this close to the target
constexpr double kYawRateLimit_rad_s = 1.5;   // trajectory yawspeed limit (role of PX4 MPC_YAWRAUTO_MAX)
constexpr double kAngAccelCutoff_hz = 30.0;   // D-term angular acceleration low-pass (PX4 IMU_DGYRO_CUTOFF)
constexpr double kLandAccelFraction = 0.5;    // Land eases into its descent at this fraction of acc_max_z
constexpr double kSwingDampingMinLandHeight_m = 2.0;  // in Land, swing damping stops below this height
constexpr double kMinBrakeAccel_m_s2 = 0.1;   // Hold/trajectory braking distance: at least this deceleration
constexpr double kVelocityChaseFactor = 1.2;  // the position loop may chase the reference this much faster
constexpr double kMinHoverMassFraction = 0.5; // hover thrust estimate: at least this fraction of the empty vehicle

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
  const bool no_yawspeed = std::isnan(t.yawspeed_rad_s);
  const bool yaw_ok = !std::isinf(t.yaw_rad);
  if (ExactlyAllSet(t.pos_m) && AllUnset(t.vel_m_s) && AllUnset(t.acc_m_s2) && no_yawspeed && yaw_ok) {
    return Position(t.pos_m, t.yaw_rad);
  }
  if (AllUnset(t.pos_m) && ExactlyAllSet(t.vel_m_s) && AllUnset(t.acc_m_s2) && no_yawspeed && yaw_ok) {
    return Velocity(t.vel_m_s, t.yaw_rad);
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
  const double hover_frac = (config.mass_kg + options.payload_mass_kg) * kGravity_m_s2 / mixer->max_thrust_n();
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
  pp.vel_max_xy_m_s = kVelocityChaseFactor * config_.limits.vel_max_xy_m_s;
  pp.vel_max_up_m_s = kVelocityChaseFactor * config_.limits.vel_max_up_m_s;
  pp.vel_max_down_m_s = kVelocityChaseFactor * config_.limits.vel_max_down_m_s;
  position_.SetParams(pp);
  attitude_.SetGains(config_.attitude);
  rate_.SetGains(config_.rate);
  trajectory_.SetLimits(config_.limits);
  ConfigureHoverThrust();
  output_.count = mixer_.rotor_count();
  ConfigureSwingDamping();
}

// Hover thrust estimate: between half the empty vehicle and the most the position loop may ask.
void FlightController::ConfigureHoverThrust() {
  HoverThrustParams hp = config_.hover_thrust;
  hp.min_hover = kMinHoverMassFraction * config_.mass_kg * kGravity_m_s2 / mixer_.max_thrust_n();
  hp.max_hover = config_.thrust_max_frac;
  HoverThrustModuleParams hm;
  hm.thrust_lag_s = config_.hover_thrust_lag_s;
  hover_.Configure(hm, hp, mixer_.max_thrust_n());
  hover_.Reset(HoverThrustFor(config_.mass_kg + options_.payload_mass_kg));
  mass_kg_ = MassFor(hover_.hover_thrust());
}

// Swing damping: needs a slung payload in the airframe and both switches on.
void FlightController::ConfigureSwingDamping() {
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
      const double period = 2.0 * kPi * std::sqrt(length / kGravity_m_s2);
      shaper_.Configure(period, 0.0, options_.control_dt_s);
    }
  }
}

double FlightController::HoverThrustFor(double mass_kg) const {
  return mass_kg * kGravity_m_s2 / mixer_.max_thrust_n();
}

double FlightController::MassFor(double hover_thrust) const {
  return hover_thrust * mixer_.max_thrust_n() / kGravity_m_s2;
}

void FlightController::SetPayloadMass(double payload_mass_kg) {
  if (!(payload_mass_kg >= 0.0) || !std::isfinite(payload_mass_kg)) return;
  options_.payload_mass_kg = payload_mass_kg;
  // A prior as uncertain as a fresh start: the estimator corrects it within seconds when the
  // announced load is not what the drone lifts (a refused hook, a heavier evacuee).
  hover_.SetPrior(HoverThrustFor(config_.mass_kg + payload_mass_kg), config_.hover_thrust.init_std);
  mass_kg_ = MassFor(hover_.hover_thrust());
}

void FlightController::Emit(FlightEventKind kind, double t_s) {
  FlightEvent e;
  e.kind = kind;
  e.t_s = t_s;
  e.mode = mode_;
  e.pos_m = estimator_.state().pos_m;
  events_.Push(e);  // full (nobody pops): the oldest is dropped
}

bool FlightController::PopEvent(FlightEvent* out) {
  return events_.Pop(out);
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
  trajectory_.Reset(s.pos_m, s.vel_m_s);
  if (shaper_.configured()) shaper_.Reset(trajectory_.reference());
}

bool FlightController::Command(const Setpoint& sp) {
  const double t = t_s_;
  const bool finite = sp.value.allFinite();
  const bool on_ground = mode_ == FlightMode::kIdle || mode_ == FlightMode::kLanded;
  if (!finite || mode_ == FlightMode::kInit) return Reject(t);
  if (!std::isnan(sp.yaw_rad)) yaw_sp_rad_ = WrapPi(sp.yaw_rad);
  if (sp.kind == Setpoint::Kind::kTakeoff) return on_ground ? CommandTakeoff(sp, t) : Reject(t);
  if (on_ground) return Reject(t);
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
    case Setpoint::Kind::kHold:
      CommandHold(t);
      return true;
    case Setpoint::Kind::kLand:
      CommandLand(t);
      return true;
    case Setpoint::Kind::kTakeoff:
    case Setpoint::Kind::kTrajectory:
      break;
  }
  return Reject(t);
}

bool FlightController::Reject(double t_s) {
  Emit(FlightEventKind::kRejected, t_s);
  return false;
}

bool FlightController::CommandTakeoff(const Setpoint& sp, double t_s) {
  if (!(sp.value.z() > 0.0)) return Reject(t_s);
  const StateEstimate& s = estimator_.state();
  home_z_m_ = s.pos_m.z();
  yaw_sp_rad_ = YawOf(s.att);
  ResetControllers();
  hover_.Reset(HoverThrustFor(config_.mass_kg + options_.payload_mass_kg));
  mass_kg_ = MassFor(hover_.hover_thrust());
  land_.Reset();
  airborne_s_ = 0.0;
  trajectory_.Reset(s.pos_m, Vec3::Zero());
  if (shaper_.configured()) shaper_.Reset(trajectory_.reference());
  TrajectoryLimits lim = config_.limits;
  lim.vel_max_up_m_s = std::min(lim.vel_max_up_m_s, config_.takeoff_speed_m_s);
  trajectory_.SetLimits(lim);
  trajectory_.SetPositionTarget(s.pos_m + Vec3(0.0, 0.0, sp.value.z()));
  SetMode(FlightMode::kTakeoff, t_s);
  Emit(FlightEventKind::kTakeoff, t_s);
  return true;
}

void FlightController::CommandHold(double t_s) {
  // Stop where braking at the acceleration limit ends.
  const TrajectoryPoint& r = trajectory_.reference();
  const double v = r.vel_m_s.norm();
  const double a =
      std::max(kMinBrakeAccel_m_s2, std::min(config_.limits.acc_max_xy_m_s2, config_.limits.acc_max_z_m_s2));
  trajectory_.SetPositionTarget(r.pos_m + r.vel_m_s * (v / (2.0 * a)));
  SetMode(FlightMode::kHold, t_s);
}

void FlightController::CommandLand(double t_s) {
  const StateEstimate& s = estimator_.state();
  land_xy_m_ = trajectory_.reference().pos_m;
  land_xy_m_.z() = s.pos_m.z();
  land_vz_m_s_ = std::min(0.0, s.vel_m_s.z());
  land_.StartLanding();
  SetMode(FlightMode::kLand, t_s);
  Emit(FlightEventKind::kLanding, t_s);
}

bool FlightController::CommandTrajectory(const TrajectoryTarget& target, double t_s) {
  if (!NoInfinity(target.pos_m) || !NoInfinity(target.vel_m_s) || !NoInfinity(target.acc_m_s2) ||
      std::isinf(target.yaw_rad) || std::isinf(target.yawspeed_rad_s)) {
    Emit(FlightEventKind::kRejected, t_s);
    return false;
  }
  const StateEstimate& s = estimator_.state();
  const bool continuing = mode_ == FlightMode::kTrajectory;
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    const bool unset = std::isnan(target.pos_m[a]) && std::isnan(target.vel_m_s[a]) && std::isnan(target.acc_m_s2[a]);
    if (unset && !(continuing && traj_held_[i])) {
      // Hold where braking at the acceleration limit from the estimated velocity ends (as Hold).
      const double acc_max =
          std::max(kMinBrakeAccel_m_s2, a < 2 ? config_.limits.acc_max_xy_m_s2 : config_.limits.acc_max_z_m_s2);
      const double v = s.vel_m_s[a];
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

PositionSetpoint FlightController::TrajectoryStep(const StateEstimate& s, double dt_s, double* yawspeed_ff_rad_s) {
  PositionSetpoint psp;
  const auto or0 = [](double v) { return std::isnan(v) ? 0.0 : v; };
  // The target's velocities (setpoints and feed-forwards) within the airframe's limits, as the
  // reference of the other kinds: horizontal by norm, vertical up/down.
  Vec3 vel(or0(traj_.vel_m_s.x()), or0(traj_.vel_m_s.y()), or0(traj_.vel_m_s.z()));
  const TrajectoryLimits& lim = config_.limits;
  const double vxy = vel.head<2>().norm();
  if (vxy > lim.vel_max_xy_m_s) vel.head<2>() *= lim.vel_max_xy_m_s / vxy;
  vel.z() = std::clamp(vel.z(), -lim.vel_max_down_m_s, lim.vel_max_up_m_s);
  for (int a = 0; a < 3; ++a) {
    const auto i = static_cast<std::size_t>(a);
    psp.vel_m_s[a] = vel[a];
    psp.acc_m_s2[a] = or0(traj_.acc_m_s2[a]);
    psp.pos_m[a] = s.pos_m[a];  // unused unless the axis is position-controlled
    if (traj_held_[i]) {
      psp.axes[i] = AxisControl::kPosition;
      psp.pos_m[a] = traj_hold_m_[a];
    } else if (!std::isnan(traj_.pos_m[a])) {
      psp.axes[i] = AxisControl::kPosition;
      psp.pos_m[a] = traj_.pos_m[a];
    } else if (!std::isnan(traj_.vel_m_s[a])) {
      psp.axes[i] = AxisControl::kVelocity;
    } else {
      psp.axes[i] = AxisControl::kAcceleration;
      psp.vel_m_s[a] = 0.0;
    }
  }
  psp.vel_cap_xy_m_s = lim.vel_max_xy_m_s;
  psp.vel_cap_up_m_s = lim.vel_max_up_m_s;
  psp.vel_cap_down_m_s = lim.vel_max_down_m_s;
  *yawspeed_ff_rad_s = TrajectoryHeading(dt_s);
  psp.yaw_rad = yaw_sp_rad_;
  psp.yawspeed_rad_s = *yawspeed_ff_rad_s;
  return psp;
}

// Heading: yaw (set at the command), else turn at yawspeed, else keep. Returns the yawspeed
// feed-forward [rad/s].
double FlightController::TrajectoryHeading(double dt_s) {
  if (!std::isnan(traj_.yaw_rad) || std::isnan(traj_.yawspeed_rad_s)) return 0.0;
  const double rate = std::clamp(traj_.yawspeed_rad_s, -kYawRateLimit_rad_s, kYawRateLimit_rad_s);
  yaw_sp_rad_ = WrapPi(yaw_sp_rad_ + rate * dt_s);
  return rate;
}

void FlightController::DisarmedOutput() {
  output_.armed = false;
  output_.u.fill(0.0);
  last_thrust_n_ = 0.0;
  hover_.ClearThrust();
}

double FlightController::StepPeriod(double t_s) {
  double dt = last_t_s_ < 0.0 ? options_.control_dt_s : t_s - last_t_s_;
  if (!(dt > 0.0) || dt > kMaxStepGap_s) dt = options_.control_dt_s;
  last_t_s_ = t_s;
  t_s_ = t_s;
  return dt;
}

bool FlightController::Armed(const StateEstimate& s) {
  if (mode_ == FlightMode::kInit) {
    if (s.valid) {
      mode_ = FlightMode::kIdle;
      mode_since_s_ = t_s_;
      gps_ok_ = s.gps_ok;
      Emit(FlightEventKind::kReady, t_s_);
    }
    DisarmedOutput();
    return false;
  }
  if (s.gps_ok != gps_ok_) {
    gps_ok_ = s.gps_ok;
    Emit(gps_ok_ ? FlightEventKind::kGpsRecovered : FlightEventKind::kGpsLost, t_s_);
  }
  if (!Flying(mode_)) {
    DisarmedOutput();
    ResetControllers();
    return false;
  }
  return true;
}

void FlightController::UpdateHoverThrust(const StateEstimate& s, double dt_s) {
  // In the air (latched until the next take-off): the land detector's answer. The vertical
  // acceleration against the vertical thrust the rotors delivered (hover_thrust_module.hpp).
  const bool in_air = land_.InAir(airborne_s_, s.pos_m.z() - home_z_m_, s.vel_m_s.z());
  const Vec3 body_z = s.att * Vec3::UnitZ();
  if (hover_.Update(in_air, last_thrust_n_, body_z.z(), s.accel_m_s2.z(), s.vel_m_s, dt_s)) {
    mass_kg_ = MassFor(hover_.hover_thrust());
  }
}

bool FlightController::LandReference(const StateEstimate& s, double dt_s, PositionSetpoint* psp) {
  const double height = s.pos_m.z() - home_z_m_;
  const double v_target = height < config_.land_slow_below_m ? config_.land_slow_speed_m_s : config_.land_speed_m_s;
  const double dv = config_.limits.acc_max_z_m_s2 * kLandAccelFraction * dt_s;
  land_vz_m_s_ = std::clamp(-v_target, land_vz_m_s_ - dv, land_vz_m_s_ + dv);
  psp->axes = {AxisControl::kPosition, AxisControl::kPosition, AxisControl::kVelocity};
  psp->pos_m = land_xy_m_;
  psp->vel_m_s = Vec3(0.0, 0.0, land_vz_m_s_);
  telemetry_.reference.pos_m = land_xy_m_;
  telemetry_.reference.vel_m_s = psp->vel_m_s;
  telemetry_.reference.acc_m_s2.setZero();
  if (!land_.UpdateTouchdown(dt_s, t_s_ - mode_since_s_, s.vel_m_s.z(), land_vz_m_s_, last_thrust_n_, mass_kg_)) {
    return true;
  }
  SetMode(FlightMode::kLanded, t_s_);
  Emit(FlightEventKind::kLanded, t_s_);
  DisarmedOutput();
  ResetControllers();
  return false;
}

void FlightController::SmoothedReference(const StateEstimate& s, double dt_s, PositionSetpoint* psp) {
  TrajectoryPoint ref = trajectory_.Step(dt_s);
  if (shaper_.configured()) {
    const TrajectoryPoint shaped = shaper_.Shape(ref);
    ref.pos_m.head<2>() = shaped.pos_m.head<2>();
    ref.vel_m_s.head<2>() = shaped.vel_m_s.head<2>();
    ref.acc_m_s2.head<2>() = shaped.acc_m_s2.head<2>();
  }
  telemetry_.reference = ref;
  if (mode_ == FlightMode::kVelocity) {
    psp->axes = {AxisControl::kVelocity, AxisControl::kVelocity, AxisControl::kVelocity};
  }
  psp->pos_m = ref.pos_m;
  psp->vel_m_s = ref.vel_m_s;
  psp->acc_m_s2 = ref.acc_m_s2;

  const bool near = (s.pos_m - trajectory_.target()).norm() < kArriveTol_m && s.vel_m_s.norm() < kArriveSpeed_m_s &&
                    trajectory_.Settled(kArriveSettled_m);
  if (mode_ == FlightMode::kTakeoff && near) {
    trajectory_.SetLimits(config_.limits);
    SetMode(FlightMode::kHold, t_s_);
    Emit(FlightEventKind::kHover, t_s_);
  } else if (mode_ == FlightMode::kPosition && near && !arrived_reported_) {
    arrived_reported_ = true;
    Emit(FlightEventKind::kArrived, t_s_);
  }
}

bool FlightController::Reference(const StateEstimate& s, double dt_s, PositionSetpoint* psp,
                                 double* yawspeed_ff_rad_s) {
  psp->yaw_rad = yaw_sp_rad_;
  *yawspeed_ff_rad_s = 0.0;
  if (mode_ == FlightMode::kTrajectory) {
    *psp = TrajectoryStep(s, dt_s, yawspeed_ff_rad_s);
    telemetry_.reference.pos_m = psp->pos_m;
    telemetry_.reference.vel_m_s = psp->vel_m_s;
    telemetry_.reference.acc_m_s2 = psp->acc_m_s2;
    return true;
  }
  if (mode_ == FlightMode::kLand) return LandReference(s, dt_s, psp);
  SmoothedReference(s, dt_s, psp);
  return true;
}

void FlightController::AddSwingDamping(const SensorSample& sample, const StateEstimate& s, double dt_s,
                                       PositionSetpoint* psp) {
  if (!damping_on_) return;
  const double load_kg = mass_kg_ - config_.mass_kg;
  if (sample.imu_fresh) swing_.Update(sample.accel_m_s2, s.att, s.accel_m_s2, load_kg, dt_s);
  if (mode_ != FlightMode::kLand || s.pos_m.z() - home_z_m_ > kSwingDampingMinLandHeight_m) {
    const double gain =
        LoadScaledDampingGain(config_.swing.gain, load_kg, config_.mass_kg, config_.swing.full_gain_load_ratio);
    psp->acc_m_s2 += swing_.DampingAcceleration(gain);
    // (velocity counterpart left out: it fights the position loop into a slow oscillation)
  }
  telemetry_.swing_estimate_rad = swing_.swing_angle_rad();
}

void FlightController::RunCascade(const StateEstimate& s, const PositionSetpoint& psp, double yawspeed_ff_rad_s,
                                  double dt_s) {
  const PositionOutput po = position_.Update(s, psp, mass_kg_, dt_s);
  telemetry_.position = po;
  telemetry_.mass_estimate_kg = mass_kg_;
  telemetry_.hover_thrust = hover_.hover_thrust();
  telemetry_.hover_thrust_std = std::sqrt(hover_.variance());
  // Non-finite estimate or setpoint: nothing sane to fly. Keep the last output.
  if (!po.valid) return;
  const Vec3 rate_sp = attitude_.Update(s.att, po.att_sp, yawspeed_ff_rad_s);

  // Angular acceleration for the D term: differentiated, low-passed rate.
  const double alpha = dt_s / (dt_s + 1.0 / (2.0 * kPi * kAngAccelCutoff_hz));
  ang_accel_ += alpha * ((s.rate_rad_s - last_rate_) / dt_s - ang_accel_);
  last_rate_ = s.rate_rad_s;
  const Vec3 torque_norm =
      rate_.Update(s.rate_rad_s, rate_sp, ang_accel_, dt_s, land_.GroundContactPhase(airborne_s_));
  const Vec3 torque_nm = torque_norm.cwiseProduct(mixer_.torque_scale_nm());
  const MixerOutput mo = mixer_.Mix(torque_nm, po.thrust_n);
  rate_.SetSaturation(mo.sat_positive, mo.sat_negative);

  double achieved = 0.0;
  for (std::size_t i = 0; i < mixer_.rotor_count(); ++i) achieved += mo.thrust_n[i];
  last_thrust_n_ = achieved;
  output_.armed = true;
  output_.u = mo.u;
  telemetry_.rate_sp_rad_s = rate_sp;
  telemetry_.torque_nm = torque_nm;
}

// The control step as PX4 runs its modules: estimator, land detector + hover thrust estimator,
// the mode's reference (flight tasks), swing damping, then position -> attitude -> rate -> mixer.
const ActuatorOutput& FlightController::Step(const SensorSample& sample) {
  const double dt = StepPeriod(sample.t_s);
  estimator_.SetAtRest(!Flying(mode_));
  const StateEstimate& s = estimator_.Update(sample);
  if (!Armed(s)) return output_;  // not ready, or on the ground: motors off
  airborne_s_ += dt;
  UpdateHoverThrust(s, dt);
  PositionSetpoint psp;
  double yawspeed_ff_rad_s = 0.0;
  if (!Reference(s, dt, &psp, &yawspeed_ff_rad_s)) return output_;  // touched down: motors off
  AddSwingDamping(sample, s, dt, &psp);
  RunCascade(s, psp, yawspeed_ff_rad_s, dt);
  return output_;
}

}  // namespace swarmbox::flight
