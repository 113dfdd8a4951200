#include "agent_node.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "swarmbox/common/logfmt.hpp"

namespace swarmbox::agent {
namespace {

flight::Vec3 V(const std::array<double, 3>& a) { return flight::Vec3(a[0], a[1], a[2]); }

std::string Seconds(double s) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", s);
  return buf;
}

}  // namespace

flight::SensorSample FromBus(const bus::SensorSample& m) {
  flight::SensorSample s;
  s.t_s = static_cast<double>(m.sim_time_ns) * 1e-9;
  s.imu_fresh = m.imu.valid;
  s.accel_mps2 = V(m.imu.accel_m_s2);
  s.gyro_radps = V(m.imu.gyro_rad_s);
  s.baro_fresh = m.baro.valid;
  s.baro_alt_m = m.baro.altitude_m;
  s.mag_fresh = m.mag.valid;
  s.mag_body = V(m.mag.field_gauss);
  // The bus marks a GPS sample valid only when it is a new fix; a dropout sends no valid fixes.
  s.gps_fresh = m.gps.valid;
  s.gps_valid = m.gps.valid && m.gps.fix_type == bus::GpsFix::k3d;
  s.gps_pos_m = V(m.gps.position_enu_m);
  s.gps_vel_mps = V(m.gps.velocity_enu_m_s);
  s.gps_eph_m = m.gps.h_acc_m;  // the receiver's reported accuracy: how much the estimator trusts it
  s.gps_epv_m = m.gps.v_acc_m;
  return s;
}

