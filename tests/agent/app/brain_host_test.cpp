// BrainHost without DDS: a scripted brain, a fake flight stack and consensus, a ChannelRadio.
// Input assembly (neighbours sorted and newest, the inbox since the previous Step, decimation),
// Output application (commands in order, then the setpoint; payload world commands; radio frames;
// proposals; status; events), the offboard failsafe on a silent brain (hold, then land; regained),
// and determinism (the same steps give the same lines, commands and frames).
#include "brain_host.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <functional>
#include <stdexcept>
#include <string>
#include <vector>

#include "swarmbox/radio/channel_radio.hpp"

namespace swarmbox::agent {
namespace {

constexpr std::int64_t kStepNs = 4'000'000;

class FakeFlight final : public FlightPort {
 public:
  bool Command(const flight::Setpoint& sp) override {
    std::string s;
    switch (sp.kind) {
      case flight::Setpoint::Kind::kTakeoff: s = "takeoff:" + std::to_string(static_cast<int>(sp.value.z())); break;
      case flight::Setpoint::Kind::kPosition: s = "position"; break;
      case flight::Setpoint::Kind::kVelocity: s = "velocity"; break;
      case flight::Setpoint::Kind::kHold: s = "hold"; break;
      case flight::Setpoint::Kind::kLand: s = "land"; break;
      case flight::Setpoint::Kind::kTrajectory: s = "trajectory"; break;
    }
    commands.push_back(s);
    setpoints.push_back(sp);
    return true;
  }
  void SetPayloadMass(double kg) override { masses.push_back(kg); }
  std::vector<std::string> commands;
  std::vector<flight::Setpoint> setpoints;
  std::vector<double> masses;
};

class FakeConsensus final : public ConsensusPort {
 public:
  bool is_leader() const override { return leading; }
  std::string leader() const override { return leader_name; }
  void TakeCommitted(std::vector<brain::Entry>* out) override {
    out->insert(out->end(), pending.begin(), pending.end());
    pending.clear();
  }
  bool Propose(std::span<const std::uint8_t> data) override {
    proposals.emplace_back(data.begin(), data.end());
    return true;
  }
  bool leading = false;
  std::string leader_name;
  std::vector<brain::Entry> pending;
  std::vector<std::vector<std::uint8_t>> proposals;
};

// What a brain saw at one Step, copied out of the spans.
struct Seen {
  std::int64_t t_ns = 0;
  brain::Vehicle self;
  std::vector<std::string> events, neighbours, messages, detections;
  std::vector<std::uint64_t> committed;
  bool is_leader = false;
  std::string leader;
};

class ScriptBrain : public RemoteBrain {
 public:
  using Script = std::function<void(const brain::Input&, brain::Output&)>;
  ScriptBrain(std::vector<Seen>* seen, Script script, std::function<bool(std::int64_t)> answers = {})
      : seen_(seen), script_(std::move(script)), answers_(std::move(answers)) {}
  void Step(const brain::Input& in, brain::Output& out) override {
    answered_ = !answers_ || answers_(in.t_ns);
    if (!answered_) return;
    Seen s;
    s.t_ns = in.t_ns;
    s.self = in.self;
    for (const brain::FlightEvent& e : in.flight_events) s.events.push_back(e.name);
    for (const brain::Neighbour& n : in.neighbours) s.neighbours.push_back(n.name + "@" + std::to_string(n.t_ns) + ":" + n.status);
    for (const brain::Message& m : in.messages) s.messages.push_back(m.from + ":" + m.topic);
    for (const brain::Detection& d : in.detections) s.detections.push_back(d.label);
    for (const brain::Entry& e : in.committed) s.committed.push_back(e.index);
    s.is_leader = in.is_leader;
    s.leader = in.leader;
    if (seen_ != nullptr) seen_->push_back(std::move(s));
    if (script_) script_(in, out);
  }
  bool answered() const override { return answered_; }

