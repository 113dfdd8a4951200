#include "agent_node.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include <opencv2/imgproc.hpp>

#include "brain_convert.hpp"
#include "external_brain.hpp"
#include "server_wait.hpp"
#include "swarmbox/bus/cyclone_config.hpp"
#include "swarmbox/bus/topics.hpp"
#include "swarmbox/brain/args.hpp"
#include "swarmbox/brain/loader.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/radio/channel_radio.hpp"
#include "swarmbox/radio/dds_radio.hpp"
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

}  // namespace

class AgentNode::FlightAdapter final : public FlightPort {
 public:
  explicit FlightAdapter(flight::FlightController& fc) : fc_(fc) {}
  bool Command(const flight::Setpoint& setpoint) override { return fc_.Command(setpoint); }
  void SetPayloadMass(double payload_mass_kg) override { fc_.SetPayloadMass(payload_mass_kg); }

 private:
  flight::FlightController& fc_;
};

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

Result<std::unique_ptr<AgentNode>> AgentNode::Create(const AgentOptions& o) {
  SWARMBOX_TRY(bus::ValidateDroneName(o.name));
  const bool channel = o.radio_model == RadioModel::kChannel;
  if (o.mesh && !channel && o.mesh_domain == o.sim_domain) {
    return Error(ErrorCode::kInvalidArgument,
                 "the sim and mesh buses need different DDS domain ids (both are " + std::to_string(o.sim_domain) + ")");
  }
  // The airframe file, parsed and validated once: the flight stack, the SAR brain and perception
  // all take what they need from this one model.
  auto af = airframe::LoadAirframe(o.airframe_path);
  if (!af) return af.error().Context("loading airframe");
  auto cfg = flight::FlightConfigFrom(*af);
  if (!cfg) return cfg.error().Context("loading airframe");
  // --mission sar: SarBrain's Context (what any brain is told) and the agent's perception,
  // checked before anything joins the bus.
  std::optional<SarBrainConfig> sar_config;
  PerceptionConfig perception;
  if (o.mission.kind == MissionKind::kSar) {
    if (o.raft.members.empty()) return Error(ErrorCode::kInvalidArgument, "--mission sar needs --members");
    if (!o.mesh) return Error(ErrorCode::kInvalidArgument, "--mission sar needs the mesh bus (drop --no-mesh)");
    brain::Context ctx;
    ctx.self = o.name;
    ctx.members = o.raft.members;
    ctx.seed = o.raft.seed;
    ctx.period_ns = std::llround(o.control_dt_s * 1e9);
    ctx.airframe = cfg->airframe;
    ctx.airframe_path = o.airframe_path;
    ctx.world_path = o.mission.world_path;
    ctx.payload = o.mission.payload;
    if (o.has_start) {
      char start[96];
      std::snprintf(start, sizeof start, "%.17g,%.17g,%.17g", o.start_m.x(), o.start_m.y(), o.start_m.z());
      ctx.args["start"] = start;
    }
    auto c = SarBrainConfigFrom(ctx, *af);
    if (!c) return c.error();
    sar_config = std::move(*c);
    perception.camera = sar_config->camera;
    perception.inference_latency_s = o.mission.inference_latency_ms * 1e-3;
  }
  const bool brain = o.brain.kind != BrainKind::kBuiltin;
  int period_steps = 1;
  if (brain) {
    auto steps = BrainPeriodSteps(o.brain, o.control_dt_s);
    if (!steps) return steps.error();
    period_steps = *steps;
    if (o.mission.kind != MissionKind::kPlan) {
      return Error(ErrorCode::kInvalidArgument, "--mission is for --brain builtin (the brain decides what to fly)");
    }
  }
  auto plan = FlightPlan::Parse(o.plan);  // --mission sar, a brain: parsed (the default) but not flown
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
  if (o.telemetry_hz < 0.0 || !std::isfinite(o.telemetry_hz)) {
    return Error(ErrorCode::kInvalidArgument, "--telemetry-hz must be >= 0");
  }
  if (o.telemetry_hz > 0.0) {
    // Every line printed on the log (the node's, Raft's, the brain host's) also goes to the
    // telemetry's event queue: the log's bytes stay as they were.
    AgentNode* n = node.get();
    auto tee = LogTee::Create(o.log, [n](std::string_view line) { n->telemetry_events_.Push(line); });
    if (!tee) return tee.error().Context("the telemetry's log tee");
    node->log_tee_ = std::move(*tee);
    node->options_.log = node->log_tee_->file();
    node->telemetry_clock_ = TelemetryClock(o.telemetry_hz);
  }
  std::FILE* const log_out = node->options_.log;  // the tee's stream with telemetry

  // No writer lingers at exit (Cyclone's default keeps an unacknowledged one up to 1 s, ~0.2 s per
  // agent): what it sent last (the last actuator command, Raft messages the protocol resends,
  // state, detections) is of no use once the agent goes. This is for the exits that delete the
  // participants (plan complete, samples stopped, errors); a SIGTERM stop skips the deletion
  // altogether (main.cpp, LeaveNow).
  constexpr int kNoLinger = 0;
  std::vector<std::string> peers;
  for (const std::string& host : o.sim_peers) {
    peers.push_back(host + ":" + std::to_string(bus::CycloneDiscoveryPort(o.sim_domain, 0)));
  }
  auto sim = bus::Participant::Create({.backend = o.middleware,
                                       .domain_id = o.sim_domain,
                                       .interface = o.sim_interface,
                                       .writer_linger_ms = kNoLinger,
                                       .peers = std::move(peers)});
  if (!sim) return sim.error().Context("joining the sim bus");
  node->sim_ = std::move(*sim);
  auto sub = node->sim_->CreateSubscriber<bus::SensorSample>(bus::SensorTopic(o.name), bus::Qos::kLockstep);
  if (!sub) return sub.error().Context("subscribing to sensor samples");
  node->sensor_sub_ = std::move(*sub);
  // The physics server's start (sim/status): while it comes, the first sample is waited for.
  auto status = node->sim_->CreateSubscriber<bus::Event>(bus::kSimStatusTopic, bus::Qos::kLockstep);
  if (!status) return status.error().Context("subscribing to the physics server's status");
  node->status_sub_ = std::move(*status);
  // Every agent writes the one keyed topic sim/actuator (cmd_.drone is the key); the server reads it
  // with one reader.
  auto pub = node->sim_->CreatePublisher<bus::ActuatorCommand>(bus::kActuatorTopic, bus::Qos::kLockstep);
  if (!pub) return pub.error().Context("publishing actuator commands");
  node->actuator_pub_ = std::move(*pub);
  if (node->telemetry_clock_.enabled()) {
    // Keyed by drone like sim/actuator: the physics server's recorder reads it with one reader.
    auto tpub = node->sim_->CreatePublisher<bus::Telemetry>(bus::kTelemetryTopic, bus::Qos::kState);
    if (!tpub) return tpub.error().Context("publishing telemetry");
    node->telemetry_pub_ = std::move(*tpub);
  }
  const bool sar = o.mission.kind == MissionKind::kSar;
  std::unique_ptr<brain::Brain> the_brain;
  if (brain) {
    auto made = node->MakeBrain(*cfg, period_steps);
    if (!made) return made.error();
    the_brain = std::move(*made);
    // Its own replicated state, made once before Raft starts (Raft replays its WAL into it).
    node->brain_state_ = the_brain->MakeReplicatedState();
  } else if (sar_config) {
    // The builtin SAR brain, through BrainHost as any brain; its replicated state is the mission.
    AgentNode* n = node.get();
    auto log = [n](const brain::Event& e) {
      LogEvent line(n->t_s_, n->options_.name, e.name);
      for (const auto& [k, v] : e.fields) line.Add(k, v);
      n->Log(line);
    };
    auto made = SarBrain::Create(*sar_config, log, channel ? nullptr : &node->netem_wall_);
    if (!made) return made.error();
    node->sar_ = made->get();
    auto state = node->sar_->MakeMissionState();
    node->sar_state_ = state.get();
    node->brain_state_ = std::move(state);
    the_brain = std::move(*made);
  }
  if (o.mesh && channel) {
    // No mesh domain at all: every frame rides the lockstep to the physics server's channel.
    node->radio_ = std::make_unique<radio::ChannelRadio>(o.name);
  } else if (o.mesh) {
    auto mesh = bus::Participant::Create({.backend = o.middleware,
                                          .domain_id = o.mesh_domain,
                                          .interface = o.mesh_interface,
                                          .writer_linger_ms = kNoLinger});
    if (!mesh) return mesh.error().Context("joining the mesh bus");
    node->mesh_ = std::move(*mesh);
    radio::DdsRadioOptions ro;
    ro.members = o.raft.members;
    ro.raft = o.raft.members.size() > 1;
    ro.pings = o.ping_every_ms > 0 && o.raft.members.size() > 1;
    ro.hear_states = sar || brain;
    ro.brains = brain;
    auto dds = radio::DdsRadio::Create(*node->mesh_, o.name, ro);
    if (!dds) return dds.error().Context("starting the mesh radio");
    node->radio_ = std::move(*dds);
  }
  if (!o.raft.members.empty()) {
    if (!o.mesh) return Error(ErrorCode::kInvalidArgument, "--members (Raft) needs the mesh bus (drop --no-mesh)");
    RaftHostOptions ro = o.raft;
    ro.self = o.name;
    ro.election_timeout_ms = ElectionTimeoutMsFor(o.mission, o.raft.election_timeout_ms);
    // Raft's clock: simulated seconds (channel: the radio's clock is the lockstep's, from 0), or
    // wall seconds since now (netem: the steady clock). Its lines carry the simulated time.
    node->raft_clock_ = std::make_unique<RadioClock>(*node->radio_, channel ? 0 : node->radio_->now_ns());
    std::unique_ptr<raft::StateMachine> machine;  // null: the SAR mission's
    if (node->sar_state_ != nullptr) {
      // SarBrain's state is raft's MissionStateMachine: Raft applies it with its own event lines.
      machine = node->sar_state_->RaftMachine();
    } else if (brain && node->brain_state_) {
      machine = std::make_unique<ReplicatedStateMachine>(node->brain_state_.get());
    } else if (brain) {
      machine = std::make_unique<raft::EntryLogMachine>();
    }
    auto raft = RaftHost::Start(ro, *node->radio_, *node->raft_clock_, log_out, &node->sim_clock_, std::move(machine));
    if (!raft) return raft.error();
    node->raft_ = std::move(*raft);
  }
  if (o.ping_every_ms < 0) return Error(ErrorCode::kInvalidArgument, "--ping-every-ms must be >= 0");
  if (o.ping_peers <= 0) return Error(ErrorCode::kInvalidArgument, "--ping-peers must be > 0");
  if (node->radio_ && o.ping_every_ms > 0 && o.raft.members.size() > 1) {
    radio::LinkProbeOptions po;
    po.ping_every = std::chrono::milliseconds(o.ping_every_ms);
    po.ping_peers = o.ping_peers;
    auto probe = radio::LinkProbe::Create(o.name, o.raft.members, po, radio::RadioTime(node->radio_->now_ns()));
    if (!probe) return probe.error().Context("starting the link probe");
    node->probe_ = std::move(*probe);
  }
  if (brain || node->sar_ != nullptr) {
    BrainHostOptions bo;
    bo.self = o.name;
    bo.period_steps = period_steps;
    bo.offboard_timeout_s = o.brain.offboard_timeout_ms * 1e-3;
    bo.offboard_hold_s = o.brain.offboard_hold_ms * 1e-3;
    bo.state = node->brain_state_.get();
    bo.neighbours.max_listed = static_cast<std::size_t>(std::max(1, o.brain.neighbours));
    node->flight_port_ = std::make_unique<FlightAdapter>(node->fc_);
    if (node->raft_) node->consensus_ = std::make_unique<RaftConsensus>(*node->raft_);
    node->brain_host_ = std::make_unique<BrainHost>(bo, std::move(the_brain), *node->flight_port_, node->radio_.get(),
                                                    node->consensus_.get(), log_out);
    if (auto spec = swarm::BatterySpecFor(cfg->airframe)) node->battery_.emplace(*spec);
  }
  // Perception runs beside the brain on a scout of the SAR mission and, for any other brain, on
  // an airframe with a camera: its detections are Input::detections. (The physics server renders
  // frames only when the trial asks for cameras; without frames nothing is detected.)
  bool perceive = node->sar_ != nullptr && node->sar_->role() == swarm::Role::kScout;
  if (brain) {
    if (af->has_camera) {
      perception.camera = af->camera;
      perception.inference_latency_s = o.mission.inference_latency_ms * 1e-3;
      perceive = true;
    }
  }
  if (perceive) {
    auto p = PerceptionHost::Create(perception);
    if (!p) return p.error();
    node->perception_ = std::move(*p);
    auto cam = node->sim_->CreateSubscriber<bus::CameraImage>(bus::CameraTopic(o.name), bus::Qos::kLockstep);
    if (!cam) return cam.error().Context("subscribing to the camera");
    node->camera_sub_ = std::move(*cam);
  }
  return node;
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

Result<std::unique_ptr<brain::Brain>> AgentNode::MakeBrain(const flight::FlightConfig& config, int period_steps) {
  const BrainOptions& b = options_.brain;
  brain::Context ctx;
  ctx.self = options_.name;
  ctx.members = options_.raft.members.empty() ? std::vector<std::string>{options_.name} : options_.raft.members;
  ctx.seed = options_.raft.seed;
  ctx.period_ns = static_cast<std::int64_t>(std::llround(period_steps * options_.control_dt_s * 1e9));
  ctx.airframe = config.airframe;
  ctx.airframe_path = options_.airframe_path;
  ctx.world_path = options_.mission.world_path;
  ctx.payload = options_.mission.payload;
  auto args = brain::ParseBrainArgs(b.args_json);
  if (!args) return args.error();
  ctx.args = std::move(*args);
  ctx.log = [this](const brain::Event& e) {
    LogEvent line(t_s_, options_.name, e.name);
    for (const auto& [k, v] : e.fields) line.Add(k, v);
    Log(line);
  };
  LogEvent loaded(0.0, options_.name, "brain_loaded");
  loaded.Add("kind", BrainKindName(b.kind));
  std::unique_ptr<brain::Brain> made;
  if (b.kind == BrainKind::kLibrary) {
    auto lib = brain::LoadBrain(b.library_path, b.name, ctx);
    if (!lib) return lib.error().Context("--brain library");
    loaded.Add("name", b.name).Add("library", b.library_path);
    made = std::move(*lib);
  } else {
    ExternalBrainOptions eo;
    eo.drone = options_.name;
    eo.wait = std::chrono::milliseconds(b.wait_ms);
    eo.start = std::chrono::milliseconds(b.start_ms);
    eo.stop = options_.stop;
    eo.log = options_.log;
    auto ext = ExternalBrain::Create(*sim_, eo);
    if (!ext) return ext.error().Context("--brain external");
    loaded.Add("name", bus::OffboardInputTopic(options_.name));
    made = std::move(*ext);
  }
  loaded.Add("period_ms", static_cast<double>(ctx.period_ns) * 1e-6, 1)
      .Add("offboard_timeout_ms", b.offboard_timeout_ms)
      .Add("offboard_hold_ms", b.offboard_hold_ms);
  Log(loaded);
  return made;
}

bool AgentNode::TakeCamera(const bus::SensorSample& msg) {
  image_count_ = 0;
  if (!camera_sub_) return true;
  bool have_step = false;
  auto take = [&](bool wait, std::chrono::milliseconds slice) {
    if (image_count_ == images_.size()) images_.emplace_back();
    bus::CameraImage& img = images_[image_count_];
    const bool took = wait ? camera_sub_->TakeFor(img, slice) : camera_sub_->Take(img);
    if (!took) return false;
    ++image_count_;
    have_step = have_step || img.sim_time_ns == msg.sim_time_ns;
    return true;
  };
  while (take(false, {})) {
  }
  // The physics server publishes a step's frame before its sample; DDS may still hand the sample
  // over first (two readers). Wait for it: what the camera saw at t_k is part of step k.
  if (!msg.camera_frame || have_step) return true;
  WaitBudget budget(options_.camera_timeout);  // waiting time, as Run()'s
  while (!have_step) {
    if (options_.stop != nullptr && *options_.stop != 0) return false;
    if (budget.spent()) {
      // Past the liveness bound: look once more, then go on without it.
      while (!have_step && take(false, {})) {
      }
      if (!have_step) {
        Log(LogEvent(t_s_, options_.name, "camera_missing")
                .Add("step", static_cast<std::int64_t>(msg.step))
                .Add("after_wall_s", std::chrono::duration<double>(options_.camera_timeout).count(), 1));
      }
      return true;
    }
    const auto slice = budget.Slice(std::chrono::milliseconds(50));
    const auto start = std::chrono::steady_clock::now();
    (void)take(true, slice);
    budget.Spend(std::chrono::steady_clock::now() - start, slice);
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

Status AgentNode::ServeRadioBetweenSteps() {
  frames_.clear();
  radio_->TakeReceived(bus::SensorSample{}, &frames_);  // netem: the sample is not looked at
  if (probe_) {
    for (const bus::RadioFrame& f : frames_) probe_->Heard(f);  // the ping sampling's order
  }
  DispatchFrames(frames_, options_.name, *this, &dispatched_);
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
  using flight::FlightEventKind;
  t_s_ = static_cast<double>(msg.sim_time_ns) * 1e-9;
  sim_clock_.Set(t_s_);
  // a. The camera frame of this step.
  if (!TakeCamera(msg)) return Ok{};  // stop requested: Run() logs it
  cmd_.world.clear();
  // b. What the radio delivered for this step, in delivery order.
  frames_.clear();
  if (radio_) {
    radio_->TakeReceived(msg, &frames_);
    if (probe_) {
      for (const bus::RadioFrame& f : frames_) probe_->Heard(f);  // the ping sampling's order
    }
    DispatchFrames(frames_, options_.name, *this, &dispatched_);
  }
  // c. Flight, Raft, the link probe, the mission or plan, the state broadcast.
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
  if (Status s = StepRaftAndProbe(); !s) return s;
  if (sar_ != nullptr) {
    StepMission(msg);
  } else if (brain_host_) {
    StepBrain(msg);
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
  if (brain_host_ && t_s_ >= next_battery_log_s_) {
    // The battery once per simulated second, for the trial's plots (SarBrain: its own model, as
    // BroadcastState sends it).
    next_battery_log_s_ = std::floor(t_s_) + 1.0;
    Log(LogEvent(t_s_, options_.name, "battery")
            .Add("fraction", sar_ != nullptr ? sar_->battery_fraction() : vehicle_.battery_fraction, 4));
  }
  BroadcastState(msg);
  // d. The step's answer: motors, world commands, Raft leadership, the radio's frames.
  if (radio_) {
    radio_->Flush(&cmd_);
  } else {
    cmd_.radio_out.clear();
  }
  cmd_.raft_leader = raft_ && raft_->service().is_leader();
  if (Status s = actuator_pub_->Publish(cmd_); !s) {
    Log(LogEvent(t_s_, options_.name, "bus_error").Add("what", "actuator").Add("reason", s.error().ToString()));
  }
  if (telemetry_pub_ && telemetry_clock_.Due(msg.sim_time_ns)) PublishTelemetry(msg);
  return Ok{};
}

void AgentNode::PublishTelemetry(const bus::SensorSample& msg) {
  constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
  bus::Telemetry& t = telemetry_;
  t.sim_time_ns = msg.sim_time_ns;
  const flight::StateEstimate& est = fc_.estimate();
  t.position_enu_m = {est.pos_m.x(), est.pos_m.y(), est.pos_m.z()};
  t.velocity_enu_m_s = {est.vel_m_s.x(), est.vel_m_s.y(), est.vel_m_s.z()};
  t.attitude_wxyz = {est.att.w(), est.att.x(), est.att.y(), est.att.z()};
  const flight::FlightMode mode = fc_.mode();
  t.flight_mode = std::string(flight::FlightModeName(mode));
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
  // Flocking (SarBrain): V18's horizontal terms; separation = repulsion, alignment = Reynolds'
  // alignment + V18 friction, cohesion, and their sum.
  const swarm::FlockingOutput* f = sar_ != nullptr ? sar_->flocking() : nullptr;
  if (f != nullptr) {
    const swarm::Vec2 align = f->alignment + f->friction;
    const swarm::Vec2 sum = f->repulsion + align + f->cohesion;
    t.flock_separation = {f->repulsion.x(), f->repulsion.y(), 0.0};
    t.flock_alignment = {align.x(), align.y(), 0.0};
    t.flock_cohesion = {f->cohesion.x(), f->cohesion.y(), 0.0};
    t.flock_sum = {sum.x(), sum.y(), 0.0};
  } else {
    t.flock_separation = t.flock_alignment = t.flock_cohesion = t.flock_sum = {kNaN, kNaN, kNaN};
  }
  t.sectors.clear();
  if (raft_) {
    const raft_service::RaftService& r = raft_->service();
    t.raft_role = r.is_learner() ? "learner" : std::string(raft::RoleName(r.role()));
    t.raft_term = r.term();
    t.raft_leader = r.leader();
    t.raft_commit_index = r.commit_index();
    // The leader's committed plan, on a change and every simulated second.
    // SarBrain's mission state is Raft's machine behind a reference (FindMission does not see through it).
    const raft::MissionState* mission = nullptr;
    if (r.is_leader()) mission = sar_state_ != nullptr ? &sar_state_->mission() : raft_->FindMission();
    if (mission != nullptr) {
      SectorsOf(mission->sectors(), &sectors_scratch_);
      if (t_s_ - sectors_sent_s_ >= 1.0 || sectors_scratch_ != sectors_sent_) {
        sectors_sent_s_ = t_s_;
        sectors_sent_ = sectors_scratch_;
        t.sectors = sectors_scratch_;
      }
    }
  } else {
    t.raft_role.clear();
    t.raft_term = 0;
    t.raft_leader.clear();
    t.raft_commit_index = 0;
  }
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

void AgentNode::StepMission(const bus::SensorSample& msg) {
  // Perception (scouts): this step's frames geolocated with the estimate of their capture step,
  // to the brain once the inference latency has passed.
  detections_.clear();
  if (perception_) {
    perception_->RecordEstimate(t_s_, fc_.estimate());
    for (std::size_t i = 0; i < image_count_; ++i) {
      bus::CameraImage& image = images_[i];
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

bool AgentNode::Done() const {
  if (sar_ != nullptr) {
    return sar_->complete() && (fc_.mode() == flight::FlightMode::kLanded || fc_.mode() == flight::FlightMode::kIdle);
  }
  if (brain_host_) return false;  // a brain flies until the trial ends (the samples stop)
  return plan_.finished();
}

Status AgentNode::Run() {
  Log(LogEvent(0.0, options_.name, "ready")
          .Add("sim_domain", options_.sim_domain)
          .Add("sim_interface", options_.sim_interface)
          .Add("middleware", options_.middleware)
          .Add("radio_model", RadioModelName(options_.radio_model))
          .Add("brain", BrainKindName(options_.brain.kind))
          .Add("mission", brain_host_ && sar_ == nullptr ? std::string_view("-") : MissionKindName(options_.mission.kind))
          .Add("plan", brain_host_ ? std::string("-") : options_.plan)
          .Add("raft", raft_ ? options_.raft.raft_dir : std::string("off")));
  bus::SensorSample msg;
  bus::Event status;
  bool got_any = false;
  while (true) {
    const auto timeout = got_any ? options_.stall_timeout : options_.first_sample_timeout;
    // Wait in slices so a stop request is seen while no sample comes. The timeout counts the time
    // spent waiting, each slice at most its own length: a process stopped (SIGSTOP, docker pause)
    // or starved in the middle of a slice does not find its deadline gone when it resumes.
    // Before the first sample the wait is for a sign of the server (server_wait.hpp): each
    // sim/status message of its start starts it afresh.
    WaitBudget budget(timeout);
    ServerWait server(options_.first_sample_timeout, options_.name);
    auto spent = [&] { return got_any ? budget.spent() : server.spent(); };
    bool took = false;
    while (true) {
      if (options_.stop != nullptr && *options_.stop != 0) {
        Log(LogEvent(t_s_, options_.name, "stopped").Add("reason", "signal"));
        return Ok{};
      }
      if (spent()) {
        // Look at the topic once more before giving up (a sample may have come in the last slice).
        took = sensor_sub_->Take(msg);
        break;
      }
      // netem: the mesh lives on the wall clock whether or not the lockstep moves (a drone the
      // physics server is waiting for, a stalled server): Raft and the probe go on between
      // samples, every 10 ms without one.
      const bool idle_radio = options_.radio_model == RadioModel::kNetem && radio_ && (raft_ || probe_);
      const auto max_slice = idle_radio ? std::chrono::milliseconds(10) : std::chrono::milliseconds(50);
      const auto slice = got_any ? budget.Slice(max_slice) : server.Slice(max_slice);
      const auto start = std::chrono::steady_clock::now();
      if (sensor_sub_->TakeFor(msg, slice)) {
        took = true;
        break;
      }
      if (got_any) {
        budget.Spend(std::chrono::steady_clock::now() - start, slice);
      } else {
        server.Spend(std::chrono::steady_clock::now() - start, slice);
        while (status_sub_->Take(status)) server.OnStatus(status);
      }
      if (idle_radio) SWARMBOX_TRY(ServeRadioBetweenSteps());
    }
    if (!took) {
      const double secs = std::chrono::duration<double>(timeout).count();
      if (!got_any) {
        return Error(ErrorCode::kUnavailable,
                     "no sensor sample on " + bus::SensorTopic(options_.name) + " " + server.Reason() +
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

}  // namespace swarmbox::agent
