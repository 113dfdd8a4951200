#include "sim_server.hpp"

#include <algorithm>
#include <chrono>
#include <optional>
#include <span>
#include <thread>

#include "world_commands.hpp"

namespace swarmbox::physics {

std::int64_t SteadyWallClock::NowNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

void SteadyWallClock::SleepUntilNs(std::int64_t t_ns) {
  std::this_thread::sleep_until(std::chrono::steady_clock::time_point(std::chrono::nanoseconds(t_ns)));
}

bool ClockProgress::OnStep(std::int64_t sim_ns, std::int64_t wall_ns, bool late) {
  if (origin_wall_ns_ < 0) {  // the first step anchors the first interval
    origin_sim_ns_ = sim_ns;
    origin_wall_ns_ = wall_ns;
  }
  sim_ns_ = sim_ns;
  wall_ns_ = wall_ns;
  if (late) ++late_;
  return sim_ns >= next_ns_;
}

ClockProgress::Line ClockProgress::Take() {
  Line line;
  const std::int64_t wall = wall_ns_ - origin_wall_ns_;
  if (wall > 0) line.rtf = static_cast<double>(sim_ns_ - origin_sim_ns_) / static_cast<double>(wall);
  line.late = late_;
  while (next_ns_ <= sim_ns_) next_ns_ += every_ns_;
  origin_sim_ns_ = sim_ns_;
  origin_wall_ns_ = wall_ns_;
  late_ = 0;
  return line;
}

void SimServer::PrintingSink::OnEvent(const PhysicsEvent& event) {
  std::fprintf(out_, "%s\n", event.ToLogEvent(node_).str().c_str());
  std::fflush(out_);
}

SimServer::SimServer(World& world, SimTransport& transport, WallClock& clock, TruthCsvFile* truth,
                     SimServerOptions options, std::FILE* events_out)
    : world_(world),
      transport_(transport),
      clock_(clock),
      truth_(truth),
      options_(std::move(options)),
      out_(events_out),
      sink_(events_out, options_.node),
      lockstep_(world.drone_count(), options_.lockstep),
      zeros_(8, 0.0),
      base_wind_(world.config().wind),
      slots_(world.drone_count()),
      trigger_(world.drone_count()) {
  world_.SetEventSink(&sink_);
  if (options_.radio_profile) {
    const std::size_t n = world.drone_count();
    channel_.emplace(*options_.radio_profile, n, options_.radio_seed, ChannelObstacles(world.config()));
    if (options_.plan.mesh) channel_->SetImpairment(std::nullopt, *options_.plan.mesh);
    positions_.resize(n);
    impairments_.resize(n);
    blocked_.assign(n * n, 0);
  }
  if (auto stereo = std::make_unique<StereoCapture>(world); stereo->any()) stereo_ = std::move(stereo);
  if (options_.clock_every_s > 0) {
    progress_.emplace(static_cast<std::int64_t>(options_.clock_every_s * 1e9));
  }
}

void SimServer::Log(const LogEvent& event) {
  std::fprintf(out_, "%s\n", event.str().c_str());
  std::fflush(out_);
}

void SimServer::Apply(const WorldCommandInput& cmd) {
  const double t = world_.time_s();
  auto reject = [&](const std::string& why) {
    Log(LogEvent(t, options_.node, "world_command_rejected").Add("command", cmd.command).Add("target", cmd.target).Add("reason", why));
  };
  std::optional<std::size_t> drone;
  if (!cmd.target.empty()) {
    drone = world_.FindDrone(cmd.target);
    if (!drone) return reject("unknown drone");
  }
  if (Status ok = CheckWorldCommand(cmd.command, drone.has_value(), cmd.args); !ok) {
    return reject(ok.error().message());
  }
  if (std::optional<std::string> why = Execute(cmd, drone)) return reject(*why);
  LogEvent done(t, options_.node, "world_command");
  done.Add("command", cmd.command).Add("target", cmd.target);
  if (cmd.command == "payload_attach" && !cmd.args.empty()) done.Add("mass_kg", cmd.args[0]);
  Log(done);
}

std::optional<std::string> SimServer::Execute(const WorldCommandInput& cmd, std::optional<std::size_t> drone) {
  const std::int64_t now = world_.time_ns();
  auto seconds = [](double s) { return static_cast<std::int64_t>(s * 1e9); };
  if (cmd.command == "gps_dropout") {
    world_.SetGpsDropout(*drone, true);
    timed_.push_back({now + seconds(cmd.args[0]), *drone, Timed::kGpsBack});
  } else if (cmd.command == "gps_degrade") {
    world_.SetGpsAccuracy(*drone, cmd.args[1], cmd.args[2]);
    timed_.push_back({now + seconds(cmd.args[0]), *drone, Timed::kGpsAccuracyBack});
  } else if (cmd.command == "imu_bias_jump") {
    world_.AddImuBias(*drone, {cmd.args[0], cmd.args[1], cmd.args[2]}, {cmd.args[3], cmd.args[4], cmd.args[5]});
  } else if (cmd.command == "wind_gust") {
    WindConfig gust = base_wind_;
    gust.mean_m_s = base_wind_.mean_m_s + Vec3{cmd.args[0], cmd.args[1], cmd.args[2]};
    world_.SetWind(gust);
    timed_.push_back({now + seconds(cmd.args[3]), 0, Timed::kWindBack});
  } else {  // payload_attach / payload_release (the table knows no other name)
    return ExecutePayload(cmd, *drone);
  }
  return std::nullopt;
}

std::optional<std::string> SimServer::ExecutePayload(const WorldCommandInput& cmd, std::size_t drone) {
  // payload_attach [mass_kg]: the payload's mass from now on (the lifter's stretcher is 15 kg
  // empty, 80 kg with the evacuee); absent or 0 keeps its current mass.
  if (cmd.command == "payload_attach" && (cmd.args.size() > 1 || (!cmd.args.empty() && !(cmd.args[0] >= 0)))) {
    return "payload_attach takes at most one argument, mass_kg >= 0";
  }
  const double mass_kg = cmd.args.empty() ? 0.0 : cmd.args[0];
  const Status s = cmd.command == "payload_attach" ? world_.AttachPayload(drone, mass_kg) : world_.ReleasePayload(drone);
  if (!s) return s.error().message();
  return std::nullopt;
}

namespace {

// How long a sent frame's payload is kept for its deliveries [simulated ns]: far beyond any delay
// the channel gives (impairment delay and jitter, a full queue on a busy medium). A delivery of an
// older frame is counted as `expired` in event=channel and dropped.
constexpr std::int64_t kFrameKeepNs = 120'000'000'000;

}  // namespace

Status CheckChannelPlan(const RadioPlan& plan) {
  if (plan.mesh) {
    if (Status s = channel::ValidateImpairment(*plan.mesh); !s) {
      return Error(ErrorCode::kInvalidArgument, "mesh: " + s.error().message());
    }
  }
  for (const PlanEntry& e : plan.schedule) {
    if (e.kind != PlanEntry::Kind::kRadio) continue;
    if (Status s = channel::ValidateImpairment(e.impairment); !s) {
      return Error(ErrorCode::kInvalidArgument, "entry '" + e.name + "': " + s.error().message(), e.where);
    }
  }
  return Ok{};
}

std::vector<channel::Box> ChannelObstacles(const WorldConfig& world) {
  std::vector<channel::Box> boxes;
  for (const ObstacleBox& o : world.obstacles) {
    const Vec3 h = o.size_m * 0.5;
    boxes.push_back({{o.center_m.x - h.x, o.center_m.y - h.y, o.center_m.z - h.z},
                     {o.center_m.x + h.x, o.center_m.y + h.y, o.center_m.z + h.z},
                     o.yaw_rad});
  }
  return boxes;
}

void SimServer::TakeDeliveries(std::int64_t until_ns) {
  for (Slot& slot : slots_) slot.radio_in.clear();
  deliveries_.clear();
  channel_->TakeDeliveries(until_ns, &deliveries_);
  for (const channel::Delivery& d : deliveries_) {
    if (d.packet.token < first_token_ || d.packet.token - first_token_ >= frames_.size()) {
      ++frames_expired_;
      continue;
    }
    bus::RadioFrame& f = slots_[d.to].radio_in.emplace_back(frames_[d.packet.token - first_token_].frame);
    f.delivered_ns = d.at_ns;
  }
  // Frames old enough that no delivery can be due any more.
  while (!frames_.empty() && frames_.front().sent_ns < until_ns - kFrameKeepNs) {
    frames_.pop_front();
    ++first_token_;
  }
  for (std::size_t i = 0; i < positions_.size(); ++i) {
    const Vec3 p = world_.Truth(i).position_m;
    positions_[i] = {p.x, p.y, p.z};
  }
  channel_->SetPositions(positions_);
}

void SimServer::SendRadio(std::int64_t now_ns) {
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = slots_[i];
    if (!lockstep_.answered(i)) {
      slot.radio_out.clear();
      continue;
    }
    std::stable_sort(slot.radio_out.begin(), slot.radio_out.end(),
                     [](const bus::RadioFrame& a, const bus::RadioFrame& b) { return a.seq < b.seq; });
    for (bus::RadioFrame& f : slot.radio_out) {
      channel::Packet p;
      p.from = i;
      if (!f.to.empty()) {
        p.to = world_.FindDrone(f.to);
        if (!p.to) {
          Log(LogEvent(world_.time_s(), options_.node, "radio_frame_rejected").Add("drone", world_.drone_name(i))
                  .Add("to", f.to).Add("reason", "unknown drone"));
          continue;
        }
      }
      p.seq = f.seq;
      p.size_bytes = f.size_bytes;
      p.sent_ns = now_ns;
      p.token = first_token_ + frames_.size();
      f.from = world_.drone_name(i);  // the answer's topic names the sender, not the frame
      f.sent_ns = now_ns;
      f.delivered_ns = 0;
      frames_.push_back({now_ns, std::move(f)});
      channel_->Send(now_ns, p);
    }
    slot.radio_out.clear();
  }
}

