// The example rendezvous brain (examples/brains/rendezvous) on a tiny deterministic world:
// N brains stepped on simulated time, a perfect in-memory consensus log (every proposal of a step
// committed in drone order, delivered to every drone at the next step) and an ideal point-mass
// flight (take-off and position targets approached at 5 m/s, `hover` on reaching the take-off
// height, `landed` on the ground after `land`). Checks the protocol end to end: everyone reaches
// its slot on the ring, logs rendezvous_complete once, and two runs are bit-identical.
#include "rendezvous_brain.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>
#include <vector>

namespace rendezvous {
namespace {

namespace sb = swarmbox::brain;

constexpr std::int64_t kPeriodNs = 20'000'000;  // brain at 50 Hz
constexpr double kSpeedMS = 5.0;
constexpr std::int64_t kInitNs = 500'000'000;   // the estimator is "init" for the first 0.5 s

// Ideal flight: moves straight at kSpeedMS towards its target.
struct IdealFlight {
  enum class Mode { kGround, kTakeoff, kHold, kPosition, kLand };
  sb::Vec3 position;
  sb::Vec3 target;
  Mode mode = Mode::kGround;
  std::vector<sb::FlightEvent> events;  // since the brain's previous Step

  std::string ModeName(std::int64_t t_ns) const {
    switch (mode) {
      case Mode::kGround: return t_ns < kInitNs ? "init" : "idle";
      case Mode::kTakeoff: return "takeoff";
      case Mode::kHold: return "hold";
      case Mode::kPosition: return "position";
      case Mode::kLand: return "land";
    }
    return "?";
  }
  void Emit(const char* name, std::int64_t t_ns) { events.push_back({name, t_ns, {}}); }

  void Apply(const sb::Output& out, std::int64_t t_ns) {
    for (const sb::Command& c : out.commands) {
      if (c.kind == sb::Command::Kind::kTakeoff && mode == Mode::kGround && t_ns >= kInitNs) {
        mode = Mode::kTakeoff;
        target = {position.x, position.y, c.param};
        Emit("takeoff", t_ns);
      } else if (c.kind == sb::Command::Kind::kLand && mode != Mode::kGround) {
        mode = Mode::kLand;
        target = {position.x, position.y, 0.0};
        Emit("landing", t_ns);
      } else {
        Emit("setpoint_rejected", t_ns);
      }
    }
    for (const sb::Setpoint& sp : out.setpoint) {
      if (mode == Mode::kHold || mode == Mode::kPosition) {
        mode = Mode::kPosition;
        target = sp.position_m;
      } else {
        Emit("setpoint_rejected", t_ns);
      }
    }
  }

