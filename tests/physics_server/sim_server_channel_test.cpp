// SimServer hosting the simulated radio channel (radio.model channel), without agents: the
// scripted fake transport answers every sample and puts frames in radio_out; what each drone hears
// comes back in its samples' radio_in. Deterministic (fixed seeds, fake wall clock).
#include <gtest/gtest.h>

#include <cmath>
#include <set>
#include <string>

#include "sim_fakes.hpp"
#include "sim_server.hpp"
#include "swarmbox/channel/radio_profile.hpp"
#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::FakeClock;
using testing::kMs;
using testing::ReadFile;
using testing::ScriptedAgents;

constexpr std::int64_t kStepNs = 4 * kMs;
constexpr std::uint32_t kFrameBytes = 200;

channel::RadioProfile WifiProfile() {
  auto p = channel::LoadRadioProfile(testing::TrialsDir() + "/radios/wifi_5ghz_mesh.yaml");
  EXPECT_TRUE(p.ok()) << (p.ok() ? "" : p.error().ToString());
  return p.ok() ? *p : channel::RadioProfile{};
}

bus::RadioFrame StateFrame(const std::string& from, std::uint64_t seq) {
  bus::RadioFrame f;
  f.from = from;
  f.seq = seq;
  f.size_bytes = kFrameBytes;
  bus::DroneState s;
  s.drone = from;
  s.seq = seq;
  f.state_msg.push_back(s);
  return f;
}

// Two hovering x500s, `a` at the origin and `b` at (distance, 0), 10 m up; the server hosts the
// channel with the 5 GHz mesh profile. The world keeps its 200 m geofence (a larger one costs a
// ground texture of its size): beyond it the drones only raise event=geofence_breach.
class ChannelServer {
 public:
  explicit ChannelServer(double distance_m, RadioPlan plan = {}, WorldConfig config = testing::CalmWorld()) {
    world = testing::MakeWorld(config);
    const Airframe af = testing::LoadShippedAirframe("x500");
    const double u = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
    testing::Spawn(*world, testing::MakeSpawn("a", af, Vec3{0, 0, 10}, 0, u));
    testing::Spawn(*world, testing::MakeSpawn("b", af, Vec3{distance_m, 0, 10}, 0, u));
    agents.throttle = u;
    agents.alive = {{"a", true}, {"b", true}};
    out = std::tmpfile();
    SimServerOptions o;
    o.rtf = 0;
    o.clock_every_s = 0;
    o.cameras = false;
    o.lockstep = {.timeout_ns = 200 * kMs, .join_timeout_ns = 500 * kMs};
    o.plan = std::move(plan);
    o.radio_profile = WifiProfile();
    o.radio_seed = 7;
    server.emplace(*world, agents, clock, nullptr, o, out);
  }
  ~ChannelServer() { std::fclose(out); }

  // One step in which each drone in `senders` broadcasts one frame (seq = step + 1).
  void Step(const std::vector<std::string>& senders) {
    const std::uint64_t k = world->step_count();
    for (const std::string& s : senders) agents.answer_radio[s] = {StateFrame(s, k + 1)};
    ASSERT_TRUE(server->RunStep(stop).ok());
  }

  std::unique_ptr<World> world;
  FakeClock clock;
  ScriptedAgents agents{clock};
  std::FILE* out = nullptr;
  std::atomic<bool> stop{false};
  std::optional<SimServer> server;
};

RadioPlan PlanOf(const std::string& json) {
  auto doc = yaml::Parse(json, "plan.json");
  EXPECT_TRUE(doc.ok()) << doc.error().ToString();
  auto plan = ParseRadioPlan(*doc);
  EXPECT_TRUE(plan.ok()) << plan.error().ToString();
  return *plan;
}