void SimServer::SetImpairmentOf(std::size_t drone) {
  const std::vector<std::size_t>& active = impairments_[drone];
  if (active.empty()) {
    channel_->ClearImpairment(drone);
  } else {
    channel_->SetImpairment(drone, options_.plan.schedule[active.back()].impairment);
  }
}

void SimServer::RadioFault(std::size_t entry, bool on) {
  const PlanEntry& e = options_.plan.schedule[entry];
  if (e.kind == PlanEntry::Kind::kRadio) {
    for (const std::string& t : e.targets) {
      const std::size_t i = *world_.FindDrone(t);  // CheckRadioPlan
      std::vector<std::size_t>& active = impairments_[i];
      if (on) {
        active.push_back(entry);
      } else {
        active.erase(std::remove(active.begin(), active.end(), entry), active.end());
      }
      SetImpairmentOf(i);
    }
  } else {
    const std::size_t n = slots_.size();
    for (std::size_t a = 0; a < e.groups.size(); ++a) {
      for (std::size_t b = 0; b < e.groups.size(); ++b) {
        if (a == b || (e.oneway && a != 0)) continue;
        for (const std::string& from : e.groups[a]) {
          for (const std::string& to : e.groups[b]) {
            const std::size_t f = *world_.FindDrone(from), t = *world_.FindDrone(to);
            int& count = blocked_[f * n + t];
            count += on ? 1 : -1;
            channel_->SetBlocked(f, t, count > 0);
          }
        }
      }
    }
  }
  Log(LogEvent(world_.time_s(), options_.node, "radio_fault").Add("fault", e.name)
          .Add("kind", e.kind == PlanEntry::Kind::kRadio ? "impair" : "partition").Add("state", on ? "on" : "off"));
  if (on && e.duration_ns > 0) radio_ends_.push_back({world_.time_ns() + e.duration_ns, entry});
}

