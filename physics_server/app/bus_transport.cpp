#include "bus_transport.hpp"

#include <algorithm>
#include <chrono>
#include <string>
#include <string_view>

namespace swarmbox::physics {
namespace {

std::array<double, 3> A(const Vec3& v) { return {v.x, v.y, v.z}; }

}  // namespace

Result<std::unique_ptr<BusTransport>> BusTransport::Create(const bus::ParticipantConfig& config,
                                                           const std::vector<std::string>& drones,
                                                           const std::vector<GpsSpec>& gps_specs,
                                                           const std::vector<bool>& stereo_drones) {
  std::unique_ptr<BusTransport> t(new BusTransport());
  auto participant = bus::Participant::Create(config);
  if (!participant) return std::move(participant).error().Context("sim bus");
  t->participant_ = std::move(*participant);
  if (Status s = t->OpenWorldEndpoints(); !s) return s.error();
  for (std::size_t i = 0; i < drones.size(); ++i) {
    const bool stereo = i < stereo_drones.size() && stereo_drones[i];
    if (Status s = t->AddDroneEndpoints(drones[i], gps_specs.at(i), stereo, i); !s) return s.error();
  }
  // One reader for every drone's answers (the topic is keyed by drone).
  BusTransport* self = t.get();
  auto act = t->participant_->CreateSubscriber<bus::ActuatorCommand>(
      bus::kActuatorTopic, bus::Qos::kLockstep, [self](const bus::ActuatorCommand& c) { self->OnActuator(c); });
  if (!act) return std::move(act).error();
  t->actuators_sub_ = std::move(*act);
  return t;
}

Status BusTransport::OpenWorldEndpoints() {
  auto clock = participant_->CreatePublisher<bus::ClockTick>(bus::kClockTopic, bus::Qos::kLockstep);
  if (!clock) return std::move(clock).error();
  clock_ = std::move(*clock);
  // Created before the per-drone endpoints: announced first in discovery.
  auto status = participant_->CreatePublisher<bus::Event>(bus::kSimStatusTopic, bus::Qos::kLockstep);
  if (!status) return std::move(status).error();
  status_ = std::move(*status);
  auto wc = participant_->CreateSubscriber<bus::WorldCommand>(
      bus::kWorldCommandTopic, bus::Qos::kLockstep, [this](const bus::WorldCommand& c) {
        std::lock_guard<std::mutex> lock(mu_);
        world_.push_back({c.target, c.command, c.args, c.seq});
      });
  if (!wc) return std::move(wc).error();
  world_commands_ = std::move(*wc);
  return Ok{};
}

Status BusTransport::AddDroneEndpoints(const std::string& name, const GpsSpec& gps, bool stereo, std::size_t index) {
  if (auto s = bus::ValidateDroneName(name); !s) return s.error();
  DroneEndpoints e;
  e.name = name;
  e.gps = gps;
  auto sensor = participant_->CreatePublisher<bus::SensorSample>(bus::SensorTopic(name), bus::Qos::kLockstep);
  if (!sensor) return std::move(sensor).error();
  e.sensor = std::move(*sensor);
  auto camera = participant_->CreatePublisher<bus::CameraImage>(bus::CameraTopic(name), bus::Qos::kLockstep);
  if (!camera) return std::move(camera).error();
  e.camera = std::move(*camera);
  if (stereo) {
    auto pair = participant_->CreatePublisher<bus::CameraImage>(bus::StereoTopic(name), bus::Qos::kLockstep);
    if (!pair) return std::move(pair).error();
    e.stereo = std::move(*pair);
  }
  index_of_.emplace(name, index);
  drones_.push_back(std::move(e));
  return Ok{};
}

Status BusTransport::SubscribeTelemetry(std::function<void(const bus::Telemetry&)> on_telemetry) {
  auto sub = participant_->CreateSubscriber<bus::Telemetry>(bus::kTelemetryTopic, bus::Qos::kState, std::move(on_telemetry));
  if (!sub) return std::move(sub).error().Context("subscribing to telemetry");
  telemetry_sub_ = std::move(*sub);
  return Ok{};
}

Status BusTransport::PublishSample(std::size_t drone, const std::string& name, const SensorSample& s,
                                   const SampleExtras& extras) {
  bus::SensorSample& m = sample_msg_;
  const GpsSpec& spec = drones_.at(drone).gps;
  m.drone = name;
  m.step = s.step;
  m.sim_time_ns = s.time_ns;
  m.imu.valid = s.imu.fresh;
  m.imu.accel_m_s2 = A(s.imu.accel_m_s2);
  m.imu.gyro_rad_s = A(s.imu.gyro_rad_s);
  m.imu.temperature_c = s.baro.temperature_c;
  m.baro.valid = s.baro.fresh;
  m.baro.pressure_pa = s.baro.pressure_pa;
  m.baro.altitude_m = s.baro.altitude_m;
  m.baro.temperature_c = s.baro.temperature_c;
  m.mag.valid = s.mag.fresh;
  m.mag.field_gauss = A(s.mag.field_gauss);
  m.gps.valid = s.gps.fresh && s.gps.valid;
  m.gps.fix_type = s.gps.valid ? bus::GpsFix::k3d : bus::GpsFix::kNone;
  m.gps.num_satellites = s.gps.valid ? 12 : 0;
  m.gps.latitude_deg = s.gps.lat_deg;
  m.gps.longitude_deg = s.gps.lon_deg;
  m.gps.altitude_m = s.gps.alt_m;
  m.gps.position_enu_m = A(s.gps.position_m);
  m.gps.velocity_enu_m_s = A(s.gps.velocity_m_s);
  m.gps.h_acc_m = s.gps.valid ? s.gps.h_acc_m : spec.horizontal_std_m;
  m.gps.v_acc_m = s.gps.valid ? s.gps.v_acc_m : spec.vertical_std_m;
  m.battery.valid = false;  // no battery model in the physics server
  m.camera_frame = extras.camera_frame;
  m.stereo_frame = extras.stereo_frame;
  m.radio_in.assign(extras.radio_in.begin(), extras.radio_in.end());
  return drones_[drone].sensor->Publish(m);
}

namespace {

// A camera message's header: who, when, the frame's size and encoding, the pinhole and the pose.
void SetImageHeader(const std::string& name, std::uint64_t step, std::int64_t time_ns, int width_px,
                    int height_px, std::uint32_t bytes_per_px, std::string_view encoding,
                    const CameraIntrinsics& k, const Pose& pose, bus::CameraImage* m) {
  m->drone = name;
  m->step = step;
  m->sim_time_ns = time_ns;
  m->width_px = static_cast<std::uint32_t>(width_px);
  m->height_px = static_cast<std::uint32_t>(height_px);
  m->row_stride_bytes = static_cast<std::uint32_t>(width_px) * bytes_per_px;
  m->encoding = std::string(encoding);
  m->intrinsics.fx_px = k.fx_px;
  m->intrinsics.fy_px = k.fy_px;
  m->intrinsics.cx_px = k.cx_px;
  m->intrinsics.cy_px = k.cy_px;
  m->intrinsics.distortion = {};
  m->camera_pose.position_enu_m = A(pose.position_m);
  const Quat& q = pose.attitude;
  m->camera_pose.orientation_wxyz = {q.w, q.x, q.y, q.z};
}

}  // namespace

Status BusTransport::PublishCamera(std::size_t drone, const std::string& name, std::uint64_t step, const CameraImage& img) {
  bus::CameraImage& m = camera_msg_;
  SetImageHeader(name, step, img.time_ns, img.width_px, img.height_px, 3, "bgr8", img.intrinsics,
                 img.camera_pose, &m);
  m.data.assign(img.bgr.begin(), img.bgr.end());
  return drones_.at(drone).camera->Publish(m);
}

Status BusTransport::PublishThermal(std::size_t drone, const std::string& name, std::uint64_t step,
                                    const ThermalImage& img) {
  bus::CameraImage& m = thermal_msg_;
  SetImageHeader(name, step, img.time_ns, img.width_px, img.height_px, 2, bus::kThermalEncoding,
                 img.intrinsics, img.camera_pose, &m);
  // Little-endian 16-bit counts (the bus's byte order for "16UC1" and "mono16").
  m.data.resize(img.centikelvin.size() * 2);
  for (std::size_t k = 0; k < img.centikelvin.size(); ++k) {
    m.data[2 * k] = static_cast<std::uint8_t>(img.centikelvin[k] & 0xFF);
    m.data[2 * k + 1] = static_cast<std::uint8_t>(img.centikelvin[k] >> 8);
  }
  return drones_.at(drone).camera->Publish(m);
}

Status BusTransport::PublishStereo(std::size_t drone, const bus::CameraImage& pair) {
  const DroneEndpoints& e = drones_.at(drone);
  if (!e.stereo) return Error(ErrorCode::kInternal, "drone '" + e.name + "' has no stereo pair publisher");
  return e.stereo->Publish(pair);
}

Status BusTransport::PublishClock(std::uint64_t step, std::int64_t sim_time_ns, std::int64_t period_ns, double rtf) {
  bus::ClockTick tick;
  tick.step = step;
  tick.sim_time_ns = sim_time_ns;
  tick.step_period_ns = period_ns;
  tick.rtf = rtf;
  return clock_->Publish(tick);
}

// The middleware's thread, one call at a time.
void BusTransport::OnActuator(const bus::ActuatorCommand& c) {
  const auto it = index_of_.find(c.drone);
  std::lock_guard<std::mutex> lock(mu_);
  if (it == index_of_.end()) {
    ++unknown_;
    return;
  }
  ActuatorInput in{drones_[it->second].name, c.step, c.armed, c.motor_throttle, c.raft_leader, {}, c.radio_out};
  in.world.reserve(c.world.size());
  for (const bus::WorldCommand& w : c.world) in.world.push_back({w.target, w.command, w.args, w.seq});
  actuators_.push_back(std::move(in));
  // Notified under the lock: the waiter cannot miss it, and wakes only when its count is reached.
  if (wake_at_ != 0 && actuators_.size() >= wake_at_) cv_.notify_one();
}

Status BusTransport::PublishStatus(const JoiningStatus& status, bool done) {
  bus::Event e;
  e.node = "physics";
  e.sim_time_ns = 0;  // the first step
  e.name = done ? "joined" : "joining";
  std::string missing;
  for (const std::string& name : status.missing) {
    if (!missing.empty()) missing += ',';
    missing += name;
  }
  e.fields = {{"joined", std::to_string(status.joined)},
              {"expected", std::to_string(status.expected)},
              {"missing", std::move(missing)}};
  return status_->Publish(e);
}

void BusTransport::WaitActuators(std::int64_t deadline_ns, std::size_t awaited, std::vector<ActuatorInput>* out) {
  std::unique_lock<std::mutex> lock(mu_);
  const auto deadline = std::chrono::steady_clock::time_point(std::chrono::nanoseconds(deadline_ns));
  wake_at_ = std::max<std::size_t>(1, awaited);
  cv_.wait_until(lock, deadline, [this] { return actuators_.size() >= wake_at_; });
  wake_at_ = 0;
  while (!actuators_.empty()) {
    out->push_back(std::move(actuators_.front()));
    actuators_.pop_front();
  }
}

std::uint64_t BusTransport::unknown_commands() const {
  std::lock_guard<std::mutex> lock(mu_);
  return unknown_;
}

void BusTransport::TakeWorldCommands(std::vector<WorldCommandInput>* out) {
  std::lock_guard<std::mutex> lock(mu_);
  while (!world_.empty()) {
    out->push_back(std::move(world_.front()));
    world_.pop_front();
  }
}

}  // namespace swarmbox::physics