Result<std::unique_ptr<AgentNode>> AgentNode::Create(const AgentOptions& o) {
  SWARMBOX_TRY(bus::ValidateDroneName(o.name));
  if (o.mesh && o.mesh_domain == o.sim_domain) {
    return Error(ErrorCode::kInvalidArgument,
                 "the sim and mesh buses need different DDS domain ids (both are " + std::to_string(o.sim_domain) + ")");
  }
  auto cfg = flight::LoadFlightConfig(o.airframe_path);
  if (!cfg) return cfg.error().Context("loading airframe");
  MissionHostConfig mc;
  if (o.mission.kind == MissionKind::kSar) {
    if (o.raft.members.empty()) return Error(ErrorCode::kInvalidArgument, "--mission sar needs --members");
    if (!o.mesh) return Error(ErrorCode::kInvalidArgument, "--mission sar needs the mesh bus (drop --no-mesh)");
    auto world = LoadWorldView(o.mission.world_path);
    if (!world) return world.error();
    auto camera = LoadCameraSpec(o.airframe_path);
    if (!camera) return camera.error().Context("loading the airframe's camera");
    mc.name = o.name;
    mc.members = o.raft.members;
    mc.airframe = cfg->airframe;
    mc.payload = o.mission.payload;
    mc.base_height_m = cfg->base_height_m;
    mc.vehicle_mass_kg = cfg->mass_kg;
    mc.has_home = o.has_start;
    mc.home_m = o.start_m;
    mc.geofence_size_x_m = world->size_x_m;
    mc.geofence_size_y_m = world->size_y_m;
    mc.camera = *camera;
    mc.inference_latency_s = o.mission.inference_latency_ms * 1e-3;
    if (!o.mission.payload.empty()) {
      auto it = std::find_if(cfg->payloads.begin(), cfg->payloads.end(),
                             [&](const flight::SlungPayload& p) { return p.name == o.mission.payload; });
      if (it == cfg->payloads.end()) {
        std::string known;
        for (const flight::SlungPayload& p : cfg->payloads) known += (known.empty() ? "" : ", ") + p.name;
        return Error(ErrorCode::kInvalidArgument, "--payload '" + o.mission.payload + "': airframe " + cfg->airframe +
                                                      " has " + (known.empty() ? std::string("no payloads") : "payloads " + known));
      }
      mc.payload_sling_length_m = it->sling_length_m;
      mc.payload_hook_m = it->hook_m;
      auto ground = LoadGroundPayload(o.airframe_path, o.mission.payload);
      if (!ground) return ground.error().Context("--payload");
      mc.payload_offset_m = ground->offset_m;
      mc.payload_half_height_m = ground->half_height_m;
    }
  }
  auto plan = FlightPlan::Parse(o.plan);  // --mission sar: parsed (the default) but not flown
  if (!plan) return plan.error().Context("--plan");
  plan->SetPreflight(o.preflight_s);
  flight::ControllerOptions co;
  co.control_dt_s = o.control_dt_s;
  co.payload_mass_kg = o.payload_mass_kg;
  co.swing_damping = o.swing_damping;
  if (o.has_start) {
    co.has_start_pos = true;
    co.start_pos_m = o.start_m + flight::Vec3(0.0, 0.0, cfg->base_height_m);
  }
  auto fc = flight::FlightController::Create(*cfg, co);
  if (!fc) return fc.error();
  std::unique_ptr<AgentNode> node(new AgentNode(o, std::move(*fc), std::move(*plan)));

  // No writer lingers at exit (Cyclone's default keeps an unacknowledged one up to 1 s, ~0.2 s per
  // agent): what it sent last (the last actuator command, Raft messages the protocol resends,
  // state, detections) is of no use once the agent goes. This is for the exits that delete the
  // participants (plan complete, samples stopped, errors); a SIGTERM stop skips the deletion
  // altogether (main.cpp, LeaveNow).
  constexpr int kNoLinger = 0;
  auto sim = bus::Participant::Create(
      {.backend = o.middleware, .domain_id = o.sim_domain, .interface = o.sim_interface, .writer_linger_ms = kNoLinger});
  if (!sim) return sim.error().Context("joining the sim bus");
  node->sim_ = std::move(*sim);
  auto sub = node->sim_->CreateSubscriber<bus::SensorSample>(bus::SensorTopic(o.name), bus::Qos::kLockstep);
  if (!sub) return sub.error().Context("subscribing to sensor samples");
  node->sensor_sub_ = std::move(*sub);
  auto pub = node->sim_->CreatePublisher<bus::ActuatorCommand>(bus::ActuatorTopic(o.name), bus::Qos::kLockstep);
  if (!pub) return pub.error().Context("publishing actuator commands");
  node->actuator_pub_ = std::move(*pub);
  if (o.mesh) {
    auto mesh = bus::Participant::Create({.backend = o.middleware,
                                          .domain_id = o.mesh_domain,
                                          .interface = o.mesh_interface,
                                          .writer_linger_ms = kNoLinger});
    if (!mesh) return mesh.error().Context("joining the mesh bus");
    node->mesh_ = std::move(*mesh);
    auto sp = node->mesh_->CreatePublisher<bus::DroneState>(bus::kDroneStateTopic, bus::Qos::kState);
    if (!sp) return sp.error().Context("publishing drone state");
    node->state_pub_ = std::move(*sp);
  }
  if (!o.raft.members.empty()) {
    if (!o.mesh) return Error(ErrorCode::kInvalidArgument, "--members (Raft) needs the mesh bus (drop --no-mesh)");
    RaftHostOptions ro = o.raft;
    ro.self = o.name;
    ro.election_timeout_ms = ElectionTimeoutMsFor(o.mission, o.raft.election_timeout_ms);
    auto raft = RaftHost::Start(ro, *node->mesh_, o.log);
    if (!raft) return raft.error();
    node->raft_ = std::move(*raft);
  }
  if (o.ping_every_ms < 0) return Error(ErrorCode::kInvalidArgument, "--ping-every-ms must be >= 0");
  if (o.mesh && o.ping_every_ms > 0 && o.raft.members.size() > 1) {
    radio::RadioLinkOptions ro;
    ro.ping_every = std::chrono::milliseconds(o.ping_every_ms);
    auto link = radio::RadioLink::Create(*node->mesh_, o.name, o.raft.members, ro);
    if (!link) return link.error().Context("starting the radio link");
    node->radio_ = std::move(*link);
  }
  if (o.mission.kind == MissionKind::kSar) {
    auto host = MissionHost::Create(mc);
    if (!host) return host.error();
    node->mission_ = std::move(*host);
    if (node->mission_->role() == swarm::Role::kScout) {
      auto cam = node->sim_->CreateSubscriber<bus::CameraImage>(bus::CameraTopic(o.name), bus::Qos::kLockstep);
      if (!cam) return cam.error().Context("subscribing to the camera");
      node->camera_sub_ = std::move(*cam);
    }
    auto wc = node->sim_->CreatePublisher<bus::WorldCommand>(bus::kWorldCommandTopic, bus::Qos::kLockstep);
    if (!wc) return wc.error().Context("publishing world commands");
    node->world_pub_ = std::move(*wc);
    auto det = node->mesh_->CreatePublisher<bus::Detection>(bus::kDetectionTopic, bus::Qos::kRadio);
    if (!det) return det.error().Context("publishing detections");
    node->detection_pub_ = std::move(*det);
    auto peers = node->mesh_->CreateSubscriber<bus::DroneState>(bus::kDroneStateTopic, bus::Qos::kState);
    if (!peers) return peers.error().Context("subscribing to drone states");
    node->peers_sub_ = std::move(*peers);
  }
  return node;
}