 private:
  std::vector<Seen>* seen_;
  Script script_;
  std::function<bool(std::int64_t)> answers_;
  bool answered_ = true;
};

// Captures the host's log lines.
class Lines {
 public:
  Lines() : file_(std::tmpfile()) {}
  ~Lines() { std::fclose(file_); }
  std::FILE* file() { return file_; }
  std::vector<std::string> Read() {
    std::fflush(file_);
    std::rewind(file_);
    std::vector<std::string> out;
    char buf[1024];
    while (std::fgets(buf, sizeof buf, file_) != nullptr) {
      std::string l(buf);
      if (!l.empty() && l.back() == '\n') l.pop_back();
      out.push_back(l);
    }
    return out;
  }
  std::vector<std::string> Events() {
    std::vector<std::string> out;
    for (const std::string& l : Read()) {
      const auto at = l.find("event=");
      out.push_back(l.substr(at + 6, l.find(' ', at) - at - 6));
    }
    return out;
  }

 private:
  std::FILE* file_;
};

brain::Vehicle Airborne() {
  brain::Vehicle v;
  v.name = "scout_1";
  v.flight_mode = "hold";
  v.armed = true;
  v.landed = false;
  v.position_m = {1, 2, 10};
  return v;
}

bus::DroneState State(const std::string& drone, std::int64_t t_ns, const std::string& mode) {
  bus::DroneState s;
  s.drone = drone;
  s.sim_time_ns = t_ns;
  s.mode = mode;
  return s;
}

struct Rig {
  FakeFlight flight;
  FakeConsensus consensus;
  radio::ChannelRadio radio{"scout_1"};
  Lines lines;
  std::vector<Seen> seen;
  std::vector<bus::WorldCommand> world;
  std::unique_ptr<BrainHost> host;

