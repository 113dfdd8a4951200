// The C brain's rendezvous protocol alone (examples/c_brain/rendezvous.h), no DDS: brains stepped
// on simulated time with a perfect consensus log (every proposal committed to every drone the next
// period, in proposal order) and an ideal flight stack (takeoff climbs, a position setpoint is
// flown at 5 m/s, land descends). Every drone reaches its slot on the ring and logs
// rendezvous_complete; all agree on the rendezvous point; the same inputs give the same run.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <numbers>
#include <string>
#include <vector>

#include "rendezvous.h"

namespace swarmbox {
namespace {

constexpr std::int64_t kPeriodNs = 20'000'000;
constexpr double kSpeedM = 5.0 * 0.02;  // per period

rv_config Config(const std::vector<std::string>& sorted_members, std::size_t self) {
  rv_config c{};
  c.altitude_m = 10.0;
  c.radius_m = 6.0;
  c.hold_s = 5.0;
  c.n_members = sorted_members.size();
  for (std::size_t i = 0; i < sorted_members.size(); ++i) {
    std::snprintf(c.members[i], sizeof c.members[i], "%s", sorted_members[i].c_str());
  }
  c.self = self;
  return c;
}

struct Drone {
  rv_state brain{};
  std::string mode = "init";
  double pos[3] = {0.0, 0.0, 0.0};
  bool landed = true;
  bool hover_event = false;
  double target[3] = {0.0, 0.0, 0.0};
  bool has_target = false;
  std::vector<std::string> events;  // "name k=v ..."
  std::vector<std::string> statuses;
};

// The ideal flight stack: applies the output's commands, then flies one period.
void Fly(Drone& d, const rv_output& out) {
  d.hover_event = false;
  for (std::size_t i = 0; i < out.n_commands; ++i) {
    const std::string name = out.commands[i].name;
    if (name == "takeoff") {
      d.mode = "takeoff";
      d.landed = false;
      d.target[2] = out.commands[i].param;
    } else if (name == "land") {
      d.mode = "land";
      d.has_target = false;
    }
  }
  if (out.has_setpoint) {
    d.mode = "position";
    std::copy(out.setpoint_enu_m, out.setpoint_enu_m + 3, d.target);
    d.has_target = true;
  }
  if (d.mode == "takeoff") {
    d.pos[2] = std::min(d.target[2], d.pos[2] + kSpeedM);
    if (d.pos[2] >= d.target[2]) {
      d.mode = "hold";
      d.hover_event = true;
    }
  } else if (d.mode == "position" && d.has_target) {
    double delta[3];
    double length = 0.0;
    for (int a = 0; a < 3; ++a) {
      delta[a] = d.target[a] - d.pos[a];
      length += delta[a] * delta[a];
    }
    length = std::sqrt(length);
    const double step = std::min(length, kSpeedM);
    for (int a = 0; a < 3 && length > 0.0; ++a) d.pos[a] += delta[a] / length * step;
  } else if (d.mode == "land") {
    d.pos[2] = std::max(0.0, d.pos[2] - kSpeedM);
    if (d.pos[2] <= 0.0) {
      d.mode = "landed";
      d.landed = true;
    }
  } else if (d.mode == "init") {
    d.mode = "idle";  // the estimator is ready after one period
  }
}

// Runs `drones` (started at `starts`) until every one is done or `max_s` of simulated time.
std::vector<Drone> Fleet(const std::vector<std::string>& members, const std::vector<std::array<double, 2>>& starts,
                       double max_s, std::int64_t* end_ns) {
  std::vector<std::string> sorted = members;
  std::sort(sorted.begin(), sorted.end());
  std::vector<Drone> drones(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) {
    const auto self = static_cast<std::size_t>(std::find(sorted.begin(), sorted.end(), members[i]) - sorted.begin());
    const rv_config c = Config(sorted, self);
    rv_init(&drones[i].brain, &c);
    drones[i].pos[0] = starts[i][0];
    drones[i].pos[1] = starts[i][1];
  }
  std::vector<std::string> pending;  // proposed this period, committed to everyone the next one
  std::int64_t t = 0;
  for (; t <= static_cast<std::int64_t>(max_s * 1e9); t += kPeriodNs) {
    const std::vector<std::string> committed = std::move(pending);
    pending.clear();
    bool all_done = true;
    for (auto& d : drones) {
      for (const auto& e : committed) {
        rv_apply_entry(&d.brain, reinterpret_cast<const std::uint8_t*>(e.data()), e.size());
      }
      const rv_input in{.t_ns = t,
                        .position_enu_m = {d.pos[0], d.pos[1], d.pos[2]},
                        .flight_mode = d.mode.c_str(),
                        .landed = d.landed,
                        .hover_event = d.hover_event,
                        .rejected_event = false,
                        .landed_event = false};
      rv_output out;
      rv_step(&d.brain, &in, &out);
      for (std::size_t p = 0; p < out.n_proposals; ++p) pending.emplace_back(out.proposals[p]);
      for (std::size_t e = 0; e < out.n_events; ++e) {
        std::string line = out.events[e].name;
        for (std::size_t f = 0; f < out.events[e].n_fields; ++f) {
          line += std::string(" ") + out.events[e].fields[f].key + "=" + out.events[e].fields[f].value;
        }
        d.events.push_back(line);
      }
      if (d.statuses.empty() || d.statuses.back() != out.status) d.statuses.emplace_back(out.status);
      Fly(d, out);
      all_done = all_done && d.brain.done;
    }
    if (all_done) break;
  }
  *end_ns = t;
  return drones;
}

TEST(CBrainRendezvous, ThreeDronesMeetOnTheRingAndLand) {
  std::int64_t end_ns = 0;
  // Not in sorted order: slots follow the sorted order (scout_a index 0, scout_b 1, scout_c 2).
  const auto drones = Fleet({"scout_c", "scout_a", "scout_b"}, {{{30.0, 0.0}}, {{0.0, 0.0}}, {{0.0, 30.0}}}, 120.0, &end_ns);
  const std::vector<std::string> phases = {"rendezvous/takeoff", "rendezvous/voting", "rendezvous/flying",
                                           "rendezvous/arrived", "rendezvous/landing", "rendezvous/done"};
  for (const auto& d : drones) {
    EXPECT_TRUE(d.brain.done) << "not done at " << static_cast<double>(end_ns) / 1e9 << " s";
    EXPECT_EQ(d.statuses, phases);
    // P = the mean of the positions proposed when hovering: (10, 10).
    EXPECT_EQ(d.events, (std::vector<std::string>{"rendezvous_point x=10.000 y=10.000", "rendezvous_complete members=3"}));
    EXPECT_EQ(d.mode, "landed");
    const double angle = 2.0 * std::numbers::pi * static_cast<double>(d.brain.config.self) / 3.0;
    EXPECT_NEAR(d.pos[0], 10.0 + 6.0 * std::cos(angle), 1.0);
    EXPECT_NEAR(d.pos[1], 10.0 + 6.0 * std::sin(angle), 1.0);
  }
  EXPECT_LT(end_ns, 60'000'000'000) << "the rendezvous took longer than a minute of simulated time";
}

TEST(CBrainRendezvous, TheSameInputsGiveTheSameRun) {
  std::int64_t end_a = 0;
  std::int64_t end_b = 0;
  const auto a = Fleet({"a", "b"}, {{{1.25, -3.5}}, {{-7.0, 2.0}}}, 120.0, &end_a);
  const auto b = Fleet({"a", "b"}, {{{1.25, -3.5}}, {{-7.0, 2.0}}}, 120.0, &end_b);
  EXPECT_EQ(end_a, end_b);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_TRUE(a[i].brain.done);
    EXPECT_EQ(a[i].events, b[i].events);
    EXPECT_EQ(std::memcmp(a[i].pos, b[i].pos, sizeof a[i].pos), 0);
  }
}

// Words are separated by runs of spaces (as the C++ example brain reads them).
TEST(CBrainRendezvous, IgnoresEntriesItDoesNotKnowAndCountsTheFirstPerMember) {
  const rv_config c = Config({"a", "b"}, 0);
  rv_state s;
  rv_init(&s, &c);
  for (const std::string& e : std::vector<std::string>{"pos c 1 2", "pos a 1", "pos a 1 2 3", "pos a x 2", "pos a nan 2", "arrived",
                              "arrived a b", "posa 1 2", std::string("pos a 1\0 2", 9), "pos a 1e999 2"}) {
    rv_apply_entry(&s, reinterpret_cast<const std::uint8_t*>(e.data()), e.size());
  }
  EXPECT_EQ(s.n_pos, 0u);
  EXPECT_EQ(s.n_arrived, 0u);
  for (const std::string& e : std::vector<std::string>{"pos  b -1.5   2.25", "pos b 9 9", " arrived b ", "arrived b"}) {
    rv_apply_entry(&s, reinterpret_cast<const std::uint8_t*>(e.data()), e.size());
  }
  EXPECT_EQ(s.n_pos, 1u);
  EXPECT_EQ(s.pos_x_m[1], -1.5);
  EXPECT_EQ(s.pos_y_m[1], 2.25);
  EXPECT_EQ(s.n_arrived, 1u);
}

TEST(CBrainRendezvous, AsksForTakeoffAgainWhenTheFlightStackRefusedIt) {
  const rv_config c = Config({"a"}, 0);
  rv_state s;
  rv_init(&s, &c);
  rv_output out;
  rv_input in{.t_ns = 0, .position_enu_m = {0, 0, 0}, .flight_mode = "init", .landed = true,
              .hover_event = false, .rejected_event = false, .landed_event = false};
  rv_step(&s, &in, &out);
  EXPECT_EQ(out.n_commands, 0u) << "takeoff in init (the flight stack refuses it)";
  in.flight_mode = "idle";
  in.t_ns += kPeriodNs;
  rv_step(&s, &in, &out);
  ASSERT_EQ(out.n_commands, 1u);
  EXPECT_STREQ(out.commands[0].name, "takeoff");
  EXPECT_EQ(out.commands[0].param, 10.0);
  in.t_ns += kPeriodNs;
  rv_step(&s, &in, &out);
  EXPECT_EQ(out.n_commands, 0u) << "asked twice";
  in.t_ns += kPeriodNs;
  in.rejected_event = true;
  rv_step(&s, &in, &out);
  EXPECT_EQ(out.n_commands, 1u) << "not asked again after setpoint_rejected";
}

}  // namespace
}  // namespace swarmbox