AgentNode::AgentNode(AgentOptions options, flight::FlightController fc, FlightPlan plan)
    : options_(std::move(options)), fc_(std::move(fc)), plan_(std::move(plan)) {
  cmd_.drone = options_.name;
  cmd_.motor_throttle.assign(fc_.mixer().rotor_count(), 0.0);
  state_.drone = options_.name;
}

void AgentNode::Log(const LogEvent& e) {
  std::fprintf(options_.log, "%s\n", e.str().c_str());
  std::fflush(options_.log);
}

void AgentNode::HandleSample(const bus::SensorSample& msg) {
  using flight::FlightEventKind;
  t_s_ = static_cast<double>(msg.sim_time_ns) * 1e-9;
  if (raft_) raft_->SetSimTime(t_s_);
  const flight::ActuatorOutput& out = fc_.Step(FromBus(msg));
  cmd_.step = msg.step;
  cmd_.sim_time_ns = msg.sim_time_ns;
  cmd_.armed = out.armed;
  for (std::size_t i = 0; i < cmd_.motor_throttle.size(); ++i) cmd_.motor_throttle[i] = out.armed ? out.u[i] : 0.0;
  if (Status s = actuator_pub_->Publish(cmd_); !s) {
    Log(LogEvent(t_s_, options_.name, "bus_error").Add("what", "actuator").Add("reason", s.error().ToString()));
  }

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
    LogEvent le(e.t_s, options_.name, flight::FlightEventName(e.kind));
    if (e.kind == FlightEventKind::kModeChange) le.Add("mode", flight::FlightModeName(e.mode));
    le.Add("x", e.pos_m.x(), 2).Add("y", e.pos_m.y(), 2).Add("z", e.pos_m.z(), 2);
    Log(le);
  }
  if (radio_) {
    for (const LogEvent& line : radio_->Poll(std::chrono::steady_clock::now(), t_s_)) Log(line);
  }
  if (mission_) {
    StepMission(msg, st.hover);
  } else {
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
  // Our state for the neighbours, 5 Hz of simulated time.
  if (state_pub_ && t_s_ >= next_state_s_) {
    next_state_s_ = t_s_ + 0.2;
    const flight::StateEstimate& est = fc_.estimate();
    ++state_.seq;
    state_.sim_time_ns = msg.sim_time_ns;
    state_.wall_time_ns = std::chrono::duration_cast<std::chrono::nanoseconds>(
                              std::chrono::system_clock::now().time_since_epoch()).count();
    state_.position_enu_m = {est.pos_m.x(), est.pos_m.y(), est.pos_m.z()};
    state_.velocity_enu_m_s = {est.vel_mps.x(), est.vel_mps.y(), est.vel_mps.z()};
    state_.heading_rad = flight::YawOf(est.att);
    if (mission_) {
      state_.mode = mission_->mode();
      state_.battery_fraction = mission_->battery_fraction();
    } else {
      state_.mode = std::string(flight::FlightModeName(fc_.mode()));
    }
    (void)state_pub_->Publish(state_);
  }
}

