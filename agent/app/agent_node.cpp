#include "agent_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "brain_convert.hpp"
#include "server_wait.hpp"
#include "swarmbox/bus/topics.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/depth/clearance.hpp"
#include "swarmbox/depth/drop_spot.hpp"
#include "wait_budget.hpp"

namespace swarmbox::agent {
namespace {

flight::Vec3 V(const std::array<double, 3>& a) { return flight::Vec3(a[0], a[1], a[2]); }

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", s);
  return buf;
}

// The wall clock of radio.model netem only (the wall part of its lost-member rule, as the radio
// itself runs on it); never read with the channel.
double SteadyS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();  // the telemetry's "none"

// Flocking (SarBrain): V18's horizontal terms; separation = repulsion, alignment = Reynolds'
// alignment + V18 friction, cohesion, and their sum. None (NaN) without SarBrain.
void FillTelemetryFlocking(const swarm::FlockingOutput* f, bus::Telemetry& t) {
  if (f == nullptr) {
    t.flock_separation = t.flock_alignment = t.flock_cohesion = t.flock_sum = {kNaN, kNaN, kNaN};
    return;
  }
  const swarm::Vec2 align = f->alignment + f->friction;
  const swarm::Vec2 sum = f->repulsion + align + f->cohesion;
  t.flock_separation = {f->repulsion.x(), f->repulsion.y(), 0.0};
  t.flock_alignment = {align.x(), align.y(), 0.0};
  t.flock_cohesion = {f->cohesion.x(), f->cohesion.y(), 0.0};
  t.flock_sum = {sum.x(), sum.y(), 0.0};
}

}  // namespace

Result<RadioModel> ParseRadioModel(std::string_view text) {
  if (text == "netem") return RadioModel::kNetem;
  if (text == "channel") return RadioModel::kChannel;
  return Error(ErrorCode::kInvalidArgument, "--radio-model '" + std::string(text) + "': expected channel or netem");
}

std::string_view RadioModelName(RadioModel model) { return model == RadioModel::kChannel ? "channel" : "netem"; }

flight::SensorSample FromBus(const bus::SensorSample& m) {
  flight::SensorSample s;
  s.t_s = static_cast<double>(m.sim_time_ns) * 1e-9;
  s.imu_fresh = m.imu.valid;
  s.accel_m_s2 = V(m.imu.accel_m_s2);
  s.gyro_rad_s = V(m.imu.gyro_rad_s);
  s.baro_fresh = m.baro.valid;
  s.baro_alt_m = m.baro.altitude_m;
  s.mag_fresh = m.mag.valid;
  s.mag_body = V(m.mag.field_gauss);
  // The bus marks a GPS sample valid only when it is a new fix; a dropout sends no valid fixes.
  s.gps_fresh = m.gps.valid;
  s.gps_valid = m.gps.valid && m.gps.fix_type == bus::GpsFix::k3d;
  s.gps_pos_m = V(m.gps.position_enu_m);
  s.gps_vel_m_s = V(m.gps.velocity_enu_m_s);
  s.gps_eph_m = m.gps.h_acc_m;  // the receiver's reported accuracy: how much the estimator trusts it
  s.gps_epv_m = m.gps.v_acc_m;
  return s;
}

AgentNode::AgentNode(AgentOptions options, flight::FlightController fc, FlightPlan plan)
    : options_(std::move(options)), fc_(std::move(fc)), plan_(std::move(plan)) {
  cmd_.drone = options_.name;
  telemetry_.drone = options_.name;
  cmd_.motor_throttle.assign(fc_.mixer().rotor_count(), 0.0);
  state_.drone = options_.name;
  frames_.reserve(64);
  lines_.reserve(8);
}

// Members are destroyed in reverse order of declaration: the Raft host and the probe before the
// radio, the radio before the mesh participant.
AgentNode::~AgentNode() = default;

void AgentNode::Log(const LogEvent& e) {
  std::fprintf(options_.log, "%s\n", e.str().c_str());
  std::fflush(options_.log);
}

