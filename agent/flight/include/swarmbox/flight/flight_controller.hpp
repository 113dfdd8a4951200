// FlightController: the whole flight stack of one drone as one pure object. Sensor sample in,
// actuator command out, on simulated time; setpoints in from the layers above, events out.
//
//   sample -> Estimator -> LandDetector + HoverThrustModule (the effective mass)
//          -> modes/setpoints -> Trajectory (limits, smoothing) [-> InputShaper]
//          -> PositionControl (+ swing damping feed-forward) -> AttitudeControl -> RateControl
//          -> Mixer -> u[i] in [0, 1]
// Step() is that sequence of calls, one per unit, as PX4 splits it into modules (land_detector,
// mc_hover_thrust_estimator, flight tasks, mc_pos_control, mc_att_control, mc_rate_control); each
// unit has its named parameters (PX4's parameter names cited where PX4 has one) and its own test.
// The trajectory kind (a brain's PX4 TrajectorySetpoint stream, setpoint.hpp) skips the
// smoothing: its targets go to PositionControl per axis, within the same velocity and tilt limits.
// When a brain's stream stops, OffboardFailsafe (offboard_failsafe.hpp) tells the caller to send
// Hold, then Land.
//
// No DDS, threads, clocks or files; Step() neither allocates nor throws (STYLE.md 1, 12). The
// agent program wraps it; the closed-loop tests run it against the physics library in process.
//
//   auto fc = FlightController::Create(*LoadFlightConfig("trials/airframes/x500.yaml"), {});
//   fc->Command(Setpoint::Takeoff(5));
//   for each lockstep sample: const ActuatorOutput& out = fc->Step(sample);  // answer with out.u
#pragma once

#include <array>
#include <cstddef>

#include "swarmbox/common/result.hpp"
#include "swarmbox/flight/attitude_control.hpp"
#include "swarmbox/flight/detail/event_ring.hpp"
#include "swarmbox/flight/estimator.hpp"
#include "swarmbox/flight/flight_config.hpp"
#include "swarmbox/flight/hover_thrust_module.hpp"
#include "swarmbox/flight/land_detector.hpp"
#include "swarmbox/flight/mixer.hpp"
#include "swarmbox/flight/position_control.hpp"
#include "swarmbox/flight/rate_control.hpp"
#include "swarmbox/flight/setpoint.hpp"
#include "swarmbox/flight/swing_damping.hpp"
#include "swarmbox/flight/trajectory.hpp"

namespace swarmbox::flight {

struct ControllerOptions {
  double control_dt_s = 0.004;       // the lockstep period the input shaper is sized for [s]
  // What the companion computer is told it carries at start: the prior of the hover thrust
  // estimate, which then learns what the drone really lifts (SetPayloadMass changes it) [kg].
  double payload_mass_kg = 0.0;
  // Name of the airframe payload whose sling the swing damping is tuned for ("" = the first).
  const char* payload_name = "";
  bool swing_damping = true;         // AND the config's swing_damping.enabled
  // Known start position (the take-off spot) for the estimator; see EstimatorParams.
  bool has_start_pos = false;
  Vec3 start_pos_m = Vec3::Zero();
};

struct ActuatorOutput {
  bool armed = false;
  std::size_t count = 0;
  std::array<double, kMaxRotors> u{};  // first `count` valid, in the airframe's rotor order
};

// Internal signals, for tests, benchmarks and logs.
struct ControllerTelemetry {
  TrajectoryPoint reference;        // after shaping
  PositionOutput position;
  Vec3 rate_sp_rad_s = Vec3::Zero();
  Vec3 torque_nm = Vec3::Zero();
  double mass_estimate_kg = 0.0;   // vehicle + load from the hover thrust estimate [kg]
  double hover_thrust = 0.0;       // learnt hover thrust, fraction of the maximum thrust
  double hover_thrust_std = 0.0;   // its 1-sigma uncertainty
  double swing_estimate_rad = 0.0;
};

class FlightController {
 public:
  static Result<FlightController> Create(const FlightConfig& config, const ControllerOptions& options);

  // The setpoint interface. Rejected (and reported as an event) when the mode cannot take it:
  // anything but Takeoff on the ground, Takeoff in the air, anything before the estimator is
  // ready; or when it has infinite values (non-finite for the kinds other than Trajectory, whose
  // NaN means unset). Does not allocate. Trajectory: see setpoint.hpp; a stream of them is one
  // mode (kTrajectory), each replacing the last.
  bool Command(const Setpoint& sp);

  // One control step on the lockstep sample. Motors off (armed = false) on the ground.
  const ActuatorOutput& Step(const SensorSample& sample);