  std::size_t max_neighbours = 32;
  void Make(std::unique_ptr<brain::Brain> b, int period = 1, double timeout_s = 1.0, double hold_s = 5.0) {
    BrainHostOptions o;
    o.self = "scout_1";
    o.neighbours.max_listed = max_neighbours;
    o.period_steps = period;
    o.offboard_timeout_s = timeout_s;
    o.offboard_hold_s = hold_s;
    host = std::make_unique<BrainHost>(o, std::move(b), flight, &radio, &consensus, lines.file());
  }
  void Step(std::uint64_t k, const brain::Vehicle& v = Airborne()) {
    bus::SensorSample sample;
    sample.sim_time_ns = static_cast<std::int64_t>(k) * kStepNs;
    std::vector<bus::RadioFrame> in;
    radio.TakeReceived(sample, &in);  // the radio's clock: this step
    host->Step(k, static_cast<std::int64_t>(k) * kStepNs, v, &world);
  }
};

TEST(BrainHost, AssemblesTheInputFromTheInboxSinceThePreviousStep) {
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, nullptr));
  rig.consensus.leading = true;
  rig.consensus.leader_name = "scout_1";
  rig.consensus.pending = {{3, {1}}, {5, {2}}};
  rig.host->OnState(State("scout_3", 1'000, "rv/voting"));
  rig.host->OnState(State("lifter", 2'000, "rv/takeoff"));
  rig.host->OnState(State("scout_3", 500, "stale"));     // older than what we have: ignored
  rig.host->OnState(State("scout_1", 3'000, "ours"));    // our own: not a neighbour
  rig.host->OnMessage({"scout_3", "", "rv/a", {1}});
  rig.host->OnMessage({"lifter", "scout_1", "rv/b", {2}});
  flight::FlightEvent hover;
  hover.kind = flight::FlightEventKind::kHover;
  hover.t_s = 0.0;
  rig.host->OnFlightEvent(hover);
  rig.host->OnDetection({0, "victim", 0.9, {4, 5, 0}, 1.5});
  rig.Step(0);
  ASSERT_EQ(rig.seen.size(), 1u);
  const Seen& s = rig.seen[0];
  EXPECT_EQ(s.self.name, "scout_1");
  EXPECT_EQ(s.self.position_m.z, 10.0);
  EXPECT_EQ(s.events, std::vector<std::string>{"hover"});
  EXPECT_EQ(s.neighbours, (std::vector<std::string>{"lifter@2000:rv/takeoff", "scout_3@1000:rv/voting"}));
  EXPECT_EQ(s.messages, (std::vector<std::string>{"scout_3:rv/a", "lifter:rv/b"}));
  EXPECT_EQ(s.detections, std::vector<std::string>{"victim"});
  EXPECT_EQ(s.committed, (std::vector<std::uint64_t>{3, 5}));
  EXPECT_TRUE(s.is_leader);
  EXPECT_EQ(s.leader, "scout_1");
  // The next Step: the inbox was handed over; the neighbour table stays (newest per drone).
  rig.host->OnState(State("scout_3", 4'000, "rv/flying"));
  rig.Step(1);
  ASSERT_EQ(rig.seen.size(), 2u);
  EXPECT_TRUE(rig.seen[1].events.empty());
  EXPECT_TRUE(rig.seen[1].messages.empty());
  EXPECT_TRUE(rig.seen[1].detections.empty());
  EXPECT_TRUE(rig.seen[1].committed.empty());
  EXPECT_EQ(rig.seen[1].neighbours, (std::vector<std::string>{"lifter@2000:rv/takeoff", "scout_3@4000:rv/flying"}));
  EXPECT_EQ(rig.seen[1].t_ns, kStepNs);
}

TEST(BrainHost, HandsTheBrainAtMostBrainNeighboursOfTheNearestSortedByName) {
  Rig rig;
  rig.max_neighbours = 2;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, nullptr));
  // scout_1 is at (1, 2, 10) (Airborne): c is 3 m away, a 5 m, b 40 m.
  auto at = [](const std::string& name, double x) {
    bus::DroneState s = State(name, 1'000, "m");
    s.position_enu_m = {x, 2, 10};
    return s;
  };
  rig.host->OnState(at("b", 41));
  rig.host->OnState(at("a", 6));
  rig.host->OnState(at("c", -2));
  rig.Step(0);
  ASSERT_EQ(rig.seen.size(), 1u);
  EXPECT_EQ(rig.seen[0].neighbours, (std::vector<std::string>{"a@1000:m", "c@1000:m"}));
  EXPECT_EQ(rig.host->neighbours().size(), 3u);  // the table knows every drone heard
}

TEST(BrainHost, RunsTheBrainEveryPeriodAndKeepsTheEventsInBetween) {
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, nullptr), 5);
  for (std::uint64_t k = 0; k <= 10; ++k) {
    if (k == 2 || k == 3) {
      flight::FlightEvent e;
      e.kind = k == 2 ? flight::FlightEventKind::kTakeoff : flight::FlightEventKind::kHover;
      e.t_s = static_cast<double>(k) * 0.004;
      rig.host->OnFlightEvent(e);
    }
    rig.Step(k);
  }
  ASSERT_EQ(rig.seen.size(), 3u);
  EXPECT_EQ(rig.seen[0].t_ns, 0);
  EXPECT_EQ(rig.seen[1].t_ns, 5 * kStepNs);
  EXPECT_EQ(rig.seen[2].t_ns, 10 * kStepNs);
  EXPECT_EQ(rig.seen[1].events, (std::vector<std::string>{"takeoff", "hover"}));
  EXPECT_TRUE(rig.seen[2].events.empty());
  EXPECT_EQ(rig.host->brain_steps(), 3u);
  // An in-process brain answers at every period: no failsafe between them.
  EXPECT_EQ(rig.host->failsafe(), flight::OffboardFailsafe::Action::kNone);
}

TEST(BrainHost, AppliesCommandsInOrderThenTheSetpointAndTheRest) {
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, [](const brain::Input& in, brain::Output& out) {
    if (in.t_ns != 0) return;
    out.setpoint.push_back(brain::Setpoint::Position({10, 0, 5}));
    out.commands = {brain::Command::Takeoff(5), brain::Command::PayloadAttach(2.5), brain::Command::Hold(),
                    brain::Command::PayloadRelease(), {brain::Command::Kind::kArm, 0.0}};
    out.messages.push_back({"", "", "rv/vote", {9, 9}});
    out.messages.push_back({"", "lifter", "rv/ack", {1}});
    out.proposals = {{'p', 'o', 's'}, {}};
    out.status = "rv/voting";
    out.events.push_back({"rendezvous_point", {{"x", "1.500"}, {"y", "-2.000"}}});
  }));
  rig.Step(0);
  EXPECT_EQ(rig.flight.commands, (std::vector<std::string>{"takeoff:5", "hold", "position"}));
  EXPECT_EQ(rig.flight.setpoints.back().value.x(), 10.0);
  EXPECT_EQ(rig.flight.masses, (std::vector<double>{2.5, 0.0}));
  ASSERT_EQ(rig.world.size(), 2u);
  EXPECT_EQ(rig.world[0].command, "payload_attach");
  EXPECT_EQ(rig.world[0].target, "scout_1");
  EXPECT_EQ(rig.world[0].args, std::vector<double>{2.5});
  EXPECT_EQ(rig.world[1].command, "payload_release");
  EXPECT_LT(rig.world[0].seq, rig.world[1].seq);
  EXPECT_EQ(rig.host->payload_mass_kg(), 0.0);
  bus::ActuatorCommand cmd;
  rig.radio.Flush(&cmd);
  ASSERT_EQ(cmd.radio_out.size(), 2u);
  EXPECT_EQ(cmd.radio_out[0].to, "");
  EXPECT_EQ(cmd.radio_out[0].brain_msg.at(0).from, "scout_1");
  EXPECT_EQ(cmd.radio_out[0].brain_msg.at(0).topic, "rv/vote");
  EXPECT_EQ(cmd.radio_out[1].to, "lifter");
  EXPECT_EQ(cmd.radio_out[1].brain_msg.at(0).payload, std::vector<std::uint8_t>{1});
  EXPECT_EQ(rig.consensus.proposals, (std::vector<std::vector<std::uint8_t>>{{'p', 'o', 's'}}));
  EXPECT_EQ(rig.host->status(), "rv/voting");
  const std::vector<std::string> lines = rig.lines.Read();
  ASSERT_EQ(lines.size(), 3u);
  EXPECT_EQ(lines[0], "t=0.000 node=scout_1 event=brain_rejected what=arm reason=\"the flight stack arms on takeoff\"");
  EXPECT_EQ(lines[1], "t=0.000 node=scout_1 event=brain_rejected what=proposal reason=empty");
  EXPECT_EQ(lines[2], "t=0.000 node=scout_1 event=rendezvous_point x=1.500 y=-2.000");
  // The next Step's Input carries the attached load the brain asked for (released again here).
  rig.Step(1);
  EXPECT_EQ(rig.seen[1].self.payload_mass_kg, 0.0);
}

TEST(BrainHost, FliesAMixedSetpointAsATrajectory) {
  const flight::Setpoint pos = FlightSetpointOf(brain::Setpoint::Position({1, 2, 3}, 0.5));
  EXPECT_EQ(pos.kind, flight::Setpoint::Kind::kPosition);
  EXPECT_EQ(pos.value.y(), 2.0);
  brain::Setpoint mixed;
  mixed.position_m = {1, 2, brain::kUnset};
  mixed.velocity_m_s = {brain::kUnset, brain::kUnset, 0.5};
  const flight::Setpoint t = FlightSetpointOf(mixed);
  EXPECT_EQ(t.kind, flight::Setpoint::Kind::kTrajectory);
  EXPECT_EQ(t.trajectory.pos_m.x(), 1.0);
  EXPECT_TRUE(std::isnan(t.trajectory.pos_m.z()));
  EXPECT_EQ(t.trajectory.vel_m_s.z(), 0.5);
}

TEST(BrainHost, HoldsThenLandsWhenTheBrainFallsSilent) {
  // Answers until t = 2 s, then never again: lost after the 1 s timeout (hold), landing 2 s
  // later (hold_s 2); its outputs are not flown meanwhile.
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(
               &rig.seen, [](const brain::Input&, brain::Output& out) { out.setpoint.push_back(brain::Setpoint::Velocity({1, 0, 0})); },
               [](std::int64_t t_ns) { return t_ns <= 2'000'000'000; }),
           5, 1.0, 2.0);
  for (std::uint64_t k = 0; k <= 2000; ++k) rig.Step(k);  // 8 s
  const std::vector<std::string> events = rig.lines.Events();
  EXPECT_EQ(events, (std::vector<std::string>{"offboard_lost", "offboard_failsafe"}));
  const std::vector<std::string> lines = rig.lines.Read();
  EXPECT_NE(lines[0].find("t=3.0"), std::string::npos) << lines[0];
  EXPECT_NE(lines[0].find("action=hold"), std::string::npos) << lines[0];
  EXPECT_NE(lines[1].find("t=5.0"), std::string::npos) << lines[1];
  EXPECT_NE(lines[1].find("action=land"), std::string::npos) << lines[1];
  // The streamed velocity was commanded once (the same one again keeps flying); then hold, land.
  EXPECT_EQ(rig.flight.commands, (std::vector<std::string>{"velocity", "hold", "land"}));
  EXPECT_EQ(rig.host->failsafe(), flight::OffboardFailsafe::Action::kLand);
}

TEST(BrainHost, FliesAgainWhenTheBrainAnswersDuringTheHold) {
  Rig rig;
  std::vector<Seen> seen;
  rig.Make(std::make_unique<ScriptBrain>(
               &seen, [](const brain::Input&, brain::Output& out) { out.setpoint.push_back(brain::Setpoint::Velocity({1, 0, 0})); },
               [](std::int64_t t_ns) { return t_ns < 1'000'000'000 || t_ns >= 2'500'000'000; }),
           1, 1.0, 5.0);
  for (std::uint64_t k = 0; k <= 750; ++k) rig.Step(k);  // 3 s
  EXPECT_EQ(rig.lines.Events(), (std::vector<std::string>{"offboard_lost", "offboard_regained"}));
  EXPECT_EQ(rig.host->failsafe(), flight::OffboardFailsafe::Action::kNone);
  // The brain hears about it as a flight event (offboard_lost went out in an input it left
  // unanswered: a silent brain's inbox is not kept for it).
  std::vector<std::string> brain_events;
  for (const Seen& s : seen) brain_events.insert(brain_events.end(), s.events.begin(), s.events.end());
  EXPECT_EQ(brain_events, (std::vector<std::string>{"offboard_regained"}));
  // Flown again after the failsafe's hold: the same velocity is commanded anew.
  EXPECT_EQ(rig.flight.commands, (std::vector<std::string>{"velocity", "hold", "velocity"}));
}

TEST(BrainHost, CommandsAStreamedSetpointOnceUntilItChangesOrACommandComes) {
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, [](const brain::Input& in, brain::Output& out) {
    const std::int64_t k = in.t_ns / kStepNs;
    if (k == 3) out.commands.push_back(brain::Command::Hold());
    brain::Setpoint sp = brain::Setpoint::Position({k < 5 ? 1.0 : 2.0, 0, brain::kUnset});
    out.setpoint.push_back(sp);
  }));
  for (std::uint64_t k = 0; k < 8; ++k) rig.Step(k);
  EXPECT_EQ(rig.flight.commands, (std::vector<std::string>{"trajectory", "hold", "trajectory", "trajectory"}));
  EXPECT_TRUE(SameSetpoint(brain::Setpoint{}, brain::Setpoint{}));
  EXPECT_FALSE(SameSetpoint(brain::Setpoint{}, brain::Setpoint::Velocity({0, 0, 0})));
}

TEST(BrainHost, ABrainThatThrowsIsNotCalledAgainAndTheFailsafeLands) {
  Rig rig;
  int calls = 0;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, [&calls](const brain::Input& in, brain::Output& out) {
    ++calls;
    if (in.t_ns >= 1'000'000'000) throw std::runtime_error("division by zero in the flocking law");
    out.setpoint.push_back(brain::Setpoint::Velocity({1, 0, 0}));
  }), 5, 1.0, 1.0);
  for (std::uint64_t k = 0; k <= 1000; ++k) rig.Step(k);  // 4 s
  EXPECT_EQ(calls, 51);  // t = 0 .. 1 s every 20 ms; never after the throw
  EXPECT_TRUE(rig.host->failed());
  EXPECT_EQ(rig.lines.Events(), (std::vector<std::string>{"brain_failed", "offboard_lost", "offboard_failsafe"}));
  EXPECT_NE(rig.lines.Read()[0].find("reason=\"division by zero in the flocking law\""), std::string::npos);
  EXPECT_EQ(rig.flight.commands, (std::vector<std::string>{"velocity", "hold", "land"}));
}

TEST(BrainHost, OnTheGroundTheFailsafeCommandsNothing) {
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(&rig.seen, nullptr, [](std::int64_t) { return false; }), 1, 1.0, 1.0);
  brain::Vehicle landed;
  landed.flight_mode = "idle";
  for (std::uint64_t k = 0; k <= 1000; ++k) rig.Step(k, landed);
  EXPECT_EQ(rig.lines.Events(), (std::vector<std::string>{"offboard_lost", "offboard_failsafe"}));
  EXPECT_TRUE(rig.flight.commands.empty());
}