bool AgentNode::TakeCamera(const bus::SensorSample& msg) {
  camera_frames_.count = 0;
  if (!camera_sub_) return true;
  switch (TakeStepFrames(*camera_sub_, msg.sim_time_ns, msg.camera_frame, options_.camera_timeout, options_.stop,
                         &camera_frames_)) {
    case FrameWait::kStopped: return false;
    case FrameWait::kMissing:
      Log(LogEvent(t_s_, options_.name, "camera_missing")
              .Add("step", static_cast<std::int64_t>(msg.step))
              .Add("after_wall_s", std::chrono::duration<double>(options_.camera_timeout).count(), 1));
      return true;
    case FrameWait::kTaken: return true;
  }
  return true;
}

void AgentNode::OnRaftPayload(std::span<const std::uint8_t> bytes) {
  if (raft_) raft_->OnPayload(bytes);
}

void AgentNode::OnPing(const bus::RadioFrame& frame) {
  if (probe_) probe_->OnFrame(frame, *radio_);
}

void AgentNode::OnState(const bus::DroneState& state, const bus::RadioFrame& frame) {
  // netem, SarBrain only: when it arrived on the steady clock, for the lost-member rule's
  // wall-clock silence (its side channel). channel: none, the simulated clock alone decides.
  if (sar_ != nullptr && options_.radio_model == RadioModel::kNetem && state.drone != options_.name) {
    netem_wall_.OnState(state.drone, state.sim_time_ns, static_cast<double>(frame.delivered_ns) * 1e-9);
  }
  if (brain_host_) brain_host_->OnState(state);
}

void AgentNode::OnDetection(const bus::Detection& /*detection*/, const bus::RadioFrame& /*frame*/) {
  // Heard and counted (dispatched_.detection): sightings reach the swarm through Raft; the
  // broadcast detections are for recorders and a ground station.
}

void AgentNode::OnBrainMessage(const bus::BrainMessage& message, const bus::RadioFrame& /*frame*/) {
  // Counted (dispatched_.brain); the built-in missions have no brain inbox.
  if (brain_host_) brain_host_->OnMessage(message);
}

void AgentNode::TakeRadioFrames(const bus::SensorSample& msg) {
  frames_.clear();
  if (!radio_) return;
  radio_->TakeReceived(msg, &frames_);
  if (probe_) {
    for (const bus::RadioFrame& f : frames_) probe_->Heard(f);  // the ping sampling's order
  }
  DispatchFrames(frames_, options_.name, *this, &dispatched_);
}

Status AgentNode::ServeRadioBetweenSteps() {
  TakeRadioFrames(bus::SensorSample{});  // netem: the sample is not looked at
  return StepRaftAndProbe();
}

Status AgentNode::StepRaftAndProbe() {
  if (raft_) {
    if (Status s = raft_->Step(); !s) return s.error().Context("raft stopped");
  }
  if (probe_) {
    lines_.clear();
    probe_->Step(radio::RadioTime(radio_->now_ns()), t_s_, *radio_, &lines_);
    for (const LogEvent& line : lines_) Log(line);
  }
  return Ok{};
}

Status AgentNode::HandleSample(const bus::SensorSample& msg) {
  t_s_ = static_cast<double>(msg.sim_time_ns) * 1e-9;
  sim_clock_.Set(t_s_);
  // a. The camera frame of this step.
  if (!TakeCamera(msg)) return Ok{};  // stop requested: Run() logs it
  cmd_.world.clear();
  // b. What the radio delivered for this step, in delivery order.
  TakeRadioFrames(msg);
  // c. Flight, Raft, the link probe, the mission or plan, the state broadcast.
  const FlightStatus st = StepFlight(msg);
  if (depth_ && !StepDepth(msg)) return Ok{};  // stop requested: Run() logs it
  if (Status s = StepRaftAndProbe(); !s) return s;
  if (sar_ != nullptr) {
    StepMission(msg);
  } else if (brain_host_) {
    StepBrain(msg);
  } else {
    StepPlan(st);
  }
  LogBattery();
  BroadcastState(msg);
  // d. The step's answer: motors, world commands, Raft leadership, the radio's frames.
  PublishAnswer();
  if (telemetry_pub_ && telemetry_clock_.Due(msg.sim_time_ns)) PublishTelemetry(msg);
  return Ok{};
}

