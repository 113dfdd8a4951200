#include "scenarios.hpp"

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "sim_harness.hpp"

namespace swarmbox::flight::testing {
namespace {

constexpr double kRadToDeg = 180.0 / kPi;

Result<std::unique_ptr<Rig>> HoveringRig(const RigOptions& o, double height_m) {
  auto rig = Rig::Create(o);
  if (!rig) return rig.error();
  Rig& r = **rig;
  if (!r.RunUntilMode(FlightMode::kIdle, 3.0)) {
    return Error(ErrorCode::kInternal, "estimator did not align within 3 s");
  }
  r.Run(5.0);  // on the ground: zero-velocity updates teach the estimator its biases
  r.MarkGpsReference();
  if (!r.fc().Command(Setpoint::Takeoff(height_m))) {
    return Error(ErrorCode::kInternal, "take-off rejected");
  }
  if (!r.RunUntilMode(FlightMode::kHold, 30.0)) {
    return Error(ErrorCode::kInternal, "no hover within 30 s of take-off");
  }
  return std::move(*rig);
}

Status TwinOk(const Rig& r) {
  if (!r.gps_twin_ok()) return Error(ErrorCode::kInternal, "GPS error twin out of step with the World (see stderr)");
  return {};
}

}  // namespace

const char* ReceiverName(Receiver receiver) { return receiver == Receiver::kRtk ? "rtk" : "standalone"; }

Result<HoverMetrics> RunHover(std::uint64_t seed, double window_s, double wind_m_s, double gust_std_m_s,
                              Receiver receiver) {
  RigOptions o;
  o.seed = seed;
  o.gps_fix = receiver;
  o.wind.mean_m_s = physics::Vec3{wind_m_s, 0.0, 0.0};
  o.wind.gust_std_m_s = gust_std_m_s;
  o.wind.gust_time_s = 2.0;
  auto rig = HoveringRig(o, 5.0);
  if (!rig) return rig.error();
  Rig& r = **rig;
  r.Run(5.0);  // settle (the wind's integrator too)
  const Vec3 target = r.fc().telemetry().reference.pos_m;
  const Vec3 gps0 = r.gps_error();
  std::vector<Vec3> nav;
  nav.reserve(static_cast<std::size_t>(window_s * 250.0) + 2);
  double truth2 = 0.0, target2 = 0.0, wander2 = 0.0, est2 = 0.0, track2 = 0.0;
  r.Run(window_s, {}, [&] {
    nav.push_back(r.nav_pos());
    target2 += (r.nav_pos() - target).squaredNorm();
    truth2 += (r.true_pos() - target).squaredNorm();
    wander2 += (r.gps_error() - gps0).head<2>().squaredNorm();
    est2 += (r.fc().estimate().pos_m - r.nav_pos()).squaredNorm();
    track2 += (r.fc().estimate().pos_m - target).squaredNorm();
  });
  const double dn = static_cast<double>(nav.size());
  Vec3 mean = Vec3::Zero();
  for (const Vec3& p : nav) mean += p / dn;
  double sum2 = 0.0, max_e = 0.0;
  for (const Vec3& p : nav) {
    sum2 += (p - mean).squaredNorm();
    max_e = std::max(max_e, (p - mean).norm());
  }
  HoverMetrics m;
  m.rms_m = std::sqrt(sum2 / dn);
  m.target_rms_m = std::sqrt(target2 / dn);
  m.truth_rms_m = std::sqrt(truth2 / dn);
  m.gps_wander_rms_m = std::sqrt(wander2 / dn);
  m.est_rms_m = std::sqrt(est2 / dn);
  m.track_rms_m = std::sqrt(track2 / dn);
  m.max_m = max_e;
  m.window_s = window_s;
  if (r.crashed()) return Error(ErrorCode::kInternal, "crashed while hovering");
  SWARMBOX_TRY(TwinOk(r));
  return m;
}

Result<StepMetrics> RunStep(std::uint64_t seed, double dx, double dy, double dz, Receiver receiver) {
  RigOptions o;
  o.seed = seed;
  o.gps_fix = receiver;
  auto rig = HoveringRig(o, 5.0);
  if (!rig) return rig.error();
  Rig& r = **rig;
  r.Run(3.0);
  const Vec3 start = r.fc().telemetry().reference.pos_m;
  const Vec3 step(dx, dy, dz);
  const Vec3 target = start + step;
  const Vec3 dir = step.normalized();
  const Vec3 nav0 = r.nav_pos();     // where the drone is at the command: the step starts there
  const Vec3 truth0 = r.true_pos();
  if (!r.fc().Command(Setpoint::Position(target, 0.0))) return Error(ErrorCode::kInternal, "setpoint rejected");
  const double t0 = r.t();
  double last_out = 0.0, last_out_3d = 0.0, last_out_truth = 0.0, last_out_target = 0.0;
  double max_along = 0.0, max_truth = 0.0, peak_v = 0.0;
  r.Run(15.0, {}, [&] {
    const Vec3 moved = r.nav_pos() - nav0;
    if (std::abs((moved - step).dot(dir)) > 0.2) last_out = r.t() - t0;
    if ((moved - step).norm() > 0.2) last_out_3d = r.t() - t0;
    if (std::abs((r.true_pos() - truth0 - step).dot(dir)) > 0.2) last_out_truth = r.t() - t0;
    if (std::abs((r.true_pos() - target).dot(dir)) > 0.2) last_out_target = r.t() - t0;
    max_along = std::max(max_along, moved.dot(dir));
    max_truth = std::max(max_truth, (r.true_pos() - truth0).dot(dir));
    const auto v = r.truth().velocity_m_s;
    peak_v = std::max(peak_v, std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
  });
  StepMetrics m;
  m.settle_s = last_out;
  m.settle_3d_s = last_out_3d;
  m.settle_truth_s = last_out_truth;
  m.settle_target_s = last_out_target;
  m.settled = last_out < 14.0;
  m.overshoot_pct = std::max(0.0, (max_along - step.norm()) / step.norm() * 100.0);
  m.overshoot_truth_pct = std::max(0.0, (max_truth - step.norm()) / step.norm() * 100.0);
  m.peak_speed_m_s = peak_v;
  SWARMBOX_TRY(TwinOk(r));
  return m;
}

Result<DropoutMetrics> RunGpsDropout(std::uint64_t seed, double dropout_s) {
  RigOptions o;
  o.seed = seed;
  auto rig = HoveringRig(o, 5.0);
  if (!rig) return rig.error();
  Rig& r = **rig;
  r.Run(5.0);
  const Vec3 target = r.fc().telemetry().reference.pos_m;
  DropoutMetrics m;
  r.world().SetGpsDropout(r.drone(), true);
  r.Run(dropout_s, {}, [&] { m.max_drift_m = std::max(m.max_drift_m, (r.nav_pos() - target).norm()); });
  m.est_err_at_end_m = (r.fc().estimate().pos_m - r.nav_pos()).norm();
  r.world().SetGpsDropout(r.drone(), false);
  r.Run(10.0, {}, [&] {
    m.max_err_after_m = std::max(m.max_err_after_m, (r.nav_pos() - target).norm());
    const auto v = r.truth().velocity_m_s;
    m.max_speed_after_m_s = std::max(m.max_speed_after_m_s, std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z));
  });
  m.final_err_m = (r.nav_pos() - target).norm();
  SWARMBOX_TRY(TwinOk(r));
  m.events_ok = r.HasEvent(FlightEventKind::kGpsLost) && r.HasEvent(FlightEventKind::kGpsRecovered);
  m.crashed = r.crashed() || r.true_pos().z() < 1.0;
  return m;
}

Result<TransferMetrics> RunHeavyTransfer(std::uint64_t seed, double distance_m, bool damping,
                                         std::FILE* trace, double loaded_mass_kg) {
  // Airborne start (a test rig, as a crane would hold it): the drone is pinned at 10 m with the
  // stretcher hanging still while the estimator aligns, released once the motors are spinning.
  RigOptions o;
  o.seed = seed;
  o.airframe = "x8_heavy";
  o.start_m = physics::Vec3{0.0, 0.0, 10.0};
  o.payload = "stretcher";
  o.payload_attached = true;
  o.swing_damping = damping;
  o.payload_mass_hint_kg = 80.0;
  auto created = Rig::Create(o);
  if (!created) return created.error();
  Rig& r = **created;
  r.world().SetPinned(r.drone(), true);
  if (loaded_mass_kg > 0.0) {  // loaded where it hangs: same sling length, new mass
    SWARMBOX_TRY(r.world().ReleasePayload(r.drone()));
    SWARMBOX_TRY(r.world().AttachPayload(r.drone(), loaded_mass_kg));
  }
  long step = 0;
  auto tracer = [&] {
    if (trace == nullptr || ++step % 250 != 0) return;
    const Vec3 p = r.true_pos();
    const Vec3 e = r.fc().estimate().pos_m;
    const ControllerTelemetry& tm = r.fc().telemetry();
    std::fprintf(trace,
                 "t=%.1f mode=%s pos=(%.2f %.2f %.2f) est=(%.2f %.2f %.2f) ref=(%.2f %.2f %.2f) "
                 "swing_deg=%.1f swing_est_deg=%.1f mass_kg=%.1f thrust_n=%.0f\n",
                 r.t(), std::string(FlightModeName(r.fc().mode())).c_str(), p.x(), p.y(), p.z(), e.x(), e.y(),
                 e.z(), tm.reference.pos_m.x(), tm.reference.pos_m.y(), tm.reference.pos_m.z(),
                 r.truth().payload_swing_rad * kRadToDeg, tm.swing_estimate_rad * kRadToDeg,
                 tm.mass_estimate_kg, tm.position.thrust_n);
  };
  if (!r.RunUntilMode(FlightMode::kIdle, 3.0)) return Error(ErrorCode::kInternal, "no alignment");
  r.Run(3.0, {}, tracer);
  r.MarkGpsReference();
  if (!r.fc().Command(Setpoint::Takeoff(0.5))) return Error(ErrorCode::kInternal, "take-off rejected");
  r.Run(0.5, {}, tracer);  // motors spin up (0.15 s lag) before the rig lets go
  r.world().SetPinned(r.drone(), false);
  r.Run(30.0, [&] { return r.fc().mode() == FlightMode::kHold; }, tracer);
  if (r.fc().mode() != FlightMode::kHold) return Error(ErrorCode::kInternal, "no hover after release");
  r.Run(10.0, {}, tracer);
  const Vec3 start = r.fc().telemetry().reference.pos_m;
  const Vec3 target = start + Vec3(distance_m, 0.0, 0.0);
  if (!r.fc().Command(Setpoint::Position(target, 0.0))) return Error(ErrorCode::kInternal, "setpoint rejected");
  TransferMetrics m;
  const double t0 = r.t();
  double t_arrive = -1.0;
  r.Run(60.0, [&] { return t_arrive >= 0.0 && r.t() - t_arrive >= 15.0; }, [&] {
    const double swing = r.truth().payload_swing_rad * kRadToDeg;
    m.max_swing_deg = std::max(m.max_swing_deg, swing);
    if (t_arrive < 0.0 && (r.nav_pos() - target).norm() < 1.0) {
      t_arrive = r.t();
      m.swing_at_arrival_deg = swing;
    }
    if (t_arrive >= 0.0 && r.t() - t_arrive >= 5.0) m.residual_swing_deg = std::max(m.residual_swing_deg, swing);
    tracer();
  });
  m.arrival_s = t_arrive >= 0.0 ? t_arrive - t0 : -1.0;
  m.final_err_m = (r.nav_pos() - target).norm();
  m.crashed = r.crashed();
  SWARMBOX_TRY(TwinOk(r));
  if (t_arrive < 0.0) return Error(ErrorCode::kInternal, "did not arrive within 60 s");
  return m;
}

}  // namespace swarmbox::flight::testing