// A frame sent at step 10 reaches the other drone at t_10 + airtime + d/c (the channel's own
// figure for the same inputs), in the sample of the step whose interval (t_{k-1}, t_k] holds that
// time, with its payload, sender, seq and both times; the sender does not hear itself.
TEST(SimServerChannel, DeliveriesArriveAtExactSimulatedTimes) {
  ChannelServer s(100);
  for (int k = 0; k < 10; ++k) s.Step({});
  const Vec3 pa = s.world->Truth(0).position_m, pb = s.world->Truth(1).position_m;
  s.Step({"a"});
  for (int k = 11; k < 14; ++k) s.Step({});

  channel::Channel reference(WifiProfile(), 2, 7, {});
  const std::vector<channel::Vec3d> positions{{pa.x, pa.y, pa.z}, {pb.x, pb.y, pb.z}};
  reference.SetPositions(positions);
  reference.Send(10 * kStepNs, channel::Packet{0, std::nullopt, 11, kFrameBytes, 10 * kStepNs, 0});
  std::vector<channel::Delivery> expected;
  reference.TakeDeliveries(20 * kStepNs, &expected);
  ASSERT_EQ(expected.size(), 1u);
  const std::int64_t at = expected[0].at_ns;
  EXPECT_GT(at, 10 * kStepNs + reference.AirtimeNs(kFrameBytes));  // plus ~333 ns of propagation

  EXPECT_TRUE(s.agents.heard["a"].empty());
  ASSERT_EQ(s.agents.heard["b"].size(), 1u);
  const auto& got = s.agents.heard["b"][0];
  EXPECT_EQ(got.frame.delivered_ns, at);
  const std::uint64_t k = static_cast<std::uint64_t>((at + kStepNs - 1) / kStepNs);  // first t_k >= at
  EXPECT_EQ(got.step, k);
  EXPECT_EQ(got.frame.from, "a");
  EXPECT_EQ(got.frame.to, "");
  EXPECT_EQ(got.frame.seq, 11u);
  EXPECT_EQ(got.frame.sent_ns, 10 * kStepNs);
  ASSERT_EQ(got.frame.state_msg.size(), 1u);
  EXPECT_EQ(got.frame.state_msg[0].drone, "a");
}

// The plan's mesh impairment is every sender's egress delay (netem's meaning) in simulated time,
// and the stats come with each clock line.
TEST(SimServerChannel, MeshDelayOfThePlanDelaysEveryFrameInSimulatedTime) {
  ChannelServer s(50, PlanOf(R"({"mesh": {"delay_ms": 100}})"));
  s.Step({"a"});
  for (int k = 1; k < 40; ++k) s.Step({});
  ASSERT_EQ(s.agents.heard["b"].size(), 1u);
  const auto& got = s.agents.heard["b"][0];
  const std::int64_t delay = got.frame.delivered_ns - got.frame.sent_ns;
  EXPECT_GE(delay, 100 * kMs);
  EXPECT_LT(delay, 101 * kMs);  // plus airtime (~0.4 ms) and propagation
  EXPECT_EQ(got.step, 26u);     // t_25 = 100 ms < delivery <= t_26
}

TEST(SimServerChannel, ChannelStatsComeWithEveryClockLine) {
  ChannelServer s(50);
  SimServerOptions o;
  o.rtf = 0;
  o.clock_every_s = 0.1;
  o.cameras = false;
  o.radio_profile = WifiProfile();
  SimServer server(*s.world, s.agents, s.clock, nullptr, o, s.out);
  for (int k = 0; k < 25; ++k) {
    s.agents.answer_radio["a"] = {StateFrame("a", static_cast<std::uint64_t>(k) + 1)};
    ASSERT_TRUE(server.RunStep(s.stop).ok());
  }
  const std::string log = ReadFile(s.out);
  EXPECT_NE(log.find("t=0.100 node=physics event=channel sent=25 delivered=24 lost_range=0 lost_per=0 lost_impairment=0 "
                     "lost_queue=0 lost_partition=0 lost_out=0 duplicated=0 medium_busy_s=0.0"),
            std::string::npos)
      << log;
}

// Many frames in one step from both drones: each receiver gets them in (delivered_ns, from, seq)
// order, unicast frames only at their addressee.
TEST(SimServerChannel, RadioInIsInDeliveryOrderAndUnicastReachesOnlyItsAddressee) {
  ChannelServer s(50);
  bus::RadioFrame to_b = StateFrame("a", 3);
  to_b.to = "b";
  s.agents.answer_radio["a"] = {StateFrame("a", 2), to_b, StateFrame("a", 1)};
  s.agents.answer_radio["b"] = {StateFrame("b", 1)};
  ASSERT_TRUE(s.server->RunStep(s.stop).ok());
  for (int k = 1; k < 10; ++k) s.Step({});
  ASSERT_EQ(s.agents.heard["b"].size(), 3u);
  std::vector<std::uint64_t> seqs;
  for (std::size_t n = 0; n < 3; ++n) {
    seqs.push_back(s.agents.heard["b"][n].frame.seq);
    if (n > 0) {
      EXPECT_LT(s.agents.heard["b"][n - 1].frame.delivered_ns, s.agents.heard["b"][n].frame.delivered_ns);
    }
  }
  EXPECT_EQ(seqs, (std::vector<std::uint64_t>{1, 2, 3}));  // a's queue, in seq order
  EXPECT_EQ(s.agents.heard["b"][2].frame.to, "b");
  ASSERT_EQ(s.agents.heard["a"].size(), 1u);
  EXPECT_EQ(s.agents.heard["a"][0].frame.from, "b");
}