void AgentNode::StepMission(const bus::SensorSample& msg, bool hover_event) {
  const flight::StateEstimate& est = fc_.estimate();
  mission_->RecordEstimate(t_s_, est);
  // Wall times for the leader's lost-member rule (at rtf 0 a radio delay is many simulated s).
  const auto wall_s = [] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
  };
  while (peers_sub_->Take(peer_)) {
    PeerState p;
    p.name = peer_.drone;
    p.mode = peer_.mode;
    p.position_m = V(peer_.position_enu_m);
    p.velocity_m_s = V(peer_.velocity_enu_m_s);
    p.sim_time_s = static_cast<double>(peer_.sim_time_ns) * 1e-9;
    p.received_wall_s = wall_s();
    mission_->OnPeerState(p);
  }
  if (camera_sub_) {
    while (camera_sub_->Take(image_)) {
      if (image_.encoding != "bgr8" && image_.encoding != "rgb8") continue;  // the detector needs colour
      if (image_.data.size() < static_cast<std::size_t>(image_.height_px) * image_.row_stride_bytes) continue;
      cv::Mat bgr(static_cast<int>(image_.height_px), static_cast<int>(image_.width_px), CV_8UC3, image_.data.data(),
                  image_.row_stride_bytes);
      if (image_.encoding == "rgb8") cv::cvtColor(bgr, bgr, cv::COLOR_RGB2BGR);
      const bus::CameraIntrinsics& k = image_.intrinsics;
      mission_->OnCameraFrame(bgr, {k.fx_px, k.fy_px, k.cx_px, k.cy_px}, static_cast<double>(image_.sim_time_ns) * 1e-9);
    }
  }
  if (t_s_ >= next_committed_s_) {  // a copy of the committed state, 10 Hz of simulated time
    next_committed_s_ = t_s_ + 0.1;
    committed_ = raft_->service().mission();
    leader_ = raft_->service().is_leader();
  }
  MissionHostInput in;
  in.t_s = t_s_;
  in.wall_s = wall_s();
  in.dt_s = options_.control_dt_s;
  in.flight_mode = fc_.mode();
  in.estimate = &est;
  in.mission = &committed_;
  in.is_leader = leader_;
  in.hover_event = hover_event;
  in.mass_estimate_kg = fc_.telemetry().mass_estimate_kg;
  const MissionHostOutput& out = mission_->Step(in);
  for (const LogEvent& e : out.events) Log(e);
  if (out.command) (void)fc_.Command(*out.command);
  for (const raft::MissionCommand& c : out.proposals) {
    (void)raft_->service().Propose(c);  // kUnavailable (no leader yet): the behaviours re-propose
  }
  if (out.payload.action != swarm::PayloadAction::kNone) {
    ++world_cmd_.seq;
    world_cmd_.sim_time_ns = msg.sim_time_ns;
    world_cmd_.target = options_.name;
    world_cmd_.args.clear();
    if (out.payload.action == swarm::PayloadAction::kAttach) {
      world_cmd_.command = "payload_attach";
      world_cmd_.args.push_back(out.payload.mass_kg);
    } else {
      world_cmd_.command = "payload_release";
    }
    // The announced load as the hover thrust estimator's prior (it corrects a refused hook).
    fc_.SetPayloadMass(out.payload.action == swarm::PayloadAction::kAttach ? out.payload.mass_kg : 0.0);
    if (Status s = world_pub_->Publish(world_cmd_); !s) {
      Log(LogEvent(t_s_, options_.name, "bus_error").Add("what", "world_command").Add("reason", s.error().ToString()));
    }
  }
  for (const swarm::GroundDetection& d : out.detections) {
    ++detection_.seq;
    detection_.from = options_.name;
    detection_.sim_time_ns = static_cast<std::int64_t>(d.capture_time_s * 1e9);
    detection_.label = "victim";
    detection_.confidence = d.confidence;
    detection_.position_enu_m = {d.position_m.x(), d.position_m.y(), d.position_m.z()};
    detection_.position_sigma_m = d.sigma_m;
    (void)detection_pub_->Publish(detection_);  // best effort, as the radio
  }
}