  // The load the drone was just told it carries (a payload attach: the stretcher's announced
  // mass; a release: 0) [kg]. A prior for the hover thrust estimate (as uncertain as at take-off),
  // which goes on correcting it from the vertical acceleration; also the prior of the next
  // take-off. Ignored if negative or not finite. Does not allocate.
  void SetPayloadMass(double payload_mass_kg);

  // Events since the last call, oldest first; false when none are left.
  bool PopEvent(FlightEvent* out);

  FlightMode mode() const { return mode_; }
  const StateEstimate& estimate() const { return estimator_.state(); }
  const Estimator& estimator() const { return estimator_; }
  const ControllerTelemetry& telemetry() const { return telemetry_; }
  const FlightConfig& config() const { return config_; }
  const Mixer& mixer() const { return mixer_; }

 private:
  FlightController(const FlightConfig& config, const ControllerOptions& options, Mixer mixer);
  // The constructor's parts: the hover thrust module (and mass_kg_), the swing observer and shaper.
  void ConfigureHoverThrust();
  void ConfigureSwingDamping();
  void SetMode(FlightMode mode, double t_s);
  void Emit(FlightEventKind kind, double t_s);
  void ResetControllers();
  void StartTrajectoryHere();
  void DisarmedOutput();
  // Command()'s parts: a rejection (event, false), and the setpoints that do more than set a
  // target.
  bool Reject(double t_s);
  bool CommandTakeoff(const Setpoint& sp, double t_s);  // on the ground
  void CommandHold(double t_s);
  void CommandLand(double t_s);
  bool CommandTrajectory(const TrajectoryTarget& target, double t_s);
  // The trajectory kind's setpoint for this step (per-axis control, heading), from target_.
  PositionSetpoint TrajectoryStep(const StateEstimate& s, double dt_s, double* yawspeed_ff_rad_s);
  double TrajectoryHeading(double dt_s);  // advances yaw_sp_rad_; the yawspeed feed-forward
  // Step()'s parts, in order. The step period from the sample time [s].
  double StepPeriod(double t_s);
  // Mode bookkeeping before flight (ready, GPS lost/recovered); false (motors off) unless flying.
  bool Armed(const StateEstimate& s);
  // Land detector's in-air answer -> hover thrust estimate -> mass_kg_.
  void UpdateHoverThrust(const StateEstimate& s, double dt_s);
  // The mode's setpoint for this step; false when the drone has just touched down (disarmed).
  bool Reference(const StateEstimate& s, double dt_s, PositionSetpoint* psp, double* yawspeed_ff_rad_s);
  bool LandReference(const StateEstimate& s, double dt_s, PositionSetpoint* psp);
  void SmoothedReference(const StateEstimate& s, double dt_s, PositionSetpoint* psp);
  void AddSwingDamping(const SensorSample& sample, const StateEstimate& s, double dt_s, PositionSetpoint* psp);
  // Position -> attitude -> rate -> mixer into output_.
  void RunCascade(const StateEstimate& s, const PositionSetpoint& psp, double yawspeed_ff_rad_s, double dt_s);
  double HoverThrustFor(double mass_kg) const;   // normalised hover thrust of a total mass
  double MassFor(double hover_thrust) const;

  FlightConfig config_;
  ControllerOptions options_;
  Mixer mixer_;
  Estimator estimator_;
  Trajectory trajectory_;
  InputShaper shaper_;
  SwingObserver swing_;
  HoverThrustModule hover_;
  LandDetector land_;
  PositionControl position_;
  AttitudeControl attitude_;
  RateControl rate_;
  ActuatorOutput output_;
  ControllerTelemetry telemetry_;

  FlightMode mode_ = FlightMode::kInit;
  double t_s_ = 0.0;
  double last_t_s_ = -1.0;
  double mode_since_s_ = 0.0;
  double yaw_sp_rad_ = 0.0;
  double home_z_m_ = 0.0;
  Vec3 land_xy_m_ = Vec3::Zero();
  double land_vz_m_s_ = 0.0;
  bool arrived_reported_ = true;
  bool gps_ok_ = true;
  double mass_kg_ = 0.0;            // hover-thrust (effective mass) estimate [kg]
  double last_thrust_n_ = 0.0;      // collective thrust commanded last step [N]
  Vec3 last_rate_ = Vec3::Zero();
  Vec3 ang_accel_ = Vec3::Zero();
  bool damping_on_ = false;
  double airborne_s_ = 0.0;
  // Trajectory kind: the target in force, and per axis whether it is held (all three unset) at
  // traj_hold_m_ (latched when the axis became unset).
  TrajectoryTarget traj_{};
  std::array<bool, 3> traj_held_{};
  Vec3 traj_hold_m_ = Vec3::Zero();

  detail::EventRing<FlightEvent, 32> events_;
};

}  // namespace swarmbox::flight