FlightStatus AgentNode::StepFlight(const bus::SensorSample& msg) {
  using flight::FlightEventKind;
  const flight::ActuatorOutput& out = fc_.Step(FromBus(msg));
  cmd_.step = msg.step;
  cmd_.sim_time_ns = msg.sim_time_ns;
  cmd_.armed = out.armed;
  for (std::size_t i = 0; i < cmd_.motor_throttle.size(); ++i) cmd_.motor_throttle[i] = out.armed ? out.u[i] : 0.0;

  FlightStatus st;
  st.t_s = t_s_;
  st.mode = fc_.mode();
  st.pos_m = fc_.estimate().pos_m;
  flight::FlightEvent e;
  while (fc_.PopEvent(&e)) {
    switch (e.kind) {
      case FlightEventKind::kArrived: st.arrived = true; break;
      case FlightEventKind::kHover: st.hover = true; break;
      case FlightEventKind::kLanded: st.landed = true; break;
      case FlightEventKind::kRejected: st.rejected = true; break;
      default: break;
    }
    if (brain_host_) brain_host_->OnFlightEvent(e);
    LogEvent le(e.t_s, options_.name, flight::FlightEventName(e.kind));
    if (e.kind == FlightEventKind::kModeChange) le.Add("mode", flight::FlightModeName(e.mode));
    le.Add("x", e.pos_m.x(), 2).Add("y", e.pos_m.y(), 2).Add("z", e.pos_m.z(), 2);
    Log(le);
  }
  return st;
}

void AgentNode::StepPlan(const FlightStatus& st) {
  if (auto sp = plan_.Tick(st)) (void)fc_.Command(*sp);
  if (plan_.index() != plan_index_logged_ && !plan_.finished()) {
    plan_index_logged_ = plan_.index();
    Log(LogEvent(t_s_, options_.name, "plan_step").Add("step", plan_.current()));
  }
  if (plan_.finished() && !plan_done_logged_) {
    plan_done_logged_ = true;
    Log(LogEvent(t_s_, options_.name, "plan_complete"));
  }
}

void AgentNode::LogBattery() {
  if (!brain_host_ || t_s_ < next_battery_log_s_) return;
  // The battery once per simulated second, for the trial's plots (SarBrain: its own model, as
  // BroadcastState sends it).
  next_battery_log_s_ = std::floor(t_s_) + 1.0;
  Log(LogEvent(t_s_, options_.name, "battery")
          .Add("fraction", sar_ != nullptr ? sar_->battery_fraction() : vehicle_.battery_fraction, 4));
}

void AgentNode::PublishAnswer() {
  if (radio_) {
    radio_->Flush(&cmd_);
  } else {
    cmd_.radio_out.clear();
  }
  cmd_.raft_leader = raft_ && raft_->service().is_leader();
  if (Status s = actuator_pub_->Publish(cmd_); !s) {
    Log(LogEvent(t_s_, options_.name, "bus_error").Add("what", "actuator").Add("reason", s.error().ToString()));
  }
}

void AgentNode::PublishTelemetry(const bus::SensorSample& msg) {
  bus::Telemetry& t = telemetry_;
  t.sim_time_ns = msg.sim_time_ns;
  const flight::StateEstimate& est = fc_.estimate();
  t.position_enu_m = {est.pos_m.x(), est.pos_m.y(), est.pos_m.z()};
  t.velocity_enu_m_s = {est.vel_m_s.x(), est.vel_m_s.y(), est.vel_m_s.z()};
  t.attitude_wxyz = {est.att.w(), est.att.x(), est.att.y(), est.att.z()};
  const flight::FlightMode mode = fc_.mode();
  t.flight_mode = std::string(flight::FlightModeName(mode));
  FillTelemetrySetpoint(t);
  FillTelemetryFlocking(sar_ != nullptr ? sar_->flocking() : nullptr, t);
  FillTelemetryRaft(t);
  if (sar_ != nullptr) {
    t.battery_fraction = sar_->battery_fraction();
  } else if (brain_host_) {
    t.battery_fraction = vehicle_.battery_fraction;
  } else {
    t.battery_fraction = kNaN;  // the built-in plan has no battery model
  }
  t.mission_stage = brain_host_ ? brain_host_->status() : std::string(plan_.current());
  t.armed = cmd_.armed;
  t.landed = LandedMode(mode);
  t.detections.swap(telemetry_detections_);
  telemetry_detections_.clear();
  t.events.clear();
  telemetry_events_.TakeInto(&t.events);
  t.links.clear();
  for (const bus::Event& e : t.events) {
    if (auto link = LinkOf(e)) t.links.push_back(std::move(*link));
  }
  // Best effort: the recording loses this one if the bus refuses it; the run goes on.
  (void)telemetry_pub_->Publish(t);
}