void SimServer::LogChannel() {
  const channel::ChannelStats& c = channel_->stats();
  Log(LogEvent(world_.time_s(), options_.node, "channel")
          .Add("sent", c.sent)
          .Add("delivered", c.delivered)
          .Add("lost_range", c.lost_range)
          .Add("lost_per", c.lost_per)
          .Add("lost_impairment", c.lost_impairment)
          .Add("lost_queue", c.lost_queue)
          .Add("lost_partition", c.lost_partition)
          .Add("lost_out", c.lost_out)
          .Add("duplicated", c.duplicated)
          .Add("medium_busy_s", static_cast<double>(c.medium_busy_ns) * 1e-9, 3)
          .Add("expired", frames_expired_));
}

Status SimServer::PublishDrone(std::size_t i, bool with_camera) {
  Slot& slot = slots_[i];
  const std::string& name = world_.drone_name(i);
  if (with_camera && slot.camera_frame) {
    // The thermal frame first: the agent waits for the step's colour frame (frame_wait.hpp), and
    // one writer's samples arrive in order, so the thermal one is there with it.
    if (slot.thermal_frame) {
      if (auto s = transport_.PublishThermal(i, name, world_.step_count(), slot.thermal); !s) return s;
    }
    if (auto s = transport_.PublishCamera(i, name, world_.step_count(), slot.image); !s) return s;
  }
  if (with_camera && slot.stereo_frame) {
    if (auto s = transport_.PublishStereo(i, slot.stereo); !s) return s;
  }
  return transport_.PublishSample(i, name, world_.sensors(i),
                                  SampleExtras{slot.camera_frame, slot.radio_in, slot.stereo_frame});
}