  void Move(double dt_s, std::int64_t t_ns) {
    if (mode == Mode::kGround || mode == Mode::kHold) return;
    const double dx = target.x - position.x, dy = target.y - position.y, dz = target.z - position.z;
    const double d = std::sqrt(dx * dx + dy * dy + dz * dz);
    const double step = kSpeedMS * dt_s;
    if (d > step) {
      position = {position.x + dx / d * step, position.y + dy / d * step, position.z + dz / d * step};
      return;
    }
    position = target;
    if (mode == Mode::kTakeoff) {
      mode = Mode::kHold;
      Emit("hover", t_ns);
    } else if (mode == Mode::kLand) {
      mode = Mode::kGround;
      Emit("landed", t_ns);
    } else if (mode == Mode::kPosition) {
      Emit("arrived", t_ns);
    }
  }
};

struct Drone {
  std::string name;
  std::unique_ptr<RendezvousBrain> brain;
  IdealFlight flight;
  std::string status;
  std::vector<sb::Event> events;
  std::vector<std::string> proposals;  // every proposal it made, as text
};

struct Outcome {
  std::vector<Drone> drones;
  std::string trace;         // every step's outputs and positions, floats in hex: bit-exact
  std::int64_t end_ns = 0;   // when the last drone logged rendezvous_complete (0: never)
};

std::string Hex(double v) {
  char buf[64];
  std::snprintf(buf, sizeof buf, "%a", v);
  return buf;
}

// N drones scout_1..scout_N at fixed, scattered starts. `lose_first`: the first proposal of every
// drone is lost (as on a leader change), so only re-proposals can commit.
Outcome RunSwarm(std::size_t n, bool lose_first = false, double limit_s = 200.0) {
  Outcome o;
  std::vector<std::string> members;
  for (std::size_t i = n; i >= 1; --i) members.push_back("scout_" + std::to_string(i));  // unsorted
  for (std::size_t i = 0; i < n; ++i) {
    Drone d;
    d.name = "scout_" + std::to_string(i + 1);
    sb::Context ctx;
    ctx.self = d.name;
    ctx.members = members;
    ctx.period_ns = kPeriodNs;
    ctx.args = {{"altitude_m", "8"}, {"radius_m", "5"}, {"hold_s", "2"}};
    d.brain = std::make_unique<RendezvousBrain>(ctx);
    const double fi = static_cast<double>(i);
    d.flight.position = {-20.0 + 13.7 * fi, 4.0 * std::sin(fi) + 3.1 * fi, 0.0};
    o.drones.push_back(std::move(d));
  }

  std::vector<sb::Entry> committed_next;
  std::vector<bool> lost(n, false);
  std::uint64_t index = 0;
  std::size_t completed = 0;
  const auto steps = static_cast<std::int64_t>(limit_s * 1e9) / kPeriodNs;
  for (std::int64_t k = 1; k <= steps && completed < n; ++k) {
    const std::int64_t t_ns = k * kPeriodNs;
    const std::vector<sb::Entry> committed = std::move(committed_next);
    committed_next.clear();
    o.trace += "t=" + std::to_string(t_ns);
    for (std::size_t i = 0; i < n; ++i) {
      Drone& d = o.drones[i];
      sb::Input in;
      in.t_ns = t_ns;
      in.self.name = d.name;
      in.self.step = static_cast<std::uint64_t>(k);
      in.self.position_m = d.flight.position;
      in.self.flight_mode = d.flight.ModeName(t_ns);
      in.self.landed = d.flight.mode == IdealFlight::Mode::kGround;
      in.self.armed = !in.self.landed;
      const std::vector<sb::FlightEvent> events = std::move(d.flight.events);
      d.flight.events.clear();
      in.flight_events = events;
      in.is_leader = i == 0;
      in.leader = o.drones[0].name;
      in.committed = committed;
      sb::Output out;
      d.brain->Step(in, out);

      d.flight.Apply(out, t_ns);
      d.status = out.status;
      for (const auto& p : out.proposals) {
        d.proposals.emplace_back(p.begin(), p.end());
        if (lose_first && !lost[i]) {
          lost[i] = true;
          continue;
        }
        committed_next.push_back({++index, p});
      }
      for (const sb::Event& e : out.events) {
        d.events.push_back(e);
        if (e.name == "rendezvous_complete") ++completed;
      }
      o.trace += " " + d.name + ":" + out.status + ":" + std::to_string(out.commands.size()) + "c" +
                 std::to_string(out.proposals.size()) + "p" + std::to_string(out.events.size()) + "e";
      for (const auto& sp : out.setpoint) o.trace += "@" + Hex(sp.position_m.x) + "," + Hex(sp.position_m.y);
    }
    for (Drone& d : o.drones) {
      d.flight.Move(static_cast<double>(kPeriodNs) * 1e-9, t_ns);
      o.trace += " " + Hex(d.flight.position.x) + "," + Hex(d.flight.position.y) + "," + Hex(d.flight.position.z);
    }
    o.trace += "\n";
    if (completed == n) o.end_ns = t_ns;
  }
  return o;
}

const sb::Event* FindEvent(const Drone& d, const std::string& name) {
  for (const sb::Event& e : d.events) {
    if (e.name == name) return &e;
  }
  return nullptr;
}

std::size_t CountEvents(const Drone& d, const std::string& name) {
  return static_cast<std::size_t>(
      std::count_if(d.events.begin(), d.events.end(), [&](const sb::Event& e) { return e.name == name; }));
}

void ExpectRendezvous(const Outcome& o) {
  const std::size_t n = o.drones.size();
  ASSERT_GT(o.end_ns, 0) << "not every drone logged rendezvous_complete";
  const sb::Event* first_point = FindEvent(o.drones[0], "rendezvous_point");
  ASSERT_NE(first_point, nullptr);
  for (const Drone& d : o.drones) {
    SCOPED_TRACE(d.name);
    EXPECT_EQ(CountEvents(d, "rendezvous_point"), 1u);
    EXPECT_EQ(CountEvents(d, "rendezvous_complete"), 1u);
    const sb::Event* point = FindEvent(d, "rendezvous_point");
    ASSERT_NE(point, nullptr);
    EXPECT_EQ(point->fields, first_point->fields);  // the same point on every drone
    const sb::Event* done = FindEvent(d, "rendezvous_complete");
    ASSERT_NE(done, nullptr);
    EXPECT_EQ(done->fields, (std::vector<std::pair<std::string, std::string>>{{"members", std::to_string(n)}}));
    EXPECT_EQ(d.status, "rendezvous/done");
    EXPECT_EQ(d.flight.mode, IdealFlight::Mode::kGround);
    EXPECT_EQ(d.flight.position.z, 0.0);
    // Its proposals in protocol order: `pos <self> x y` (re-proposed unchanged), then `arrived <self>`.
    ASSERT_FALSE(d.proposals.empty());
    EXPECT_EQ(d.proposals.front().rfind("pos " + d.name + " ", 0), 0u) << d.proposals.front();
    EXPECT_EQ(d.proposals.back(), "arrived " + d.name);
  }
  // Every drone landed on its slot: P + r (cos a, sin a), a = 2 pi i / N, from the logged P.
  const double px = std::stod(first_point->fields[0].second);
  const double py = std::stod(first_point->fields[1].second);
  for (std::size_t i = 0; i < n; ++i) {
    SCOPED_TRACE(o.drones[i].name);
    const double a = 2.0 * std::numbers::pi * static_cast<double>(i) / static_cast<double>(n);
    EXPECT_NEAR(o.drones[i].flight.position.x, px + 5.0 * std::cos(a), 1.0);
    EXPECT_NEAR(o.drones[i].flight.position.y, py + 5.0 * std::sin(a), 1.0);
  }
}

class RendezvousSwarm : public ::testing::TestWithParam<std::size_t> {};

TEST_P(RendezvousSwarm, EveryDroneReachesItsSlotAndCompletes) {
  const Outcome o = RunSwarm(GetParam());
  ExpectRendezvous(o);
  // The point is the mean of the starts (straight take-offs), summed in sorted member order.
  double sx = 0.0, sy = 0.0;
  for (std::size_t i = 0; i < GetParam(); ++i) {
    const double fi = static_cast<double>(i);
    char bx[64], by[64];
    std::snprintf(bx, sizeof bx, "%.3f", -20.0 + 13.7 * fi);
    std::snprintf(by, sizeof by, "%.3f", 4.0 * std::sin(fi) + 3.1 * fi);
    sx += std::stod(bx);
    sy += std::stod(by);
  }
  const double n = static_cast<double>(GetParam());
  char ex[64], ey[64];
  std::snprintf(ex, sizeof ex, "%.3f", sx / n);
  std::snprintf(ey, sizeof ey, "%.3f", sy / n);
  const sb::Event* point = FindEvent(o.drones[0], "rendezvous_point");
  ASSERT_NE(point, nullptr);
  EXPECT_EQ(point->fields[0].second, ex);
  EXPECT_EQ(point->fields[1].second, ey);
  // Perfect log and ideal flight: nothing was re-proposed.
  for (const Drone& d : o.drones) EXPECT_EQ(d.proposals.size(), 2u) << d.name;
}

TEST_P(RendezvousSwarm, TwoRunsAreBitIdentical) {
  const Outcome a = RunSwarm(GetParam());
  const Outcome b = RunSwarm(GetParam());
  ASSERT_GT(a.end_ns, 0);
  EXPECT_EQ(a.end_ns, b.end_ns);
  EXPECT_EQ(a.trace, b.trace);
}

TEST_P(RendezvousSwarm, LostProposalsAreProposedAgainAfterTwoSeconds) {
  const Outcome o = RunSwarm(GetParam(), /*lose_first=*/true);
  ExpectRendezvous(o);
  for (const Drone& d : o.drones) {
    // pos lost once then re-proposed; arrived committed at the first try.
    ASSERT_EQ(d.proposals.size(), 3u) << d.name;
    EXPECT_EQ(d.proposals[0], d.proposals[1]) << d.name;
  }
  EXPECT_GT(o.end_ns, RunSwarm(GetParam()).end_ns + 2'000'000'000 - kPeriodNs);
}

INSTANTIATE_TEST_SUITE_P(ThreeToFiveDrones, RendezvousSwarm, ::testing::Values(3u, 4u, 5u));

TEST(RendezvousEntries, ParseWhatTheProtocolWritesAndNothingElse) {
  const std::vector<std::uint8_t> text = PosEntry("scout_2", -1.23456, 20.0);
  EXPECT_EQ(std::string(text.begin(), text.end()), "pos scout_2 -1.235 20.000");
  const auto pos = ParseEntry(text);
  ASSERT_TRUE(pos.has_value());
  EXPECT_EQ(pos->kind, Entry::Kind::kPos);
  EXPECT_EQ(pos->name, "scout_2");
  EXPECT_EQ(pos->x, -1.235);
  EXPECT_EQ(pos->y, 20.0);
  const auto arrived = ParseEntry(ArrivedEntry("scout_1"));
  ASSERT_TRUE(arrived.has_value());
  EXPECT_EQ(arrived->kind, Entry::Kind::kArrived);
  EXPECT_EQ(arrived->name, "scout_1");
  for (const char* bad : {"", "pos", "pos a 1", "pos a 1 2 3", "pos a x 2", "pos a 1 inf", "arrived",
                          "arrived a b", "victim 3 4"}) {
    const std::string entry = bad;
    EXPECT_FALSE(ParseEntry({entry.begin(), entry.end()}).has_value()) << bad;
  }
}

TEST(RendezvousBrainSteps, WaitsForTheEstimatorThenTakesOffOnce) {
  sb::Context ctx;
  ctx.self = "a";
  ctx.members = {"a", "b"};
  RendezvousBrain brain(ctx);
  sb::Input in;
  in.self.landed = true;
  in.self.flight_mode = "init";
  sb::Output out;
  brain.Step(in, out);
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(out.status, "rendezvous/takeoff");
  in.self.flight_mode = "idle";
  out.Clear();
  brain.Step(in, out);
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].kind, sb::Command::Kind::kTakeoff);
  EXPECT_EQ(out.commands[0].param, 10.0);  // altitude_m's default
  out.Clear();
  brain.Step(in, out);  // still on the ground, asked already
  EXPECT_TRUE(out.commands.empty());
  // A rejected take-off on the ground is asked again.
  const std::vector<sb::FlightEvent> rejected = {{"setpoint_rejected", 0, {}}};
  in.flight_events = rejected;
  out.Clear();
  brain.Step(in, out);
  EXPECT_EQ(out.commands.size(), 1u);
}

TEST(RendezvousBrainSteps, HoldAboveAltitudeCountsAsAirborneAndFirstPosPerMemberCounts) {
  sb::Context ctx;
  ctx.self = "b";
  ctx.members = {"b", "a"};
  ctx.args = {{"radius_m", "0"}};
  RendezvousBrain brain(ctx);
  sb::Input in;
  in.self.landed = true;
  in.self.flight_mode = "idle";
  sb::Output out;
  brain.Step(in, out);  // takeoff
  in.self.landed = false;
  in.self.flight_mode = "hold";
  in.self.position_m = {1.0, 2.0, 9.5};  // above altitude_m - 1 m
  out.Clear();
  brain.Step(in, out);
  EXPECT_EQ(out.status, "rendezvous/voting");
  ASSERT_EQ(out.proposals.size(), 1u);
  EXPECT_EQ(std::string(out.proposals[0].begin(), out.proposals[0].end()), "pos b 1.000 2.000");

  const std::vector<sb::Entry> log = {{1, PosEntry("a", 3.0, 4.0)}, {2, PosEntry("a", 100.0, 100.0)},
                                      {3, PosEntry("stranger", 0.0, 0.0)}, {4, PosEntry("b", 1.0, 2.0)}};
  in.committed = log;
  in.t_ns = 20'000'000;
  out.Clear();
  brain.Step(in, out);
  EXPECT_EQ(out.status, "rendezvous/flying");
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].name, "rendezvous_point");
  EXPECT_EQ(out.events[0].fields, (std::vector<std::pair<std::string, std::string>>{{"x", "2.000"}, {"y", "3.000"}}));
  ASSERT_EQ(out.setpoint.size(), 1u);
  EXPECT_EQ(out.setpoint[0].position_m.x, 2.0);  // radius 0: the point itself
  EXPECT_EQ(out.setpoint[0].position_m.y, 3.0);
  EXPECT_EQ(out.setpoint[0].position_m.z, 10.0);
  EXPECT_TRUE(std::isnan(out.setpoint[0].yaw_rad));
}

TEST(RendezvousBrainSteps, BadArgumentsThrow) {
  sb::Context ctx;
  ctx.self = "a";
  ctx.members = {"a"};
  ctx.args = {{"altitude_m", "0.5"}};
  EXPECT_THROW(RendezvousBrain{ctx}, std::invalid_argument);
  ctx.args = {{"hold_s", "-1"}};
  EXPECT_THROW(RendezvousBrain{ctx}, std::invalid_argument);
  ctx.args = {{"radius_m", "wide"}};
  EXPECT_THROW(RendezvousBrain{ctx}, std::invalid_argument);
}

}  // namespace
}  // namespace rendezvous