void AgentNode::FillTelemetrySetpoint(bus::Telemetry& t) const {
  // The setpoint: what a brain commanded (NaN = the axis it left unset), else the flight
  // stack's shaped reference (the built-in plan).
  const brain::Setpoint* flown = brain_host_ ? brain_host_->flown() : nullptr;
  if (flown != nullptr) {
    t.setpoint_position_enu_m = {flown->position_m.x, flown->position_m.y, flown->position_m.z};
    t.setpoint_velocity_enu_m_s = {flown->velocity_m_s.x, flown->velocity_m_s.y, flown->velocity_m_s.z};
    t.setpoint_yaw_rad = flown->yaw_rad;
  } else if (brain_host_) {
    t.setpoint_position_enu_m = {kNaN, kNaN, kNaN};
    t.setpoint_velocity_enu_m_s = {kNaN, kNaN, kNaN};
    t.setpoint_yaw_rad = kNaN;
  } else {
    const flight::TrajectoryPoint& ref = fc_.telemetry().reference;
    t.setpoint_position_enu_m = {ref.pos_m.x(), ref.pos_m.y(), ref.pos_m.z()};
    t.setpoint_velocity_enu_m_s = {ref.vel_m_s.x(), ref.vel_m_s.y(), ref.vel_m_s.z()};
    t.setpoint_yaw_rad = kNaN;
  }
}

void AgentNode::FillTelemetryRaft(bus::Telemetry& t) {
  t.sectors.clear();
  if (!raft_) {
    t.raft_role.clear();
    t.raft_term = 0;
    t.raft_leader.clear();
    t.raft_commit_index = 0;
    return;
  }
  const raft_service::RaftService& r = raft_->service();
  t.raft_role = r.is_learner() ? "learner" : std::string(raft::RoleName(r.role()));
  t.raft_term = r.term();
  t.raft_leader = r.leader();
  t.raft_commit_index = r.commit_index();
  // The leader's committed plan, on a change and every simulated second.
  // SarBrain's mission state is Raft's machine behind a reference (FindMission does not see through it).
  const raft::MissionState* mission = nullptr;
  if (r.is_leader()) mission = sar_state_ != nullptr ? &sar_state_->mission() : raft_->FindMission();
  if (mission == nullptr) return;
  SectorsOf(mission->sectors(), &sectors_scratch_);
  if (t_s_ - sectors_sent_s_ >= 1.0 || sectors_scratch_ != sectors_sent_) {
    sectors_sent_s_ = t_s_;
    sectors_sent_ = sectors_scratch_;
    t.sectors = sectors_scratch_;
  }
}

void AgentNode::BroadcastState(const bus::SensorSample& msg) {
  // Our state for the neighbours, 5 Hz of simulated time.
  if (!radio_ || t_s_ < next_state_s_) return;
  next_state_s_ = t_s_ + 0.2;
  const flight::StateEstimate& est = fc_.estimate();
  ++state_.seq;
  state_.sim_time_ns = msg.sim_time_ns;
  // Informational only (recorders); never read on the channel, where it stays 0 so a frame's
  // bytes do not depend on the wall clock.
  state_.wall_time_ns = options_.radio_model == RadioModel::kNetem
                            ? std::chrono::duration_cast<std::chrono::nanoseconds>(
                                  std::chrono::system_clock::now().time_since_epoch())
                                  .count()
                            : 0;
  state_.position_enu_m = {est.pos_m.x(), est.pos_m.y(), est.pos_m.z()};
  state_.velocity_enu_m_s = {est.vel_m_s.x(), est.vel_m_s.y(), est.vel_m_s.z()};
  state_.heading_rad = flight::YawOf(est.att);
  if (brain_host_) {
    // The brain's status (Neighbour::status on the other drones); the flight mode until it says.
    state_.mode = brain_host_->status().empty() ? std::string(flight::FlightModeName(fc_.mode())) : brain_host_->status();
    // SarBrain: its own battery model (the one behind its battery_low), as before the SDK.
    state_.battery_fraction = sar_ != nullptr ? sar_->battery_fraction() : vehicle_.battery_fraction;
  } else {
    state_.mode = std::string(flight::FlightModeName(fc_.mode()));
  }
  out_frame_ = bus::RadioFrame{};
  out_frame_.state_msg.push_back(state_);
  radio_->Send(std::move(out_frame_));
}