void SimServer::Accept(std::size_t i, ActuatorInput& cmd) {
  for (std::size_t r : lockstep_.TakeRejoined()) world_.SetLost(r, false);
  const std::size_t rotors = world_.airframe(i).rotors.size();
  const std::span<const double> u = cmd.armed ? std::span<const double>(cmd.throttle) : std::span<const double>(zeros_.data(), rotors);
  if (auto s = world_.SetActuators(i, u); !s) {
    Log(LogEvent(world_.time_s(), options_.node, "bad_command").Add("drone", cmd.drone).Add("reason", s.error().message()));
  }
  Slot& slot = slots_[i];
  slot.answer_leader = cmd.raft_leader;
  slot.world = std::move(cmd.world);
  if (channel_) slot.radio_out = std::move(cmd.radio_out);  // netem: the mesh network carries the radio
}

void SimServer::ApplyAnswers() {
  const std::uint64_t step = world_.step_count();
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = slots_[i];
    if (!lockstep_.answered(i)) continue;
    std::stable_sort(slot.world.begin(), slot.world.end(),
                     [](const WorldCommandInput& a, const WorldCommandInput& b) { return a.seq < b.seq; });
    for (const WorldCommandInput& c : slot.world) Apply(c);
    slot.world.clear();
    if (slot.answer_leader && !slot.leader) slot.leader_since = step + 1;
    slot.leader = slot.answer_leader;
  }
}

std::optional<std::size_t> SimServer::RaftLeader() const {
  std::optional<std::size_t> best;
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    const Slot& slot = slots_[i];
    if (!slot.leader || lockstep_.out(i) || lockstep_.lost(i)) continue;
    if (!best || slot.leader_since > slots_[*best].leader_since) best = i;  // ties: drone order
  }
  return best;
}

void SimServer::TakeOut(std::size_t i, const PlanEntry& e) {
  Slot& slot = slots_[i];
  if (lockstep_.out(i)) {
    Log(LogEvent(world_.time_s(), options_.node, "fault_skipped").Add("fault", e.name).Add("drone", world_.drone_name(i))
            .Add("reason", "already out"));
    return;
  }
  lockstep_.SetOut(i, true);
  world_.SetOut(i, true);
  if (channel_) channel_->SetOut(i, true);
  slot.leader = false;
  slot.camera_frame = false;
  slot.stereo_frame = false;
  slot.radio_in.clear();
  slot.radio_out.clear();
  slot.back_ns = e.duration_ns > 0 ? world_.time_ns() + e.duration_ns : -1;
  slot.out_fault = e.name;
  Log(LogEvent(world_.time_s(), options_.node, "drone_out").Add("drone", world_.drone_name(i)).Add("fault", e.name)
          .Add("mode", ModeName(e.mode)));
}