// A brain whose output depends on everything it is handed.
void Chatty(const brain::Input& in, brain::Output& out) {
  const std::uint64_t k = static_cast<std::uint64_t>(in.t_ns / kStepNs);
  if (k % 7 == 0) out.messages.push_back({"", "", "t", {static_cast<std::uint8_t>(k), static_cast<std::uint8_t>(in.neighbours.size())}});
  if (k % 11 == 0) out.proposals.push_back({static_cast<std::uint8_t>(in.committed.size() + 1)});
  if (k % 13 == 0) out.events.push_back({"tick", {{"k", std::to_string(k)}, {"msgs", std::to_string(in.messages.size())}}});
  out.setpoint.push_back(brain::Setpoint::Position({static_cast<double>(k % 5), 0, 10}));
  out.status = "s" + std::to_string(k % 3);
}

struct Trace {
  std::vector<std::string> lines, commands;
  std::vector<bus::RadioFrame> frames;
  std::vector<std::vector<std::uint8_t>> proposals;
};

Trace RunChatty() {
  Rig rig;
  rig.Make(std::make_unique<ScriptBrain>(nullptr, Chatty), 2);
  Trace t;
  for (std::uint64_t k = 0; k < 500; ++k) {
    if (k % 9 == 0) rig.host->OnState(State(k % 2 ? "b" : "a", static_cast<std::int64_t>(k) * kStepNs, "x"));
    if (k % 4 == 0) rig.host->OnMessage({"b", "", "m", {1}});
    if (k % 25 == 0) rig.consensus.pending.push_back({k + 1, {2}});
    rig.Step(k);
    bus::ActuatorCommand cmd;
    rig.radio.Flush(&cmd);
    t.frames.insert(t.frames.end(), cmd.radio_out.begin(), cmd.radio_out.end());
  }
  t.lines = rig.lines.Read();
  t.commands = rig.flight.commands;
  t.proposals = rig.consensus.proposals;
  return t;
}