void AgentNode::StepBrain(const bus::SensorSample& msg) {
  const flight::StateEstimate& est = fc_.estimate();
  const flight::FlightMode mode = fc_.mode();
  if (battery_) battery_->Step(options_.control_dt_s, est.vel_m_s, brain_host_->payload_mass_kg(), !LandedMode(mode));
  brain::Vehicle& v = vehicle_;
  v.name = options_.name;
  v.step = msg.step;
  v.position_m = {est.pos_m.x(), est.pos_m.y(), est.pos_m.z()};
  v.velocity_m_s = {est.vel_m_s.x(), est.vel_m_s.y(), est.vel_m_s.z()};
  v.attitude_wxyz[0] = est.att.w();
  v.attitude_wxyz[1] = est.att.x();
  v.attitude_wxyz[2] = est.att.y();
  v.attitude_wxyz[3] = est.att.z();
  v.angular_rate_rad_s = {est.rate_rad_s.x(), est.rate_rad_s.y(), est.rate_rad_s.z()};
  v.heading_rad = flight::YawOf(est.att);
  v.battery_fraction = battery_ ? battery_->fraction() : 1.0;
  v.battery_voltage_v = 0.0;  // not modelled: the battery model counts energy
  v.flight_mode = std::string(flight::FlightModeName(mode));
  v.armed = cmd_.armed;
  v.landed = LandedMode(mode);
  v.mass_estimate_kg = fc_.telemetry().mass_estimate_kg;
  brain_host_->Step(msg.step, msg.sim_time_ns, v, &cmd_.world);
}

// A thermal frame to perception in kelvin: 16-bit little-endian counts of 0.01 K (bus/messages.hpp).
void AgentNode::OnThermalImage(const bus::CameraImage& image) {
  const int w = static_cast<int>(image.width_px), h = static_cast<int>(image.height_px);
  if (w <= 0 || h <= 0 || image.row_stride_bytes < image.width_px * 2 ||
      image.data.size() < static_cast<std::size_t>(h) * image.row_stride_bytes) {
    return;
  }
  thermal_kelvin_.create(h, w, CV_32F);
  for (int y = 0; y < h; ++y) {
    const std::uint8_t* row = image.data.data() + static_cast<std::size_t>(y) * image.row_stride_bytes;
    auto* out = thermal_kelvin_.ptr<float>(y);
    for (int x = 0; x < w; ++x) {
      const auto counts = static_cast<unsigned>(row[2 * x]) | (static_cast<unsigned>(row[2 * x + 1]) << 8);
      out[x] = static_cast<float>(counts) * 0.01f;
    }
  }
  const bus::CameraIntrinsics& k = image.intrinsics;
  perception_->OnThermalFrame(thermal_kelvin_, {k.fx_px, k.fy_px, k.cx_px, k.cy_px},
                              static_cast<double>(image.sim_time_ns) * 1e-9);
}

void AgentNode::StepMission(const bus::SensorSample& msg) {
  // Perception (scouts): this step's frames geolocated with the estimate of their capture step,
  // to the brain once the inference latency has passed.
  detections_.clear();
  if (perception_) {
    perception_->RecordEstimate(t_s_, fc_.estimate());
    for (std::size_t i = 0; i < camera_frames_.count; ++i) {
      bus::CameraImage& image = camera_frames_.images[i];
      if (image.encoding == bus::kThermalEncoding) {  // before its colour frame (frame_wait.hpp)
        OnThermalImage(image);
        continue;
      }
      if (image.encoding != "bgr8" && image.encoding != "rgb8") continue;  // the detector needs colour
      if (image.data.size() < static_cast<std::size_t>(image.height_px) * image.row_stride_bytes) continue;
      cv::Mat bgr(static_cast<int>(image.height_px), static_cast<int>(image.width_px), CV_8UC3, image.data.data(),
                  image.row_stride_bytes);
      if (image.encoding == "rgb8") cv::cvtColor(bgr, bgr, cv::COLOR_RGB2BGR);
      const bus::CameraIntrinsics& k = image.intrinsics;
      perception_->OnCameraFrame(bgr, {k.fx_px, k.fy_px, k.cx_px, k.cy_px}, static_cast<double>(image.sim_time_ns) * 1e-9);
    }
    perception_->PopVisible(t_s_, &detections_);
    for (const brain::Detection& d : detections_) brain_host_->OnDetection(d);
    if (telemetry_pub_) {
      for (const brain::Detection& d : detections_) telemetry_detections_.push_back(DetectionToBus(d, options_.name));
    }
  }
  if (depth_) AnswerDropSpot();
  // The lost-member rule's wall clock, netem only: with the channel the radio runs on simulated
  // time and nothing of the wall clock may feed a decision (the brain has no side channel then).
  if (options_.radio_model == RadioModel::kNetem) netem_wall_.now_s = SteadyS();
  StepBrain(msg);
  // The detections on the radio too (for recorders and a ground station), best effort.
  for (const brain::Detection& d : detections_) {
    out_frame_ = bus::RadioFrame{};
    out_frame_.detection_msg.push_back(DetectionToBus(d, options_.name));
    radio_->Send(std::move(out_frame_));
  }
}