void SimServer::CarryOut(const PlanEntry& e) {
  const double t = world_.time_s();
  switch (e.kind) {
    case PlanEntry::Kind::kDroneOut: {
      std::vector<std::size_t> drones;
      for (const std::string& target : e.targets) {
        if (target == kRaftLeaderTarget) {
          const std::optional<std::size_t> leader = RaftLeader();
          if (!leader) {
            Log(LogEvent(t, options_.node, "fault_skipped").Add("fault", e.name).Add("reason", "no drone leads the Raft group"));
            continue;
          }
          Log(LogEvent(t, options_.node, "raft_leader_resolved").Add("fault", e.name).Add("drone", world_.drone_name(*leader)));
          drones.push_back(*leader);
        } else if (const auto i = world_.FindDrone(target)) {
          drones.push_back(*i);
        }
      }
      for (std::size_t i : drones) TakeOut(i, e);
      break;
    }
    case PlanEntry::Kind::kWorldCommand:
      Apply({e.target, e.command, e.args, 0});
      break;
    case PlanEntry::Kind::kRadio:
    case PlanEntry::Kind::kPartition:
      if (channel_) {
        RadioFault(static_cast<std::size_t>(&e - options_.plan.schedule.data()), true);
        break;
      }
      Log(LogEvent(t, options_.node, "radio_fault_ignored").Add("fault", e.name)
              .Add("kind", e.kind == PlanEntry::Kind::kRadio ? "impair" : "partition")
              .Add("reason", "radio.model netem: the fault sidecars carry radio faults"));
      break;
  }
}

void SimServer::RunSchedule(std::int64_t now_ns) {
  // Drones whose time out ends now come back first: they re-enter the lockstep as joining drones
  // at the next step.
  for (std::size_t i = 0; i < slots_.size(); ++i) {
    Slot& slot = slots_[i];
    if (!lockstep_.out(i) || slot.back_ns < 0 || slot.back_ns > now_ns) continue;
    lockstep_.SetOut(i, false);
    world_.SetOut(i, false);
    if (channel_) channel_->SetOut(i, false);
    slot.back_ns = -1;
    Log(LogEvent(world_.time_s(), options_.node, "drone_back").Add("drone", world_.drone_name(i)).Add("fault", slot.out_fault));
  }
  for (std::size_t n = 0; n < radio_ends_.size();) {
    if (radio_ends_[n].at_ns > now_ns) {
      ++n;
      continue;
    }
    const std::size_t entry = radio_ends_[n].entry;
    radio_ends_.erase(radio_ends_.begin() + static_cast<std::ptrdiff_t>(n));
    RadioFault(entry, false);
  }
  const std::vector<PlanEntry>& schedule = options_.plan.schedule;
  while (next_entry_ < schedule.size() && schedule[next_entry_].at_ns <= now_ns) CarryOut(schedule[next_entry_++]);
}

JoiningStatus SimServer::Joining() const {
  JoiningStatus status;
  for (std::size_t i = 0; i < world_.drone_count(); ++i) {
    if (lockstep_.out(i)) continue;
    ++status.expected;
    if (lockstep_.joined(i)) {
      ++status.joined;
    } else {
      status.missing.push_back(world_.drone_name(i));
    }
  }
  return status;
}

Status SimServer::ReportJoining(bool done) {
  const JoiningStatus status = Joining();
  if (done) {
    const bool reported = joining_.reported();
    const double wait_s = joining_.End(clock_.NowNs());
    if (reported || lockstep_.lost_count() > 0) {
      Log(JoinedEvent(world_.time_s(), options_.node, status, lockstep_.lost_count(), wait_s));
    }
  } else {
    Log(JoiningEvent(world_.time_s(), options_.node, status));
  }
  return transport_.PublishStatus(status, done);
}

// Waits until `deadline_ns` at most (not at all when it has passed) for the awaited answers and
// hands each accepted one to the step.
void SimServer::TakeAnswers(std::int64_t deadline_ns) {
  inbox_.clear();
  transport_.WaitActuators(deadline_ns, std::max<std::size_t>(1, lockstep_.awaited()), &inbox_);
  for (ActuatorInput& cmd : inbox_) {
    const std::optional<std::size_t> i = world_.FindDrone(cmd.drone);
    if (!i) continue;
    if (lockstep_.OnCommand(*i, cmd.step, clock_.NowNs()) != Lockstep::Answer::kAccepted) continue;
    Accept(*i, cmd);
  }
}