// Loss per the profile: for each distance the share of 500 frames heard matches 1 - PER of the
// link (log-distance path loss with the pair's seeded shadowing); all arrive at 100 m, none beyond
// max_range_m.
TEST(SimServerChannel, LossGrowsWithDistanceAsTheProfileSaysAndNothingArrivesBeyondRange) {
  const channel::RadioProfile profile = WifiProfile();
  std::vector<double> heard_share;
  for (const double d : {100.0, 600.0, 700.0, 740.0, 800.0}) {
    ChannelServer s(d);
    channel::Channel reference(profile, 2, 7, {});
    const Vec3 pa = s.world->Truth(0).position_m, pb = s.world->Truth(1).position_m;
    const std::vector<channel::Vec3d> positions{{pa.x, pa.y, pa.z}, {pb.x, pb.y, pb.z}};
    reference.SetPositions(positions);
    const double per = reference.Link(0, 1).per;
    constexpr int kFrames = 500;
    for (int k = 0; k < kFrames; ++k) s.Step({"a"});
    s.Step({});
    const double share = static_cast<double>(s.agents.heard["b"].size()) / kFrames;
    const double sigma = std::sqrt(per * (1 - per) / kFrames);
    EXPECT_NEAR(share, 1 - per, 4 * sigma + 0.01) << "at " << d << " m, PER " << per;
    heard_share.push_back(share);
  }
  EXPECT_EQ(heard_share.front(), 1.0);
  EXPECT_GT(heard_share[1], heard_share[3]);
  EXPECT_EQ(heard_share.back(), 0.0);
  EXPECT_LT(profile.max_range_m, 800.0);
}

// A wall between the drones costs obstacle_loss_db: a link clear at 300 m loses most frames.
TEST(SimServerChannel, AWallOnTheLineOfSightCostsTheProfilesObstacleLoss) {
  WorldConfig walled = testing::CalmWorld();
  walled.obstacles.push_back({"wall", Vec3{150, 0, 10}, Vec3{1, 40, 20}, 0});
  std::size_t clear_heard = 0, walled_heard = 0;
  {
    ChannelServer s(300);
    for (int k = 0; k < 300; ++k) s.Step({"a"});
    clear_heard = s.agents.heard["b"].size();
  }
  ChannelServer s(300, {}, walled);
  channel::Channel reference(WifiProfile(), 2, 7, ChannelObstacles(s.world->config()));
  const Vec3 pa = s.world->Truth(0).position_m, pb = s.world->Truth(1).position_m;
  const std::vector<channel::Vec3d> positions{{pa.x, pa.y, pa.z}, {pb.x, pb.y, pb.z}};
  reference.SetPositions(positions);
  EXPECT_EQ(reference.Link(0, 1).obstacles, 1);
  for (int k = 0; k < 300; ++k) s.Step({"a"});
  walled_heard = s.agents.heard["b"].size();
  EXPECT_GT(clear_heard, 290u);
  const channel::LinkState wall = reference.Link(0, 1);
  EXPECT_NEAR(static_cast<double>(walled_heard) / 300, 1 - wall.per, 0.1);
  std::printf("300 m: clear %zu/300 heard; a wall: %.1f dB path loss, PER %.3f, %zu/300 heard\n", clear_heard,
              wall.path_loss_db, wall.per, walled_heard);
  EXPECT_LT(walled_heard, clear_heard / 2);
}

// drone_out in channel mode: from at_s the drone neither sends nor hears; the other one goes on.
TEST(SimServerChannel, DroneOutLeavesTheChannelAtExactlyAtS) {
  ChannelServer s(90, PlanOf(R"({"schedule": [{"at_s": 0.1, "name": "k", "kind": "drone_out", "mode": "kill",
                                                 "targets": ["b"]}]})"));
  for (int k = 0; k < 60; ++k) s.Step({"a", "b"});
  // b's frames: sent at t_0 .. t_25 (its answer to step 25 went out before the kill), no later.
  std::int64_t last_from_b = -1;
  for (const auto& h : s.agents.heard["a"]) last_from_b = std::max(last_from_b, h.frame.sent_ns);
  EXPECT_EQ(last_from_b, 24 * kStepNs);  // the frame of t_25 was still queued when b left the air
  EXPECT_EQ(s.agents.last_step["b"], 25u);
  EXPECT_EQ(s.agents.heard["a"].size(), 25u);
  const channel::ChannelStats* stats = s.server->channel_stats();
  ASSERT_NE(stats, nullptr);
  const std::uint64_t lost_out = stats->lost_out;
  EXPECT_GT(lost_out, 0u);
  EXPECT_EQ(ReadFile(s.out), "t=0.100 node=physics event=drone_out drone=b fault=k mode=kill\n");
}