bool AgentNode::StepDepth(const bus::SensorSample& msg) {
  const flight::StateEstimate& e = fc_.estimate();
  bus::Pose body;
  body.position_enu_m = {e.pos_m.x(), e.pos_m.y(), e.pos_m.z()};
  body.orientation_wxyz = {e.att.w(), e.att.x(), e.att.y(), e.att.z()};
  switch (depth_->TakePairs(msg, body)) {
    case FrameWait::kStopped: return false;
    case FrameWait::kMissing:
      Log(LogEvent(t_s_, options_.name, "stereo_missing")
              .Add("step", static_cast<std::int64_t>(msg.step))
              .Add("after_wall_s", std::chrono::duration<double>(options_.camera_timeout).count(), 1));
      break;
    case FrameWait::kTaken: break;
  }
  const int released = depth_->Release(msg.sim_time_ns);
  // Geolocation on the surface the depth saw (StepMission's camera frames come after this).
  if (released > 0 && perception_) {
    const DepthHost::Frame& f = *depth_->latest();
    perception_->OnDepthFrame(f.frame, f.camera_pose, f.intrinsics);
  }
  // A scout's safe height: the highest surface around it in each new depth frame.
  if (released > 0 && sar_ != nullptr && sar_->role() == swarm::Role::kScout) {
    const DepthHost::Frame& f = *depth_->latest();
    const depth::Clearance c = depth::ClearanceBelow(f.frame.depth_m, f.intrinsics, f.camera_pose, {});
    if (c.valid) sar_->ReportObstacleTop(c.top_z_m);
  }
  return true;
}

namespace {

constexpr double kDegPerRad = 180.0 / std::numbers::pi;

// How the agent checks a drop spot: the ground's height from the view (the drone's own height is
// an estimate, and SGBM reads the ground low from 8 m: depth::DropSpotConfig::ground_quantile), and
// no footprint centre within 2.5 m of the victim: half a person's length (0.9 m) plus half the
// footprint's width (0.6 m) plus 1 m for the rescuers between them; the usual drop point is 3 m
// away (LifterConfig::stretcher_offset_m). The stretcher goes beside the victim, never over them.
constexpr double kGroundQuantile = 0.3;
constexpr double kVictimKeepOut_m = 2.5;

// The survey's config: the ground from the view, the victim kept clear, the lifter's own payload
// (hanging under the camera at the exposure) masked out.
depth::DropSpotConfig DropSpotConfigFor(const SarBrain::DropSpotQuery& q, const bus::Pose& camera,
                                        const std::optional<depth::SlungPayload>& payload) {
  depth::DropSpotConfig config;
  config.ground_quantile = kGroundQuantile;
  config.keep_out.push_back({.x_m = q.victim_xy_m.x(), .y_m = q.victim_xy_m.y(), .radius_m = kVictimKeepOut_m});
  if (payload) config.masked.push_back(depth::SlungPayloadVolume(camera, *payload));
  return config;
}

}  // namespace

