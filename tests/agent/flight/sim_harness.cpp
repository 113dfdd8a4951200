#include "sim_harness.hpp"

#include <cmath>
#include <cstdio>
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
  out.accel_m_s2 = E(s.imu.accel_m_s2);
  out.gyro_rad_s = E(s.imu.gyro_rad_s);
  out.baro_fresh = s.baro.fresh;
  out.baro_alt_m = s.baro.altitude_m;
  out.mag_fresh = s.mag.fresh;
  out.mag_body = E(s.mag.field_gauss);
  out.gps_fresh = s.gps.fresh;
  out.gps_valid = s.gps.valid;
  out.gps_pos_m = E(s.gps.position_m);
  out.gps_vel_m_s = E(s.gps.velocity_m_s);
  out.gps_eph_m = s.gps.h_acc_m;
  out.gps_epv_m = s.gps.v_acc_m;
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
  if (options.gps_fix == physics::GpsFix::kRtk) physics::SetRtkFix(&af->gps, options.rtk_baseline_km);
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
  // The twin of the World's receiver error: SensorSuite seed MixSeed(world seed, 0x5E0000 +
  // drone index) (world.cpp), GpsErrorModel seed MixSeed(that, 0x6A5) (sensor_models.cpp).
  rig->twin_ = std::make_unique<physics::GpsErrorModel>(
      physics::MixSeed(physics::MixSeed(options.seed, 0x5E0000 + rig->drone_), 0x6A5));
  rig->split_ = physics::GpsErrorModel::SplitForSpec(af->gps);
  rig->RecordTruthAndCheckGps();
  return rig;
}

void Rig::RecordTruthAndCheckGps() {
  const std::int64_t now = world_->time_ns();
  hist_t_[hist_n_ % kHist] = now;
  hist_p_[hist_n_ % kHist] = world_->Truth(drone_).position_m;
  ++hist_n_;
  const physics::GpsSample& g = world_->sensors(drone_).gps;
  if (!g.fresh || !g.valid) return;
  const double dt = last_fix_ns_ < 0 ? 0.0 : static_cast<double>(now - last_fix_ns_) * 1e-9;
  last_fix_ns_ = now;
  const physics::Vec3 err = twin_->Next(dt, split_);
  // The truth the fix describes: the newest at least the latency old (as SensorSuite::Delayed).
  const auto latency_ns = static_cast<std::int64_t>(std::llround(physics::kGpsLatencyS * 1e9));
  std::size_t k = hist_n_ - 1;
  while (k > 0 && hist_n_ - k < kHist && hist_t_[k % kHist] > now - latency_ns) --k;
  const physics::Vec3 expected = hist_p_[k % kHist] + err;
  const physics::Vec3 d = g.position_m - expected;
  if (std::sqrt(d.x * d.x + d.y * d.y + d.z * d.z) > 1e-9) {
    if (twin_ok_) {
      std::fprintf(stderr, "sim_harness: GPS fix at t=%.3f differs from the twin error model by (%g %g %g) m\n",
                   world_->time_s(), d.x, d.y, d.z);
    }
    twin_ok_ = false;
  }
}

Vec3 Rig::gps_error() const {
  const physics::Vec3& c = twin_->correlated_m();
  return Vec3(c.x, c.y, c.z);
}

Vec3 Rig::nav_pos() const {
  // Horizontal only: height is the barometer's (the GPS's vertical wander is estimated away).
  Vec3 shift = gps_error() - gps_ref_;
  shift.z() = 0.0;
  return true_pos() + shift;
}

Vec3 Rig::true_pos() const { return E(world_->Truth(drone_).position_m); }

double Rig::Run(double max_s, const std::function<bool()>& done, const std::function<void()>& each) {
  const double t0 = t();
  while (t() - t0 < max_s - 1e-9) {
    const ActuatorOutput& out = fc_->Step(FromPhysics(world_->sensors(drone_)));
    for (std::size_t i = 0; i < u_.size(); ++i) u_[i] = out.armed ? out.u[i] : 0.0;
    (void)world_->SetActuators(drone_, u_);
    world_->Step();
    RecordTruthAndCheckGps();
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