// The camera of drone `i` at this step: due by its trigger (camera_trigger.hpp), rendered, shown
// to the recording.
bool SimServer::CaptureCamera(std::size_t i) {
  Slot& slot = slots_[i];
  if (!options_.cameras || world_.Truth(i).lost) return false;
  const Vec3 position_m = world_.Truth(i).position_m;
  if (!trigger_.Due(i, world_.airframe(i).camera, world_.CameraDue(i), world_.time_ns(), position_m)) return false;
  trigger_.Captured(i, world_.time_ns(), position_m);
  world_.RenderCamera(i, &slot.image);
  slot.thermal_frame = world_.airframe(i).thermal.enabled && world_.RenderThermal(i, &slot.thermal).ok();
  if (options_.observer != nullptr) options_.observer->OnCamera(i, slot.image);
  return true;
}

// The stereo pair of drone `i` at step `step`: due on its fixed schedule (StereoCapture), not for
// a lost drone; rendered into the slot.
bool SimServer::CaptureStereo(std::size_t i, std::uint64_t step) {
  if (!stereo_ || !stereo_->Due(i, step) || world_.Truth(i).lost) return false;
  stereo_->Capture(world_, i, step, &slots_[i].stereo);
  return true;
}

// Step k's cameras, stereo pairs and samples (each frame before its sample), then the clock.
Status SimServer::PublishStep(std::uint64_t step) {
  if (channel_) TakeDeliveries(world_.time_ns());
  for (std::size_t i = 0; i < world_.drone_count(); ++i) {
    if (lockstep_.out(i)) continue;
    slots_[i].camera_frame = CaptureCamera(i);
    slots_[i].stereo_frame = CaptureStereo(i, step);
    if (auto s = PublishDrone(i, /*with_camera=*/true); !s) return s;
  }
  return transport_.PublishClock(step, world_.time_ns(), world_.options().control_period_ns, options_.rtf);
}

// While a step waits, every drone's sample is sent again at this period: unanswered ones for late
// joiners and lost messages (the lockstep QoS is volatile), answered ones as a keepalive, so an
// agent that did answer does not take a long wait (a fleet still starting, a silent drone's
// timeout) for a stalled server (its --stall-timeout). It answers again; Lockstep drops the
// duplicate. An unanswered drone gets its camera frame again first (its sample says a frame goes
// with it, and an agent waits for that frame before it answers).
Status SimServer::Republish() {
  for (std::size_t i = 0; i < world_.drone_count(); ++i) {
    if (lockstep_.out(i)) continue;
    if (auto s = PublishDrone(i, /*with_camera=*/!lockstep_.answered(i)); !s) return s;
  }
  return Ok{};
}

// Waits for every live drone's answer to the step (or its timeout), re-sending samples meanwhile
// and reporting the start's progress while the first step waits. Returns when the step is
// complete or `stop` is set.
Status SimServer::AwaitAnswers(std::uint64_t step, const std::atomic<bool>& stop) {
  // The step starts for the lockstep once its samples are out: rendering and publishing the
  // cameras (a 640 x 360 frame is 691 kB) can take a while on a loaded host, and no agent can
  // answer before it has its sample, so that time does not count against the drones.
  lockstep_.BeginStep(step, clock_.NowNs());
  if (step == 0) joining_.Begin(clock_.NowNs());
  constexpr std::int64_t kPollNs = 20'000'000;        // re-check `stop` at least this often
  constexpr std::int64_t kRepublishNs = 200'000'000;  // Republish()
  std::int64_t last_publish = clock_.NowNs();
  while (!stop.load()) {
    const std::int64_t now = clock_.NowNs();
    // A server that was itself held up past a deadline (descheduled, a slow publish) takes the
    // answers that arrived meanwhile before it judges anyone lost: otherwise its own stall would
    // mark every drone lost at once.
    if (now >= lockstep_.NextDeadlineNs()) TakeAnswers(now);
    if (lockstep_.StepComplete(now)) break;
    if (joining_.Due(now)) {
      if (auto s = ReportJoining(/*done=*/false); !s) return s;
    }
    if (now - last_publish >= kRepublishNs) {
      last_publish = now;
      if (auto s = Republish(); !s) return s;
    }
    TakeAnswers(std::min(lockstep_.NextDeadlineNs(), now + kPollNs));
  }
  for (std::size_t i : lockstep_.TakeNewlyLost()) world_.SetLost(i, true);
  return Ok{};
}