void AgentNode::AnswerDropSpot() {
  if (sar_ == nullptr || !sar_->drop_spot_query()) return;
  const SarBrain::DropSpotQuery& q = *sar_->drop_spot_query();
  const DepthHost::Frame* f = depth_->latest();
  // A frame exposed once the lifter held over the point, and each frame answers once.
  if (f == nullptr || static_cast<double>(f->frame.capture_ns) * 1e-9 < q.since_t_s ||
      f->frame.capture_ns == drop_spot_frame_ns_) {
    return;
  }
  drop_spot_frame_ns_ = f->frame.capture_ns;
  const depth::DropSpot spot = depth::ChooseDropSpot(f->frame.depth_m, f->intrinsics, f->camera_pose,
                                                     q.default_xy_m.x(), q.default_xy_m.y(), q.yaw_rad,
                                                     q.ground_z_m, DropSpotConfigFor(q, f->camera_pose, slung_payload_));
  LogEvent line(t_s_, options_.name, "drop_spot_survey");
  line.Add("capture_s", static_cast<double>(f->frame.capture_ns) * 1e-9, 3)
      .Add("fill", f->frame.summary.fill_rate, 2)
      .Add("candidates", static_cast<std::int64_t>(spot.candidates))
      .Add("flat", static_cast<std::int64_t>(spot.flat))
      .Add("default_ok", spot.default_ok)
      .Add("found", spot.found)
      .Add("ground_m", spot.ground_z_m - q.ground_z_m, 2);
  if (spot.at_default.valid) {
    line.Add("default_slope_deg", spot.at_default.slope_rad * kDegPerRad, 1)
        .Add("default_height_m", spot.at_default.height_m - spot.ground_z_m, 2);
  }
  Log(line);
  swarm::DropSpotAnswer answer;
  answer.found = spot.found;
  answer.xy_m = Eigen::Vector2d(spot.x_m, spot.y_m);
  answer.slope_deg = spot.fit.slope_rad * kDegPerRad;
  answer.height_m = spot.fit.height_m - spot.ground_z_m;
  answer.default_ok = spot.default_ok;
  sar_->AnswerDropSpot(answer);
}

bool AgentNode::Done() const {
  if (sar_ != nullptr) {
    return sar_->complete() && (fc_.mode() == flight::FlightMode::kLanded || fc_.mode() == flight::FlightMode::kIdle);
  }
  if (brain_host_) return false;  // a brain flies until the trial ends (the samples stop)
  return plan_.finished();
}

// One wait for the next sample. The timeout counts the time spent waiting, each slice at most its
// own length: a process stopped (SIGSTOP, docker pause) or starved in the middle of a slice does
// not find its deadline gone when it resumes. Before the first sample the wait is for a sign of
// the server (server_wait.hpp): each sim/status message of its start starts it afresh. After it,
// each sim/status `joining` (the server waits for other drones) starts the wait afresh too, and
// the bound is the start's patience (first_sample_timeout) while the lockstep is still at its
// first step, stall_timeout once it has moved: at 100 drones on a loaded host the server's start
// itself can pause for longer than a stall timeout (2026-11-27, load ~70: 10-12 s between two of
// its joining lines, and the three drones that had joined gave up after 5 s).
class AgentNode::SampleWait {
 public:
  SampleWait(bool got_any, bool lockstep_moved, const AgentOptions& o)
      : got_any_(got_any),
        timeout_(got_any && lockstep_moved ? o.stall_timeout : o.first_sample_timeout),
        budget_(timeout_),
        server_(o.first_sample_timeout, o.name) {}

  bool got_any() const { return got_any_; }
  std::chrono::milliseconds timeout() const { return timeout_; }
  const ServerWait& server() const { return server_; }
  bool spent() const { return got_any_ ? budget_.spent() : server_.spent(); }
  std::chrono::milliseconds Slice(std::chrono::milliseconds max) const {
    return got_any_ ? budget_.Slice(max) : server_.Slice(max);
  }
  // A slice waited without a sample; before the first sample, the server's statuses since.
  void Spend(std::chrono::steady_clock::duration elapsed, std::chrono::milliseconds slice,
             bus::Subscriber<bus::Event>& status_sub, bus::Event& status) {
    if (got_any_) {
      budget_.Spend(elapsed, slice);
      // The server's start still going on (sim/status `joining`): a drone that joined early has
      // its first sample and then none until every drone has joined, which at 100 drones takes
      // longer than the stall timeout. That pause is the start's, not a stall: wait afresh.
      while (status_sub.Take(status)) {
        if (status.name == "joining") budget_ = WaitBudget(timeout_);
      }
      return;
    }
    server_.Spend(elapsed, slice);
    while (status_sub.Take(status)) server_.OnStatus(status);
  }

 private:
  bool got_any_;
  std::chrono::milliseconds timeout_;
  WaitBudget budget_;
  ServerWait server_;
};

