#include "brain_host.hpp"

#include <cmath>
#include <cstdio>
#include <exception>
#include <utility>

#include "brain_convert.hpp"
#include "swarmbox/common/format.hpp"

namespace swarmbox::agent {
namespace {

double Seconds(std::int64_t t_ns) { return static_cast<double>(t_ns) * 1e-9; }

bool Same(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }
bool Same(const brain::Vec3& a, const brain::Vec3& b) { return Same(a.x, b.x) && Same(a.y, b.y) && Same(a.z, b.z); }

}  // namespace

bool SameSetpoint(const brain::Setpoint& a, const brain::Setpoint& b) {
  return Same(a.position_m, b.position_m) && Same(a.velocity_m_s, b.velocity_m_s) &&
         Same(a.acceleration_m_s2, b.acceleration_m_s2) && Same(a.yaw_rad, b.yaw_rad) &&
         Same(a.yawspeed_rad_s, b.yawspeed_rad_s);
}

bool LandedMode(flight::FlightMode mode) {
  return mode == flight::FlightMode::kInit || mode == flight::FlightMode::kIdle ||
         mode == flight::FlightMode::kLanded;
}

brain::FlightEvent FlightEventOf(const flight::FlightEvent& e) {
  brain::FlightEvent out;
  out.name = std::string(flight::FlightEventName(e.kind));
  out.t_ns = std::llround(e.t_s * 1e9);
  if (e.kind == flight::FlightEventKind::kModeChange) out.fields["mode"] = std::string(flight::FlightModeName(e.mode));
  out.fields["x"] = FormatFixed(e.pos_m.x(), 2);
  out.fields["y"] = FormatFixed(e.pos_m.y(), 2);
  out.fields["z"] = FormatFixed(e.pos_m.z(), 2);
  return out;
}

flight::Setpoint FlightSetpointOf(const brain::Setpoint& sp) {
  flight::TrajectoryTarget t;
  t.pos_m = flight::Vec3(sp.position_m.x, sp.position_m.y, sp.position_m.z);
  t.vel_m_s = flight::Vec3(sp.velocity_m_s.x, sp.velocity_m_s.y, sp.velocity_m_s.z);
  t.acc_m_s2 = flight::Vec3(sp.acceleration_m_s2.x, sp.acceleration_m_s2.y, sp.acceleration_m_s2.z);
  t.yaw_rad = sp.yaw_rad;
  t.yawspeed_rad_s = sp.yawspeed_rad_s;
  return flight::Setpoint::FromTrajectory(t);
}

BrainHost::BrainHost(BrainHostOptions options, std::unique_ptr<brain::Brain> brain, FlightPort& flight,
                     radio::MeshRadio* radio, ConsensusPort* consensus, std::FILE* log)
    : options_(std::move(options)),
      brain_(std::move(brain)),
      remote_(dynamic_cast<RemoteBrain*>(brain_.get())),
      flight_(flight),
      radio_(radio),
      consensus_(consensus),
      log_(log),
      failsafe_(options_.offboard_timeout_s, options_.offboard_hold_s),
      neighbours_(options_.self, options_.neighbours) {
  if (options_.period_steps < 1) options_.period_steps = 1;
}

void BrainHost::OnMessage(const bus::BrainMessage& message) { messages_.push_back(MessageFromBus(message)); }

void BrainHost::OnState(const bus::DroneState& state) { neighbours_.OnState(state); }

void BrainHost::OnFlightEvent(const flight::FlightEvent& event) { flight_events_.push_back(FlightEventOf(event)); }

void BrainHost::OnDetection(const brain::Detection& detection) { detections_.push_back(detection); }

void BrainHost::Log(const LogEvent& e) {
  if (log_ == nullptr) return;
  std::fprintf(log_, "%s\n", e.str().c_str());
  std::fflush(log_);
}

void BrainHost::Reject(double t_s, const std::string& what, const std::string& reason) {
  Log(LogEvent(t_s, options_.self, "brain_rejected").Add("what", what).Add("reason", reason));
}

void BrainHost::BuildInput(std::int64_t t_ns, const brain::Vehicle& vehicle) {
  in_ = brain::Input{};
  in_.t_ns = t_ns;
  in_.self = vehicle;
  in_.self.name = options_.self;
  in_.self.payload_mass_kg = payload_mass_kg_;
  committed_.clear();
  if (consensus_ != nullptr) {
    in_.is_leader = consensus_->is_leader();
    in_.leader = consensus_->leader();
    consensus_->TakeCommitted(&committed_);
  }
  in_.flight_events = flight_events_;
  in_.neighbours = neighbours_.List(t_ns, vehicle.position_m);
  in_.messages = messages_;
  in_.committed = committed_;
  in_.detections = detections_;
  in_.state = options_.state;
}

void BrainHost::ApplyCommand(const brain::Command& c, std::int64_t t_ns, std::vector<bus::WorldCommand>* world) {
  const double t_s = Seconds(t_ns);
  switch (c.kind) {
    case brain::Command::Kind::kTakeoff:
      (void)flight_.Command(flight::Setpoint::Takeoff(c.param));  // a rejection is a flight event
      return;
    case brain::Command::Kind::kLand:
      (void)flight_.Command(flight::Setpoint::Land());
      return;
    case brain::Command::Kind::kHold:
      (void)flight_.Command(flight::Setpoint::Hold());
      return;
    case brain::Command::Kind::kArm:
      Reject(t_s, "arm", "the flight stack arms on takeoff");
      return;
    case brain::Command::Kind::kDisarm:
      Reject(t_s, "disarm", "the flight stack disarms when it has landed");
      return;
    case brain::Command::Kind::kPayloadAttach:
    case brain::Command::Kind::kPayloadRelease: {
      const bool attach = c.kind == brain::Command::Kind::kPayloadAttach;
      if (attach && !(std::isfinite(c.param) && c.param >= 0.0)) {
        Reject(t_s, "payload_attach", "mass_kg must be finite and >= 0");
        return;
      }
      bus::WorldCommand w;
      w.seq = ++world_seq_;
      w.sim_time_ns = t_ns;
      w.target = options_.self;
      w.command = attach ? "payload_attach" : "payload_release";
      if (attach) w.args.push_back(c.param);
      world->push_back(std::move(w));  // applied by the physics server before it steps the world
      payload_mass_kg_ = attach ? c.param : 0.0;
      // The announced load as the hover thrust estimator's prior (it corrects a refused hook).
      flight_.SetPayloadMass(payload_mass_kg_);
      return;
    }
  }
}

void BrainHost::Fly(std::int64_t t_ns, std::vector<bus::WorldCommand>* world) {
  for (const brain::Command& c : out_.commands) ApplyCommand(c, t_ns, world);
  if (!out_.commands.empty()) has_flown_ = false;  // a command replaced what was flying
  if (out_.setpoint.empty()) return;
  if (out_.setpoint.size() > 1)
    Reject(Seconds(t_ns), "setpoint", "more than one setpoint; the first is flown");
  const brain::Setpoint& sp = out_.setpoint.front();
  // The same setpoint streamed again (PX4 offboard style) keeps flying the one commanded:
  // commanding it anew would restart the position trajectory at every period.
  if (!has_flown_ || !SameSetpoint(sp, flown_)) {
    has_flown_ = flight_.Command(FlightSetpointOf(sp));
    flown_ = sp;
  }
}

void BrainHost::SendMessages(double t_s) {
  for (const brain::Message& m : out_.messages) {
    if (radio_ == nullptr) {
      if (!warned_radio_) Reject(t_s, "message", "no radio (--no-mesh)");
      warned_radio_ = true;
      break;
    }
    bus::RadioFrame f;
    f.to = m.to;
    bus::BrainMessage b = MessageToBus(m);
    b.from = options_.self;
    f.brain_msg.push_back(std::move(b));
    radio_->Send(std::move(f));  // best effort, as the radio
  }
}

void BrainHost::Propose(double t_s) {
  for (const std::vector<std::uint8_t>& p : out_.proposals) {
    if (consensus_ == nullptr) {
      if (!warned_consensus_) Reject(t_s, "proposal", "no consensus (--members)");
      warned_consensus_ = true;
      break;
    }
    if (p.empty()) {
      Reject(t_s, "proposal", "empty");
      continue;
    }
    (void)consensus_->Propose(p);  // not accepted (no leader yet): the brain re-proposes
  }
}

void BrainHost::Apply(std::int64_t t_ns, std::vector<bus::WorldCommand>* world, bool fly) {
  const double t_s = Seconds(t_ns);
  if (fly) Fly(t_ns, world);
  SendMessages(t_s);
  Propose(t_s);
  status_ = out_.status;
  for (const brain::Event& e : out_.events) {
    LogEvent line(t_s, options_.self, e.name);
    for (const auto& [k, v] : e.fields) line.Add(k, v);
    Log(line);
  }
}

bool BrainHost::StepBrain(std::int64_t t_ns, const brain::Vehicle& vehicle) {
  BuildInput(t_ns, vehicle);
  out_.Clear();
  bool answered = false;
  if (!failed_) {
    try {
      brain_->Step(in_, out_);
      ++brain_steps_;
      answered = remote_ == nullptr || remote_->answered();
    } catch (const std::exception& e) {
      // A broken contract (Step must not throw): the brain is not called again, its state is
      // unknown; the offboard failsafe brings the drone down.
      failed_ = true;
      Log(LogEvent(Seconds(t_ns), options_.self, "brain_failed").Add("reason", e.what()));
    } catch (...) {
      failed_ = true;
      Log(LogEvent(Seconds(t_ns), options_.self, "brain_failed").Add("reason", "a non-standard exception"));
    }
  }
  flight_events_.clear();
  messages_.clear();
  detections_.clear();
  return answered;
}

namespace {

// A failsafe event as the brain sees it among its flight events.
brain::FlightEvent FailsafeFlightEvent(const flight::OffboardFailsafe::Event& e) {
  brain::FlightEvent fe;
  fe.name = std::string(flight::OffboardFailsafe::EventName(e.kind));
  fe.t_ns = std::llround(e.t_s * 1e9);
  fe.fields["silent_s"] = FormatFixed(e.silent_s, 3);
  fe.fields["action"] = std::string(flight::OffboardFailsafe::ActionName(e.action));
  return fe;
}

}  // namespace

flight::OffboardFailsafe::Action BrainHost::UpdateFailsafe(double t_s, bool answered, bool landed) {
  using Action = flight::OffboardFailsafe::Action;
  const Action before = failsafe_.action();
  const Action action = failsafe_.Update(t_s, answered);
  flight::OffboardFailsafe::Event e;
  while (failsafe_.PopEvent(&e)) {
    Log(flight::OffboardFailsafe::ToLogEvent(e, options_.self));
    flight_events_.push_back(FailsafeFlightEvent(e));
  }
  if (action != before) has_flown_ = false;  // the failsafe took over (or gave back)
  if (action != before && !landed) {         // on the ground there is nothing to hold or land
    if (action == Action::kHold) (void)flight_.Command(flight::Setpoint::Hold());
    if (action == Action::kLand) (void)flight_.Command(flight::Setpoint::Land());
  }
  return action;
}

void BrainHost::Step(std::uint64_t step, std::int64_t t_ns, const brain::Vehicle& vehicle,
                     std::vector<bus::WorldCommand>* world) {
  const bool period = step % static_cast<std::uint64_t>(options_.period_steps) == 0;
  const bool answered = period && StepBrain(t_ns, vehicle);
  const auto action = UpdateFailsafe(Seconds(t_ns), answered, vehicle.landed);
  if (answered) {
    ++answers_;
    Apply(t_ns, world, action == flight::OffboardFailsafe::Action::kNone);
  }
}

}  // namespace swarmbox::agent