// The world commands timed by Apply (gps_dropout, gps_degrade, wind_gust) that end now.
void SimServer::EndTimedCommands() {
  for (auto it = timed_.begin(); it != timed_.end();) {
    if (world_.time_ns() < it->until_ns) {
      ++it;
      continue;
    }
    if (it->kind == Timed::kGpsBack) world_.SetGpsDropout(it->drone, false);
    if (it->kind == Timed::kGpsAccuracyBack) world_.SetGpsAccuracy(it->drone, 0, 0);
    if (it->kind == Timed::kWindBack) world_.SetWind(base_wind_);
    it = timed_.erase(it);
  }
}

// The step's commands, radio and plan at t_k, then World::Step() to t_{k+1} and what records it.
Status SimServer::AdvanceWorld() {
  ApplyAnswers();
  world_inbox_.clear();
  transport_.TakeWorldCommands(&world_inbox_);
  for (const WorldCommandInput& c : world_inbox_) Apply(c);
  if (channel_) SendRadio(world_.time_ns());
  RunSchedule(world_.time_ns());
  world_.Step();
  EndTimedCommands();
  if (truth_ != nullptr) {
    if (auto s = truth_->MaybeWrite(world_); !s) return s;
  }
  if (options_.observer != nullptr) options_.observer->OnStep(world_);
  return Ok{};
}

// Sleeps to the requested real-time factor (rtf > 0); returns the wall time after it and whether
// the step ended behind its paced wall time.
std::int64_t SimServer::Pace(bool* late) {
  *late = false;
  std::int64_t now = clock_.NowNs();
  if (options_.rtf <= 0) return now;
  if (pace_origin_wall_ns_ < 0) {
    pace_origin_wall_ns_ = now;
    pace_origin_sim_ns_ = world_.time_ns();
  }
  const auto target = pace_origin_wall_ns_ +
                      static_cast<std::int64_t>(static_cast<double>(world_.time_ns() - pace_origin_sim_ns_) / options_.rtf);
  if (target > now) {
    clock_.SleepUntilNs(target);
    return target;  // what the wall clock says after the sleep, without reading it again
  }
  *late = target < now;
  if (now - target > 500'000'000) pace_origin_wall_ns_ = -1;  // fell behind by > 0.5 s (agents
                                                               // slow): re-anchor, no catch-up burst
  return now;
}

// event=clock (and event=channel) when a line is due.
void SimServer::ReportProgress(std::int64_t wall_ns, bool late) {
  if (!progress_ || !progress_->OnStep(world_.time_ns(), wall_ns, late)) return;
  const ClockProgress::Line line = progress_->Take();
  Log(LogEvent(world_.time_s(), options_.node, "clock")
          .Add("rtf", line.rtf, 2)
          .Add("steps", static_cast<std::uint64_t>(world_.step_count()))
          .Add("late", line.late)
          .Add("lost", static_cast<std::uint64_t>(lockstep_.lost_count())));
  if (channel_) LogChannel();
}

Status SimServer::RunStep(const std::atomic<bool>& stop) {
  const std::uint64_t step = world_.step_count();
  if (auto s = PublishStep(step); !s) return s;
  if (auto s = AwaitAnswers(step, stop); !s) return s;
  if (stop.load()) return Ok{};
  if (joining_.active()) {
    if (auto s = ReportJoining(/*done=*/true); !s) return s;
  }
  if (auto s = AdvanceWorld(); !s) return s;
  bool late = false;
  const std::int64_t now = Pace(&late);
  ReportProgress(now, late);
  return Ok{};
}

Status SimServer::Run(const std::atomic<bool>& stop) {
  const auto max_ns = static_cast<std::int64_t>(options_.max_sim_time_s * 1e9);
  while (!stop.load()) {
    if (options_.max_sim_time_s > 0 && world_.time_ns() >= max_ns) break;
    if (auto s = RunStep(stop); !s) return s;
  }
  if (truth_ != nullptr) return truth_->Flush();
  return Ok{};
}

}  // namespace swarmbox::physics