Status AgentNode::Run() {
  LogReady();
  bus::SensorSample msg;
  bus::Event status;
  bool got_any = false;
  while (true) {
    SampleWait wait(got_any, have_step_ && last_step_ > 0, options_);
    auto waited = WaitForSample(wait, msg, status);
    if (!waited) return waited.error();
    if (*waited == Waited::kStopped) return Ok{};
    if (*waited == Waited::kTimedOut) return SamplesStopped(wait);
    if (have_step_ && msg.step == last_step_) {
      (void)actuator_pub_->Publish(cmd_);  // a resent sample: answer it again, do not step twice
      continue;
    }
    if (have_step_ && msg.step < last_step_) continue;  // stale
    got_any = true;
    have_step_ = true;
    last_step_ = msg.step;
    SWARMBOX_TRY(HandleSample(msg));
    if (options_.exit_when_done && Done()) return Ok{};
  }
}

void AgentNode::LogReady() {
  Log(LogEvent(0.0, options_.name, "ready")
          .Add("sim_domain", options_.sim_domain)
          .Add("sim_interface", options_.sim_interface)
          .Add("middleware", options_.middleware)
          .Add("radio_model", RadioModelName(options_.radio_model))
          .Add("brain", BrainKindName(options_.brain.kind))
          .Add("mission", brain_host_ && sar_ == nullptr ? std::string_view("-") : MissionKindName(options_.mission.kind))
          .Add("plan", brain_host_ ? std::string("-") : options_.plan)
          .Add("raft", raft_ ? options_.raft.raft_dir : std::string("off")));
}

Result<AgentNode::Waited> AgentNode::WaitForSample(SampleWait& wait, bus::SensorSample& msg, bus::Event& status) {
  // In slices, so a stop request is seen while no sample comes.
  while (true) {
    if (options_.stop != nullptr && *options_.stop != 0) {
      Log(LogEvent(t_s_, options_.name, "stopped").Add("reason", "signal"));
      return Waited::kStopped;
    }
    if (wait.spent()) {
      // Look at the topic once more before giving up (a sample may have come in the last slice).
      return sensor_sub_->Take(msg) ? Waited::kSample : Waited::kTimedOut;
    }
    // netem: the mesh lives on the wall clock whether or not the lockstep moves (a drone the
    // physics server is waiting for, a stalled server): Raft and the probe go on between
    // samples, every 10 ms without one.
    const bool idle_radio = options_.radio_model == RadioModel::kNetem && radio_ && (raft_ || probe_);
    const auto max_slice = idle_radio ? std::chrono::milliseconds(10) : std::chrono::milliseconds(50);
    const auto slice = wait.Slice(max_slice);
    const auto start = std::chrono::steady_clock::now();
    if (sensor_sub_->TakeFor(msg, slice)) return Waited::kSample;
    wait.Spend(std::chrono::steady_clock::now() - start, slice, *status_sub_, status);
    if (idle_radio) SWARMBOX_TRY(ServeRadioBetweenSteps());
  }
}

Status AgentNode::SamplesStopped(const SampleWait& wait) {
  const double secs = std::chrono::duration<double>(wait.timeout()).count();
  if (!wait.got_any()) {
    return Error(ErrorCode::kUnavailable,
                 "no sensor sample on " + bus::SensorTopic(options_.name) + " " + wait.server().Reason() +
                     ": is swarmbox-physics running with this drone on " + options_.middleware + " domain " +
                     std::to_string(options_.sim_domain) + ", interface " + options_.sim_interface + "?");
  }
  Log(LogEvent(t_s_, options_.name, "samples_stopped")
          .Add("after_s", secs, 1)
          .Add("plan", sar_ != nullptr ? std::string_view("sar") : brain_host_ ? std::string_view("brain") : plan_.current()));
  // A brain has no end of its own: the trial's end stops the samples.
  if ((brain_host_ && sar_ == nullptr) || Done() || (sar_ != nullptr && sar_->complete())) return Ok{};
  if (sar_ != nullptr) {
    return Error(ErrorCode::kUnavailable, "sensor samples stopped for " + Seconds(secs) +
                                              " s before the SAR mission was complete (" + sar_->mode() + ")");
  }
  return Error(ErrorCode::kUnavailable,
               "sensor samples stopped for " + Seconds(secs) + " s before the plan was complete (at '" +
                   std::string(plan_.current()) + "')");
}

}  // namespace swarmbox::agent
