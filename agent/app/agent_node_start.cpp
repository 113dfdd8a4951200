// AgentNode's start-up (agent_node.hpp): AgentNode::Create, one function per phase. The order of
// the phases is the order of their checks and of what they start: an error names the first thing
// wrong, and nothing joins the bus before the airframe, the mission and the brain's period are
// known to be good.
#include <algorithm>
#include <cmath>
#include <utility>

#include "agent_node.hpp"
#include "external_brain.hpp"
#include "swarmbox/airframe/airframe.hpp"
#include "swarmbox/brain/args.hpp"
#include "swarmbox/brain/loader.hpp"
#include "swarmbox/bus/cyclone_config.hpp"
#include "swarmbox/bus/topics.hpp"
#include "swarmbox/radio/channel_radio.hpp"
#include "swarmbox/radio/dds_radio.hpp"

namespace swarmbox::agent {

// What Create reads and checks before the node exists: the airframe model (parsed and validated
// once: the flight stack, the SAR brain and perception all take what they need from it), and what
// the brain and perception are made from.
struct AgentNode::Startup {
  airframe::Airframe airframe;
  flight::FlightConfig flight;
  std::optional<SarBrainConfig> sar{};  // --mission sar
  PerceptionConfig perception{};        // --mission sar: the SAR brain's camera
  bool brain = false;                 // --brain library|external
  int period_steps = 1;               // the brain's period [lockstep steps]
};

namespace {

// No writer lingers at exit (Cyclone's default keeps an unacknowledged one up to 1 s, ~0.2 s per
// agent): what it sent last (the last actuator command, Raft messages the protocol resends,
// state, detections) is of no use once the agent goes. This is for the exits that delete the
// participants (plan complete, samples stopped, errors); a SIGTERM stop skips the deletion
// altogether (main.cpp, LeaveNow).
constexpr int kNoLinger = 0;

// What every brain is told about its drone and trial (brain::Context), but for its args and log.
// Without members the drone is alone: the members are itself.
brain::Context BrainContextFor(const AgentOptions& o, const flight::FlightConfig& config, int period_steps) {
  brain::Context ctx;
  ctx.self = o.name;
  ctx.members = o.raft.members.empty() ? std::vector<std::string>{o.name} : o.raft.members;
  ctx.seed = o.raft.seed;
  ctx.period_ns = static_cast<std::int64_t>(std::llround(period_steps * o.control_dt_s * 1e9));
  ctx.airframe = config.airframe;
  ctx.airframe_path = o.airframe_path;
  ctx.world_path = o.mission.world_path;
  ctx.payload = o.mission.payload;
  return ctx;
}

// --mission sar: SarBrain's configuration from its Context (what any brain is told), checked
// before anything joins the bus. It steps every lockstep step.
Result<SarBrainConfig> SarConfigFor(const AgentOptions& o, const airframe::Airframe& af,
                                    const flight::FlightConfig& config) {
  if (o.raft.members.empty()) return Error(ErrorCode::kInvalidArgument, "--mission sar needs --members");
  if (!o.mesh) return Error(ErrorCode::kInvalidArgument, "--mission sar needs the mesh bus (drop --no-mesh)");
  brain::Context ctx = BrainContextFor(o, config, /*period_steps=*/1);
  // The trial's tuning first: its keys are tuning numbers only, never `start`.
  auto tuning = ParseMissionTuning(o.mission.tuning_json);
  if (!tuning) return tuning.error();
  ctx.args = std::move(*tuning);
  if (o.has_start) {
    char start[96];
    std::snprintf(start, sizeof start, "%.17g,%.17g,%.17g", o.start_m.x(), o.start_m.y(), o.start_m.z());
    ctx.args["start"] = start;
  }
  return SarBrainConfigFrom(ctx, af);
}

flight::ControllerOptions ControllerOptionsFor(const AgentOptions& o, const flight::FlightConfig& config) {
  flight::ControllerOptions co;
  co.control_dt_s = o.control_dt_s;
  co.payload_mass_kg = o.payload_mass_kg;
  co.swing_damping = o.swing_damping;
  if (o.has_start) {
    co.has_start_pos = true;
    co.start_pos_m = o.start_m + flight::Vec3(0.0, 0.0, config.base_height_m);
  }
  return co;
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

Result<std::unique_ptr<AgentNode>> AgentNode::Create(const AgentOptions& o) {
  auto startup = LoadStartup(o);
  if (!startup) return startup.error();
  auto made = MakeNode(o, startup->flight);
  if (!made) return made.error();
  std::unique_ptr<AgentNode> node = std::move(*made);
  SWARMBOX_TRY(node->StartTelemetry());
  SWARMBOX_TRY(node->JoinSimBus());
  auto brain = node->MakeFlyingBrain(*startup);
  if (!brain) return brain.error();
  SWARMBOX_TRY(node->StartRadio(startup->brain));
  SWARMBOX_TRY(node->StartRaft(startup->brain));
  SWARMBOX_TRY(node->StartLinkProbe());
  node->StartBrainHost(*startup, std::move(*brain));
  SWARMBOX_TRY(node->StartPerception(*startup));
  SWARMBOX_TRY(node->StartDepth(*startup));
  return node;
}

Result<AgentNode::Startup> AgentNode::LoadStartup(const AgentOptions& o) {
  SWARMBOX_TRY(bus::ValidateDroneName(o.name));
  if (o.mesh && o.radio_model != RadioModel::kChannel && o.mesh_domain == o.sim_domain) {
    return Error(ErrorCode::kInvalidArgument,
                 "the sim and mesh buses need different DDS domain ids (both are " + std::to_string(o.sim_domain) + ")");
  }
  auto af = airframe::LoadAirframe(o.airframe_path);
  if (!af) return af.error().Context("loading airframe");
  auto config = flight::FlightConfigFrom(*af);
  if (!config) return config.error().Context("loading airframe");
  Startup s{.airframe = std::move(*af), .flight = std::move(*config)};
  if (o.mission.kind == MissionKind::kSar) {
    auto sar = SarConfigFor(o, s.airframe, s.flight);
    if (!sar) return sar.error();
    s.sar = std::move(*sar);
    s.perception.camera = s.sar->camera;
    s.perception.thermal = s.airframe.thermal;
    s.perception.inference_latency_s = o.mission.inference_latency_ms * 1e-3;
  }
  s.brain = o.brain.kind != BrainKind::kBuiltin;
  if (s.brain) {
    auto steps = BrainPeriodSteps(o.brain, o.control_dt_s);
    if (!steps) return steps.error();
    s.period_steps = *steps;
    if (o.mission.kind != MissionKind::kPlan) {
      return Error(ErrorCode::kInvalidArgument, "--mission is for --brain builtin (the brain decides what to fly)");
    }
  }
  return s;
}

Result<std::unique_ptr<AgentNode>> AgentNode::MakeNode(const AgentOptions& o, const flight::FlightConfig& config) {
  auto plan = FlightPlan::Parse(o.plan);  // --mission sar, a brain: parsed (the default) but not flown
  if (!plan) return plan.error().Context("--plan");
  plan->SetPreflight(o.preflight_s);
  auto fc = flight::FlightController::Create(config, ControllerOptionsFor(o, config));
  if (!fc) return fc.error();
  return std::unique_ptr<AgentNode>(new AgentNode(o, std::move(*fc), std::move(*plan)));
}

Status AgentNode::StartTelemetry() {
  const double hz = options_.telemetry_hz;
  if (hz < 0.0 || !std::isfinite(hz)) return Error(ErrorCode::kInvalidArgument, "--telemetry-hz must be >= 0");
  if (hz > 0.0) {
    // Every line printed on the log (the node's, Raft's, the brain host's) also goes to the
    // telemetry's event queue: the log's bytes stay as they were.
    auto tee = LogTee::Create(options_.log, [this](std::string_view line) { telemetry_events_.Push(line); });
    if (!tee) return tee.error().Context("the telemetry's log tee");
    log_tee_ = std::move(*tee);
    options_.log = log_tee_->file();  // from here on, the tee's stream: every part prints to it
    telemetry_clock_ = TelemetryClock(hz);
  }
  return Ok{};
}

Status AgentNode::JoinSimBus() {
  const AgentOptions& o = options_;
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
  sim_ = std::move(*sim);
  auto sub = sim_->CreateSubscriber<bus::SensorSample>(bus::SensorTopic(o.name), bus::Qos::kLockstep);
  if (!sub) return sub.error().Context("subscribing to sensor samples");
  sensor_sub_ = std::move(*sub);
  // The physics server's start (sim/status): while it comes, the first sample is waited for.
  auto status = sim_->CreateSubscriber<bus::Event>(bus::kSimStatusTopic, bus::Qos::kLockstep);
  if (!status) return status.error().Context("subscribing to the physics server's status");
  status_sub_ = std::move(*status);
  return StartSimPublishers();
}

Status AgentNode::StartSimPublishers() {
  // Every agent writes the one keyed topic sim/actuator (cmd_.drone is the key); the server reads it
  // with one reader.
  auto pub = sim_->CreatePublisher<bus::ActuatorCommand>(bus::kActuatorTopic, bus::Qos::kLockstep);
  if (!pub) return pub.error().Context("publishing actuator commands");
  actuator_pub_ = std::move(*pub);
  if (telemetry_clock_.enabled()) {
    // Keyed by drone like sim/actuator: the physics server's recorder reads it with one reader.
    auto tpub = sim_->CreatePublisher<bus::Telemetry>(bus::kTelemetryTopic, bus::Qos::kState);
    if (!tpub) return tpub.error().Context("publishing telemetry");
    telemetry_pub_ = std::move(*tpub);
  }
  return Ok{};
}

Result<std::unique_ptr<brain::Brain>> AgentNode::MakeFlyingBrain(const Startup& s) {
  if (s.brain) {
    auto made = MakeBrain(s.flight, s.period_steps);
    if (!made) return made.error();
    // Its own replicated state, made once before Raft starts (Raft replays its WAL into it).
    brain_state_ = (*made)->MakeReplicatedState();
    return made;
  }
  if (!s.sar) return std::unique_ptr<brain::Brain>();  // the built-in plan: no brain
  // The builtin SAR brain, through BrainHost as any brain; its replicated state is the mission.
  const bool channel = options_.radio_model == RadioModel::kChannel;
  auto made = SarBrain::Create(*s.sar, [this](const brain::Event& e) { LogBrainEvent(e); },
                               channel ? nullptr : &netem_wall_);
  if (!made) return made.error();
  sar_ = made->get();
  auto state = sar_->MakeMissionState();
  sar_state_ = state.get();
  brain_state_ = std::move(state);
  return std::unique_ptr<brain::Brain>(std::move(*made));
}

Result<std::unique_ptr<brain::Brain>> AgentNode::MakeBrain(const flight::FlightConfig& config, int period_steps) {
  const BrainOptions& b = options_.brain;
  brain::Context ctx = BrainContextFor(options_, config, period_steps);
  auto args = brain::ParseBrainArgs(b.args_json);
  if (!args) return args.error();
  ctx.args = std::move(*args);
  ctx.log = [this](const brain::Event& e) { LogBrainEvent(e); };
  LogEvent loaded(0.0, options_.name, "brain_loaded");
  loaded.Add("kind", BrainKindName(b.kind));
  auto made = b.kind == BrainKind::kLibrary ? LoadLibraryBrain(ctx, loaded) : StartExternalBrain(loaded);
  if (!made) return made.error();
  loaded.Add("period_ms", static_cast<double>(ctx.period_ns) * 1e-6, 1)
      .Add("offboard_timeout_ms", b.offboard_timeout_ms)
      .Add("offboard_hold_ms", b.offboard_hold_ms);
  Log(loaded);
  return made;
}

Result<std::unique_ptr<brain::Brain>> AgentNode::LoadLibraryBrain(const brain::Context& ctx, LogEvent& loaded) {
  const BrainOptions& b = options_.brain;
  auto lib = brain::LoadBrain(b.library_path, b.name, ctx);
  if (!lib) return lib.error().Context("--brain library");
  loaded.Add("name", b.name).Add("library", b.library_path);
  return std::unique_ptr<brain::Brain>(std::move(*lib));
}

Result<std::unique_ptr<brain::Brain>> AgentNode::StartExternalBrain(LogEvent& loaded) {
  const BrainOptions& b = options_.brain;
  ExternalBrainOptions eo;
  eo.drone = options_.name;
  eo.wait = std::chrono::milliseconds(b.wait_ms);
  eo.start = std::chrono::milliseconds(b.start_ms);
  eo.stop = options_.stop;
  eo.log = options_.log;
  auto ext = ExternalBrain::Create(*sim_, eo);
  if (!ext) return ext.error().Context("--brain external");
  loaded.Add("name", bus::OffboardInputTopic(options_.name));
  return std::unique_ptr<brain::Brain>(std::move(*ext));
}

Status AgentNode::StartRadio(bool brain) {
  const AgentOptions& o = options_;
  if (!o.mesh) return Ok{};
  if (o.radio_model == RadioModel::kChannel) {
    // No mesh domain at all: every frame rides the lockstep to the physics server's channel.
    radio_ = std::make_unique<radio::ChannelRadio>(o.name);
    return Ok{};
  }
  auto mesh = bus::Participant::Create({.backend = o.middleware,
                                        .domain_id = o.mesh_domain,
                                        .interface = o.mesh_interface,
                                        .writer_linger_ms = kNoLinger});
  if (!mesh) return mesh.error().Context("joining the mesh bus");
  mesh_ = std::move(*mesh);
  radio::DdsRadioOptions ro;
  ro.members = o.raft.members;
  ro.raft = o.raft.members.size() > 1;
  ro.pings = o.ping_every_ms > 0 && o.raft.members.size() > 1;
  ro.hear_states = o.mission.kind == MissionKind::kSar || brain;
  ro.brains = brain;
  auto dds = radio::DdsRadio::Create(*mesh_, o.name, ro);
  if (!dds) return dds.error().Context("starting the mesh radio");
  radio_ = std::move(*dds);
  return Ok{};
}

Status AgentNode::StartRaft(bool brain) {
  const AgentOptions& o = options_;
  if (o.raft.members.empty()) return Ok{};
  if (!o.mesh) return Error(ErrorCode::kInvalidArgument, "--members (Raft) needs the mesh bus (drop --no-mesh)");
  RaftHostOptions ro = o.raft;
  ro.self = o.name;
  ro.election_timeout_ms = ElectionTimeoutMsFor(o.mission, o.raft.election_timeout_ms);
  // Raft's clock: simulated seconds (channel: the radio's clock is the lockstep's, from 0), or
  // wall seconds since now (netem: the steady clock). Its lines carry the simulated time.
  const bool channel = o.radio_model == RadioModel::kChannel;
  raft_clock_ = std::make_unique<RadioClock>(*radio_, channel ? 0 : radio_->now_ns());
  std::unique_ptr<raft::StateMachine> machine = RaftMachine(brain);
  auto raft = RaftHost::Start(ro, *radio_, *raft_clock_, options_.log, &sim_clock_, std::move(machine));
  if (!raft) return raft.error();
  raft_ = std::move(*raft);
  return Ok{};
}

std::unique_ptr<raft::StateMachine> AgentNode::RaftMachine(bool brain) {
  if (sar_state_ != nullptr) {
    // SarBrain's state is raft's MissionStateMachine: Raft applies it with its own event lines.
    return sar_state_->RaftMachine();
  }
  if (brain && brain_state_) return std::make_unique<ReplicatedStateMachine>(brain_state_.get());
  if (brain) return std::make_unique<raft::EntryLogMachine>();
  return nullptr;  // RaftHost's own MissionStateMachine
}

Status AgentNode::StartLinkProbe() {
  const AgentOptions& o = options_;
  if (o.ping_every_ms < 0) return Error(ErrorCode::kInvalidArgument, "--ping-every-ms must be >= 0");
  if (o.ping_peers <= 0) return Error(ErrorCode::kInvalidArgument, "--ping-peers must be > 0");
  if (radio_ && o.ping_every_ms > 0 && o.raft.members.size() > 1) {
    radio::LinkProbeOptions po;
    po.ping_every = std::chrono::milliseconds(o.ping_every_ms);
    po.ping_peers = o.ping_peers;
    auto probe = radio::LinkProbe::Create(o.name, o.raft.members, po, radio::RadioTime(radio_->now_ns()));
    if (!probe) return probe.error().Context("starting the link probe");
    probe_ = std::move(*probe);
  }
  return Ok{};
}

void AgentNode::StartBrainHost(const Startup& s, std::unique_ptr<brain::Brain> brain) {
  if (!s.brain && sar_ == nullptr) return;  // the built-in plan flies without a host
  const AgentOptions& o = options_;
  BrainHostOptions bo;
  bo.self = o.name;
  bo.period_steps = s.period_steps;
  bo.offboard_timeout_s = o.brain.offboard_timeout_ms * 1e-3;
  bo.offboard_hold_s = o.brain.offboard_hold_ms * 1e-3;
  bo.state = brain_state_.get();
  bo.neighbours.max_listed = static_cast<std::size_t>(std::max(1, o.brain.neighbours));
  flight_port_ = std::make_unique<FlightAdapter>(fc_);
  if (raft_) consensus_ = std::make_unique<RaftConsensus>(*raft_);
  brain_host_ = std::make_unique<BrainHost>(bo, std::move(brain), *flight_port_, radio_.get(), consensus_.get(),
                                            options_.log);
  if (auto spec = swarm::BatterySpecFor(s.flight.airframe)) battery_.emplace(*spec);
}

Status AgentNode::StartPerception(const Startup& s) {
  // Perception runs beside the brain on a scout of the SAR mission and, for any other brain, on
  // an airframe with a camera: its detections are Input::detections. (The physics server renders
  // frames only when the trial asks for cameras; without frames nothing is detected.)
  PerceptionConfig perception = s.perception;
  bool perceive = sar_ != nullptr && sar_->role() == swarm::Role::kScout;
  if (s.brain && s.airframe.has_camera) {
    perception.camera = s.airframe.camera;
    perception.thermal = s.airframe.thermal;
    perception.inference_latency_s = options_.mission.inference_latency_ms * 1e-3;
    perceive = true;
  }
  if (!perceive) return Ok{};
  auto p = PerceptionHost::Create(perception);
  if (!p) return p.error();
  perception_ = std::move(*p);
  auto cam = sim_->CreateSubscriber<bus::CameraImage>(bus::CameraTopic(options_.name), bus::Qos::kLockstep);
  if (!cam) return cam.error().Context("subscribing to the camera");
  camera_sub_ = std::move(*cam);
  return Ok{};
}

// The payload this drone carries (`payload`, the airframe's) as its stereo camera sees it: the
// hook and sling from the airframe, the mount's offset, the flight stack's tilt limit (the most
// the sling swings while the lifter holds over the point); none without a payload.
std::optional<depth::SlungPayload> AgentNode::SlungPayloadSeen(const Startup& s, const std::string& payload) {
  if (payload.empty()) return std::nullopt;
  const auto spec = s.airframe.FindPayload(payload);
  if (!spec) return std::nullopt;
  const airframe::PayloadSpec& p = **spec;
  const airframe::Vec3& mount = s.airframe.stereo.offset_m;
  return depth::SlungPayload{.hook_below_camera_m = mount.z - p.hook_m.z,
                             .hook_from_camera_m = std::hypot(mount.x - p.hook_m.x, mount.y - p.hook_m.y),
                             .sling_length_m = p.sling_length_m,
                             .payload_half_diagonal_m = airframe::Norm(p.size_m) / 2,
                             .max_tilt_rad = s.flight.position.tilt_max_rad};
}

Status AgentNode::StartDepth(const Startup& s) {
  if (!s.airframe.stereo.enabled) return Ok{};  // no `stereo:`: nothing subscribed, nothing costs
  // The device latency's draws: the trial's seed, told apart per drone by its name (FNV-1a).
  std::uint64_t seed = 14695981039346656037ull ^ options_.raft.seed;
  for (const char c : options_.name) seed = (seed ^ static_cast<unsigned char>(c)) * 1099511628211ull;
  auto host = DepthHost::Create(*sim_, {.drone = options_.name,
                                        .spec = s.airframe.stereo,
                                        .seed = seed,
                                        .pair_timeout = options_.camera_timeout,
                                        .stop = options_.stop});
  if (!host) return host.error();
  depth_ = std::move(*host);
  slung_payload_ = SlungPayloadSeen(s, options_.mission.payload);
  return Ok{};
}

void AgentNode::LogBrainEvent(const brain::Event& e) {
  LogEvent line(t_s_, options_.name, e.name);
  for (const auto& [k, v] : e.fields) line.Add(k, v);
  Log(line);
}

}  // namespace swarmbox::agent