// A partition from 0.1 s for 0.1 s: exactly the frames sent at t_25 .. t_49 do not cross it.
TEST(SimServerChannel, PartitionBlocksExactlyTheFramesSentWhileItIsOn) {
  ChannelServer s(90, PlanOf(R"({"schedule": [{"at_s": 0.1, "name": "split", "kind": "partition",
                                                 "groups": [["a"], ["b"]], "duration_s": 0.1}]})"));
  for (int k = 0; k < 80; ++k) s.Step({"a", "b"});
  std::set<std::int64_t> sent;
  for (const auto& h : s.agents.heard["a"]) sent.insert(h.frame.sent_ns / kStepNs);
  for (std::int64_t k = 0; k < 79; ++k) EXPECT_EQ(sent.count(k), (k >= 25 && k < 50) ? 0u : 1u) << "step " << k;
  EXPECT_EQ(ReadFile(s.out),
            "t=0.100 node=physics event=radio_fault fault=split kind=partition state=on\n"
            "t=0.200 node=physics event=radio_fault fault=split kind=partition state=off\n");
}

// The range test: scout b flies away from a, past the profile's range, and back. It is flown
// through the world's API: motors off, a PD force on its body holds its height and moves it along
// x (open-loop rotor hover does not survive a horizontal flight). They hear each other until about max_range_m, not
// at all beyond it, and again once b is back in range.
TEST(SimServerChannel, TwoScoutsFlownApartLoseEachOtherAtTheRangeAndFindEachOtherAgain) {
  const channel::RadioProfile profile = WifiProfile();
  const double near = channel::RangeForPer(profile, 0.01) - 30;  // a good link
  std::printf("PER 0.01 at %.0f m, 0.5 at %.0f m, 0.99 at %.0f m, max_range_m %.0f\n", channel::RangeForPer(profile, 0.01),
              channel::RangeForPer(profile, 0.5), channel::RangeForPer(profile, 0.99), profile.max_range_m);
  ChannelServer s(near);
  s.agents.motors_off["b"] = true;
  const double g = s.world->config().gravity_m_s2;
  const double range = profile.max_range_m;
  const double mass = s.world->airframe(1).mass_kg;
  double max_x = 0, last_heard_out_x = 0, first_heard_back_x = 0;
  bool went_out = false, heard_beyond = false, heard_back = false;
  std::size_t heard = 0;
  std::vector<double> x_at_step;
  for (int k = 0; k < 18000; ++k) {
    const DroneTruth b = s.world->Truth(1);
    x_at_step.push_back(b.position_m.x);
    const double target = k < 9000 ? range + 80 : near;  // out for 36 s, then back
    const double accel = std::clamp(1.0 * (target - b.position_m.x) - 2.0 * b.velocity_m_s.x, -8.0, 8.0);
    const double lift = g + std::clamp(2.0 * (10.2 - b.position_m.z) - 3.0 * b.velocity_m_s.z, -5.0, 5.0);
    s.world->SetExternalForce(1, Vec3{mass * accel, 0, mass * lift});
    s.Step(k % 5 == 0 ? std::vector<std::string>{"a", "b"} : std::vector<std::string>{});
    max_x = std::max(max_x, b.position_m.x);
    const auto& got = s.agents.heard["b"];
    for (; heard < got.size(); ++heard) {
      const double x = x_at_step[static_cast<std::size_t>(got[heard].frame.sent_ns / kStepNs)];
      if (x > range) heard_beyond = true;
      if (!went_out) last_heard_out_x = std::max(last_heard_out_x, x);
      if (went_out && !heard_back) {
        heard_back = true;
        first_heard_back_x = x;
      }
    }
    if (b.position_m.x > range) went_out = true;
      }
  EXPECT_GT(max_x, range + 50);               // b was well beyond the range...
  EXPECT_TRUE(went_out);
  EXPECT_FALSE(heard_beyond);                  // ...and nothing crossed it
  EXPECT_GT(last_heard_out_x, channel::RangeForPer(profile, 0.5));  // contact held into the PER edge
  EXPECT_TRUE(heard_back);                     // found again on the way back,
  EXPECT_LE(first_heard_back_x, range);        // inside the range
  EXPECT_NEAR(s.world->Truth(1).position_m.x, near, 20);
  std::printf("range %.0f m: last heard going out at %.1f m, first heard coming back at %.1f m, farthest %.0f m\n", range,
              last_heard_out_x, first_heard_back_x, max_x);
}

}  // namespace
}  // namespace swarmbox::physics