TEST(BrainHost, TheSameStepsGiveTheSameRun) {
  const Trace a = RunChatty();
  const Trace b = RunChatty();
  EXPECT_FALSE(a.lines.empty());
  EXPECT_FALSE(a.frames.empty());
  EXPECT_FALSE(a.proposals.empty());
  EXPECT_EQ(a.lines, b.lines);
  EXPECT_EQ(a.commands, b.commands);
  EXPECT_EQ(a.frames, b.frames);
  EXPECT_EQ(a.proposals, b.proposals);
}

TEST(BrainHost, FlightEventsCarryTheirNameTimeAndPlace) {
  flight::FlightEvent e;
  e.kind = flight::FlightEventKind::kModeChange;
  e.mode = flight::FlightMode::kHold;
  e.t_s = 1.236;
  e.pos_m = flight::Vec3(1.0, -2.5, 10.004);
  const brain::FlightEvent b = FlightEventOf(e);
  EXPECT_EQ(b.name, "mode");  // flight::FlightEventName(kModeChange)
  EXPECT_EQ(b.t_ns, 1'236'000'000);
  EXPECT_EQ(b.fields.at("mode"), "hold");
  EXPECT_EQ(b.fields.at("y"), "-2.50");
  EXPECT_EQ(b.fields.at("z"), "10.00");
}

}  // namespace
}  // namespace swarmbox::agent