bool AgentNode::Done() const {
  if (!mission_) return plan_.finished();
  return mission_->complete() && (fc_.mode() == flight::FlightMode::kLanded || fc_.mode() == flight::FlightMode::kIdle);
}

Status AgentNode::Run() {
  Log(LogEvent(0.0, options_.name, "ready")
          .Add("sim_domain", options_.sim_domain)
          .Add("sim_interface", options_.sim_interface)
          .Add("middleware", options_.middleware)
          .Add("mission", MissionKindName(options_.mission.kind))
          .Add("plan", mission_ ? std::string("-") : options_.plan)
          .Add("raft", raft_ ? options_.raft.raft_dir : std::string("off")));
  bus::SensorSample msg;
  bool got_any = false;
  while (true) {
    const auto timeout = got_any ? options_.stall_timeout : options_.first_sample_timeout;
    // Wait in slices so the Raft host is polled (storage failure, proposals) and a stop request
    // seen while no sample comes.
    const auto wait_until = std::chrono::steady_clock::now() + timeout;
    bool took = false;
    while (true) {
      if (options_.stop != nullptr && *options_.stop != 0) {
        Log(LogEvent(t_s_, options_.name, "stopped").Add("reason", "signal"));
        return Ok{};
      }
      if (raft_) {
        if (Status s = raft_->Poll(); !s) return s.error().Context("raft stopped");
      }
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(wait_until - std::chrono::steady_clock::now());
      if (left <= std::chrono::milliseconds(0)) break;
      const bool poll = raft_ || options_.stop != nullptr;
      const auto slice = poll ? std::min(left, std::chrono::milliseconds(50)) : left;
      if (sensor_sub_->TakeFor(msg, slice)) {
        took = true;
        break;
      }
    }
    if (!took) {
      const double secs = std::chrono::duration<double>(timeout).count();
      if (!got_any) {
        return Error(ErrorCode::kUnavailable,
                     "no sensor sample on " + bus::SensorTopic(options_.name) + " within " + Seconds(secs) +
                         " s: is swarmbox-physics running with this drone on " + options_.middleware + " domain " +
                         std::to_string(options_.sim_domain) + ", interface " + options_.sim_interface + "?");
      }
      Log(LogEvent(t_s_, options_.name, "samples_stopped").Add("after_s", secs, 1).Add("plan", mission_ ? std::string_view("sar") : plan_.current()));
      if (Done() || (mission_ && mission_->complete())) return Ok{};
      if (mission_) {
        return Error(ErrorCode::kUnavailable, "sensor samples stopped for " + Seconds(secs) +
                                                  " s before the SAR mission was complete (" + mission_->mode() + ")");
      }
      return Error(ErrorCode::kUnavailable,
                   "sensor samples stopped for " + Seconds(secs) + " s before the plan was complete (at '" +
                       std::string(plan_.current()) + "')");
    }
    if (have_step_ && msg.step == last_step_) {
      (void)actuator_pub_->Publish(cmd_);  // a resent sample: answer it again, do not step twice
      continue;
    }
    if (have_step_ && msg.step < last_step_) continue;  // stale
    got_any = true;
    have_step_ = true;
    last_step_ = msg.step;
    HandleSample(msg);
    if (options_.exit_when_done && Done()) return Ok{};
  }
}

}  // namespace swarmbox::agent
