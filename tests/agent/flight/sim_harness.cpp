#include "sim_harness.hpp"

#include <utility>

namespace swarmbox::flight::testing {
namespace {

Vec3 E(const physics::Vec3& v) { return Vec3(v.x, v.y, v.z); }

}  // namespace

std::string TrialsDir() { return SWARMBOX_TRIALS_DIR; }

SensorSample FromPhysics(const physics::SensorSample& s) {
  SensorSample out;
  out.t_s = static_cast<double>(s.time_ns) * 1e-9;
  out.imu_fresh = s.imu.fresh;
  out.accel_mps2 = E(s.imu.accel_m_s2);
  out.gyro_radps = E(s.imu.gyro_rad_s);
  out.baro_fresh = s.baro.fresh;
  out.baro_alt_m = s.baro.altitude_m;
  out.mag_fresh = s.mag.fresh;
  out.mag_body = E(s.mag.field_gauss);
  out.gps_fresh = s.gps.fresh;
  out.gps_valid = s.gps.valid;
  out.gps_pos_m = E(s.gps.position_m);
  out.gps_vel_mps = E(s.gps.velocity_m_s);
  return out;
}

Result<std::unique_ptr<Rig>> Rig::Create(const RigOptions& options) {
  auto rig = std::unique_ptr<Rig>(new Rig());
  physics::WorldConfig wc;
  wc.name = "closed_loop";
  wc.wind = options.wind;
  auto world = physics::World::Create(wc, {.seed = options.seed});
  if (!world) return world.error();
  rig->world_ = std::move(*world);
  rig->world_->SetEventSink(&rig->sink_);
  const std::string path = TrialsDir() + "/airframes/" + options.airframe + ".yaml";
  auto af = physics::LoadAirframe(path);
  if (!af) return af.error();
  physics::DroneSpawn spawn;
  spawn.name = "drone_1";
  spawn.airframe = *af;
  spawn.position_m = options.start_m;
  spawn.payload = options.payload;
  spawn.payload_attached = options.payload_attached;
  spawn.initial_throttle = options.initial_throttle;
  auto idx = rig->world_->AddDrone(spawn);
  if (!idx) return idx.error();
  rig->drone_ = *idx;

  auto cfg = LoadFlightConfig(path);
  if (!cfg) return cfg.error();
  ControllerOptions co;
  co.control_dt_s = 0.004;
  co.swing_damping = options.swing_damping;
  co.payload_mass_kg = options.payload_mass_hint_kg;
  co.has_start_pos = true;  // the take-off spot is surveyed (as PX4's home)
  const physics::Vec3 body0 = rig->world_->Truth(rig->drone_).position_m;
  co.start_pos_m = E(body0);
  auto fc = FlightController::Create(*cfg, co);
  if (!fc) return fc.error();
  rig->fc_ = std::make_unique<FlightController>(std::move(*fc));
  rig->u_.assign(rig->fc_->mixer().rotor_count(), 0.0);
  return rig;
}

Vec3 Rig::true_pos() const { return E(world_->Truth(drone_).position_m); }

double Rig::Run(double max_s, const std::function<bool()>& done, const std::function<void()>& each) {
  const double t0 = t();
  while (t() - t0 < max_s - 1e-9) {
    const ActuatorOutput& out = fc_->Step(FromPhysics(world_->sensors(drone_)));
    for (std::size_t i = 0; i < u_.size(); ++i) u_[i] = out.armed ? out.u[i] : 0.0;
    (void)world_->SetActuators(drone_, u_);
    world_->Step();
    FlightEvent e;
    while (fc_->PopEvent(&e)) events_.push_back(e);
    for (const auto& pe : sink_.events) {
      if (pe.kind == physics::EventKind::kCrash) crashed_ = true;
    }
    sink_.events.clear();
    if (each) each();
    if (done && done()) break;
  }
  return t() - t0;
}

bool Rig::RunUntilMode(FlightMode mode, double max_s) {
  Run(max_s, [&] { return fc_->mode() == mode; });
  return fc_->mode() == mode;
}

bool Rig::HasEvent(FlightEventKind kind) const {
  for (const auto& e : events_) {
    if (e.kind == kind) return true;
  }
  return false;
}

}  // namespace swarmbox::flight::testing
