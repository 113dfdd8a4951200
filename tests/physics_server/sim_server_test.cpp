// SimServer's lockstep loop with a fake transport (a scripted agent) and a fake wall clock: no
// DDS, deterministic.
#include "sim_server.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <map>
#include <utility>
#include <string>

#include "server_options.hpp"
#include "sim_fakes.hpp"
#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

using testing::FakeClock;
using testing::kMs;
using testing::ReadFile;
using testing::ScriptedAgents;

class SimServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    world_ = testing::MakeWorld(testing::CalmWorld());
    Airframe af = testing::LoadShippedAirframe("x500");
    af.camera.trigger_distance_m = 0;  // the fixed 5 Hz these tests count (SimServerCameraTrigger: the shipped trigger)
    u_ = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
    testing::Spawn(*world_, testing::MakeSpawn("a", af, Vec3{0, 0, 10}, 0, u_));
    testing::Spawn(*world_, testing::MakeSpawn("b", af, Vec3{5, 0, 10}, 0, u_));
    agents_.throttle = u_;
    agents_.alive = {{"a", true}, {"b", true}};
    out_ = std::tmpfile();
    ASSERT_NE(out_, nullptr);
  }
  void TearDown() override { std::fclose(out_); }

  SimServerOptions Options(double max_sim_s) {
    SimServerOptions o;
    o.rtf = 1.0;
    o.max_sim_time_s = max_sim_s;
    o.lockstep = {.timeout_ns = 200 * kMs, .join_timeout_ns = 500 * kMs};
    return o;
  }

  std::unique_ptr<World> world_;
  FakeClock clock_;
  ScriptedAgents agents_{clock_};
  std::FILE* out_ = nullptr;
  double u_ = 0;
  std::atomic<bool> stop_{false};
};

TEST_F(SimServerTest, StepsInLockstepAndPacesToRealTime) {
  SimServer server(*world_, agents_, clock_, nullptr, Options(1.0), out_);
  ASSERT_TRUE(server.Run(stop_).ok());
  EXPECT_EQ(world_->step_count(), 250u);
  EXPECT_EQ(agents_.samples["a"], 250);
  EXPECT_EQ(agents_.frames["a"], 5);  // 5 Hz
  // Paced at rtf 1: 1 s of simulated time took at least 1 s of (fake) wall time.
  EXPECT_GE(clock_.now_ns, 996 * kMs);
  // Both held in hover by the agents' commands.
  EXPECT_NEAR(world_->Truth(1).position_m.z, 10.23, 0.01);
  EXPECT_EQ(ReadFile(out_), "");
}

TEST_F(SimServerTest, SilentDroneIsLostWithMotorsOffAndTheWorldGoesOn) {
  SimServerOptions o = Options(2.0);
  o.rtf = 0;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  for (int k = 0; k < 100; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  agents_.alive["b"] = false;  // killed at t = 0.4 s
  ASSERT_TRUE(server.Run(stop_).ok());
  EXPECT_EQ(world_->step_count(), 500u);
  EXPECT_TRUE(world_->Truth(1).lost);
  EXPECT_FALSE(world_->Truth(0).lost);
  EXPECT_LT(world_->Truth(1).rotor_speed_rad_s[0], 1.0);  // motors off, spun down
  EXPECT_LT(world_->Truth(1).position_m.z, 5.0);           // and it fell
  EXPECT_NEAR(world_->Truth(0).position_m.z, 10.23, 0.01); // the other kept hovering
  const std::string log = ReadFile(out_);
  EXPECT_EQ(log.rfind("t=0.400 node=physics event=drone_lost a=b\n", 0), 0u) << log;
  EXPECT_NE(log.find("event=crash a=b b=ground"), std::string::npos) << log;
}

TEST_F(SimServerTest, LostDroneRejoinsWhenItAnswersAgain) {
  SimServerOptions o = Options(0);
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  agents_.alive["b"] = false;
  for (int k = 0; k < 3; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());  // join timeout on step 0
  EXPECT_TRUE(world_->Truth(1).lost);
  agents_.alive["b"] = true;
  ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_FALSE(world_->Truth(1).lost);
  const std::string log = ReadFile(out_);
  EXPECT_NE(log.find("event=drone_lost a=b"), std::string::npos) << log;
  EXPECT_NE(log.find("event=drone_rejoined a=b"), std::string::npos) << log;
}

TEST_F(SimServerTest, WorldCommandsDropGpsAndRejectUnknownOnes) {
  SimServer server(*world_, agents_, clock_, nullptr, Options(0), out_);
  agents_.world_commands = {{"a", "gps_dropout", {0.5}}, {"a", "teleport", {1, 0, 0}},
                            {"nobody", "gps_dropout", {1}}};
  int invalid = 0;
  for (int k = 0; k < 250; ++k) {
    ASSERT_TRUE(server.RunStep(stop_).ok());
    const GpsSample& g = world_->sensors(0).gps;
    if (g.fresh && !g.valid) ++invalid;
  }
  EXPECT_EQ(invalid, 5);  // 0.5 s at 10 Hz, then the fix is back
  const std::string log = ReadFile(out_);
  EXPECT_NE(log.find("event=world_command command=gps_dropout target=a"), std::string::npos) << log;
  EXPECT_NE(log.find("event=world_command_rejected command=teleport target=a reason=\"not supported by this physics server\""),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("event=world_command_rejected command=gps_dropout target=nobody reason=\"unknown drone\""),
            std::string::npos)
      << log;
}

TEST_F(SimServerTest, StopFlagEndsTheRunAndFlushesTruth) {
  const std::string path = ::testing::TempDir() + "sim_server_truth.csv";
  auto truth = TruthCsvFile::Open(path, 10);
  ASSERT_TRUE(truth.ok());
  SimServer server(*world_, agents_, clock_, &*truth, Options(0), out_);
  for (int k = 0; k < 50; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  stop_ = true;
  ASSERT_TRUE(server.Run(stop_).ok());
  std::FILE* f = std::fopen(path.c_str(), "r");
  ASSERT_NE(f, nullptr);
  const std::string csv = ReadFile(f);
  std::fclose(f);
  // 0.2 s at 10 Hz: rows at t = 0.004, 0.1, 0.2 for two drones, plus the header.
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 7);
}

TEST(ServerOptions, ParsesDroneArguments) {
  auto d = ParseDroneArg("lifter:x8_heavy:1.5,-2,0:90:stretcher:attached");
  ASSERT_TRUE(d.ok()) << d.error().ToString();
  EXPECT_EQ(d->name, "lifter");
  EXPECT_EQ(d->airframe, "x8_heavy");
  EXPECT_DOUBLE_EQ(d->x_m, 1.5);
  EXPECT_DOUBLE_EQ(d->y_m, -2);
  EXPECT_DOUBLE_EQ(d->yaw_deg, 90);
  EXPECT_EQ(d->payload, "stretcher");
  EXPECT_TRUE(d->payload_attached);
  auto bad = ParseDroneArg("scout:x500:1,2");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().message(),
            "bad --drone 'scout:x500:1,2': position must be x,y,z in metres (expected "
            "name:airframe:x,y,z[:yaw_deg[:payload[:attached]]])");
  EXPECT_EQ(AirframePathFor("x500", "/t/airframes"), "/t/airframes/x500.yaml");
  EXPECT_EQ(AirframePathFor("./my.yaml", "/t/airframes"), "./my.yaml");
}

TEST(ServerOptions, DronesFileErrorsPointAtTheLine) {
  auto doc = yaml::Parse("drones:\n  - {name: a, airframe: x500, pose: [0, 0, 0]}\n  - {name: b, airframe: x500, pos: [1, 0, 0]}\n", "d.yaml");
  ASSERT_TRUE(doc.ok());
  auto list = ParseDronesFile(*doc);
  ASSERT_FALSE(list.ok());
  EXPECT_EQ(list.error().ToString(), "d.yaml:3:5: missing required key 'pose' in drone");
}

}  // namespace
}  // namespace swarmbox::physics

namespace swarmbox::physics {
namespace {

TEST_F(SimServerTest, GpsDegradeAndImuBiasJumpChangeTheSensors) {
  SimServer server(*world_, agents_, clock_, nullptr, Options(0), out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  const double ax_before = world_->sensors(0).imu.accel_m_s2.x;
  agents_.world_commands = {{"a", "gps_degrade", {1.0, 5.0, 8.0}}, {"a", "imu_bias_jump", {2.0, 0, 0, 0, 0, 0}}};
  ASSERT_TRUE(server.RunStep(stop_).ok());
  // A 2 m/s^2 step against noise of 0.02 m/s^2 and hover dynamics of < 0.1 m/s^2.
  EXPECT_NEAR(world_->sensors(0).imu.accel_m_s2.x - ax_before, 2.0, 0.2);
  bool degraded = false, restored = false;
  for (int k = 0; k < 500; ++k) {
    ASSERT_TRUE(server.RunStep(stop_).ok());
    const GpsSample& g = world_->sensors(0).gps;
    if (!g.fresh) continue;
    if (world_->time_s() < 1.0) degraded = degraded || (g.h_acc_m == 5.0 && g.v_acc_m == 8.0);
    if (world_->time_s() > 1.1) restored = g.h_acc_m == 0.8 && g.v_acc_m == 1.5;
  }
  EXPECT_TRUE(degraded);
  EXPECT_TRUE(restored);  // back to the x500's GPS after duration_s
}

}  // namespace
}  // namespace swarmbox::physics

namespace swarmbox::physics {
namespace {

// event=clock: the progress line every clock_every_s simulated seconds.
TEST(ClockProgress, MeasuresRtfAndLateStepsPerInterval) {
  ClockProgress p(1'000 * kMs);
  // Given steps of 4 ms simulated that take 2 ms of wall time, every other one behind the pace,
  EXPECT_FALSE(p.OnStep(4 * kMs, 100 * kMs, false));  // anchors the interval
  bool due = false;
  int steps = 1;
  for (std::int64_t k = 2; !due; ++k, ++steps) due = p.OnStep(4 * kMs * k, 100 * kMs + 2 * kMs * (k - 1), k % 2 == 0);
  // then a line is due at 1 s simulated, at rtf 2 with 125 late steps out of 249 after the anchor.
  EXPECT_EQ(steps, 250);
  const ClockProgress::Line line = p.Take();
  EXPECT_DOUBLE_EQ(line.rtf, 2.0);
  EXPECT_EQ(line.late, 125u);
  // The next interval starts where this one ended.
  EXPECT_FALSE(p.OnStep(1'004 * kMs, 600 * kMs, false));
  EXPECT_TRUE(p.OnStep(2'000 * kMs, 1'096 * kMs, true));
  const ClockProgress::Line next = p.Take();
  EXPECT_DOUBLE_EQ(next.rtf, 1000.0 / 498.0);
  EXPECT_EQ(next.late, 1u);
}

TEST(ClockProgress, NoWallTimeGivesRtfZeroAndSkippedIntervalsAreNotRepeated) {
  ClockProgress p(1'000 * kMs);
  EXPECT_FALSE(p.OnStep(4 * kMs, 0, false));
  EXPECT_TRUE(p.OnStep(3'500 * kMs, 0, false));  // a jump over three intervals: one line
  EXPECT_EQ(p.Take().rtf, 0.0);
  EXPECT_FALSE(p.OnStep(3'900 * kMs, 0, false));
  EXPECT_TRUE(p.OnStep(4'000 * kMs, 0, false));
}

TEST_F(SimServerTest, PrintsTheClockLineEverySimulatedInterval) {
  SimServerOptions o = Options(2.0);
  o.clock_every_s = 1.0;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.Run(stop_).ok());
  // Paced at rtf 1 by the fake clock; agents answer within 1 ms, so no step is late.
  EXPECT_EQ(ReadFile(out_),
            "t=1.000 node=physics event=clock rtf=1.00 steps=250 late=0 lost=0\n"
            "t=2.000 node=physics event=clock rtf=1.00 steps=500 late=0 lost=0\n");
}

TEST_F(SimServerTest, ClockLineCountsLateStepsAndLostDrones) {
  // rtf 8 asks 0.5 ms of wall time per 4 ms step, the agents take 1 ms: every step after the
  // first is late and the measured rtf is 4.
  SimServerOptions o = Options(1.0);
  o.rtf = 8;
  o.clock_every_s = 1.0;
  agents_.alive["b"] = false;  // never answers: lost after the join timeout on step 0
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.Run(stop_).ok());
  const std::string log = ReadFile(out_);
  EXPECT_NE(log.find("t=1.000 node=physics event=clock rtf=4.00 steps=250 late=249 lost=1\n"), std::string::npos) << log;
}

TEST_F(SimServerTest, ClockEveryZeroPrintsNoClockLine) {
  SimServerOptions o = Options(12.0);
  o.rtf = 0;
  o.clock_every_s = 0;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.Run(stop_).ok());
  EXPECT_EQ(ReadFile(out_).find("event=clock"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::physics

namespace swarmbox::physics {
namespace {

TEST_F(SimServerTest, AWaitingStepResendsEverySampleAsAKeepalive) {
  // Given drone b that has not joined yet (it answers nothing until its join timeout, 500 ms),
  agents_.alive["b"] = false;
  SimServer server(*world_, agents_, clock_, nullptr, Options(0), out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  // then during the wait both drones got step 0 again at 200 and 400 ms: b to join late, a (which
  // answered at once) so that it sees a live server; a's repeated answers were dropped.
  EXPECT_EQ(agents_.samples["b"], 3);
  EXPECT_EQ(agents_.samples["a"], 3);
  EXPECT_EQ(world_->step_count(), 1u);
  EXPECT_TRUE(world_->Truth(1).lost);
  EXPECT_FALSE(world_->Truth(0).lost);
}

}  // namespace
}  // namespace swarmbox::physics

namespace swarmbox::physics {
namespace {

// payload_attach [mass_kg] reaches World::AttachPayload: the simulated payload body takes the
// announced mass (the lifter's stretcher: 15 kg empty, 80 kg with the evacuee), no argument keeps
// it, and a malformed mass is refused by name with nothing changed. (What the mass does to the
// flight is tested in payload_test and in the flight stack's closed-loop payload tests.)
TEST(SimServerPayload, AttachWithAMassChangesTheSimulatedMass) {
  auto world = testing::MakeWorld(testing::CalmWorld());
  const Airframe af = testing::LoadShippedAirframe("x8_heavy");
  testing::Spawn(*world, testing::MakeSpawn("lifter", af, Vec3{0, 0, 20}, 0.0, 0.0, "stretcher", true));
  const double spawn_kg = af.payloads[0].mass_kg;
  EXPECT_NEAR(world->Truth(0).payload_mass_kg, spawn_kg, 1e-9);
  FakeClock clock;
  ScriptedAgents agents{clock};
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  SimServerOptions o;
  o.rtf = 0;
  o.lockstep = {.timeout_ns = 200 * kMs, .join_timeout_ns = 500 * kMs};
  std::atomic<bool> stop{false};
  SimServer server(*world, agents, clock, nullptr, o, out);
  auto step = [&](std::vector<WorldCommandInput> cmds) {
    agents.world_commands = std::move(cmds);
    ASSERT_TRUE(server.RunStep(stop).ok());
  };

  step({{"lifter", "payload_release", {}}});
  EXPECT_FALSE(world->Truth(0).payload_attached);
  // Loaded: the evacuee is on.
  step({{"lifter", "payload_attach", {80.0, 1.0}}, {"lifter", "payload_attach", {-1.0}},
        {"lifter", "payload_attach", {80.0}}});
  EXPECT_TRUE(world->Truth(0).payload_attached);
  EXPECT_NEAR(world->Truth(0).payload_mass_kg, 80.0, 1e-9);
  // No mass: keeps the 80 kg.
  step({{"lifter", "payload_release", {}}});
  step({{"lifter", "payload_attach", {}}});
  EXPECT_NEAR(world->Truth(0).payload_mass_kg, 80.0, 1e-9);
  // Set down empty again and picked up: 15 kg.
  step({{"lifter", "payload_release", {}}});
  step({{"lifter", "payload_attach", {15.0}}});
  EXPECT_TRUE(world->Truth(0).payload_attached);
  EXPECT_NEAR(world->Truth(0).payload_mass_kg, 15.0, 1e-9);

  const std::string log = ReadFile(out);
  std::fclose(out);
  EXPECT_NE(log.find("event=world_command_rejected command=payload_attach target=lifter "
                     "reason=\"payload_attach takes at most one argument, mass_kg >= 0\""),
            std::string::npos)
      << log;
  EXPECT_NE(log.find("event=world_command command=payload_attach target=lifter mass_kg=80.000"), std::string::npos)
      << log;
  EXPECT_NE(log.find("event=world_command command=payload_attach target=lifter mass_kg=15.000"), std::string::npos)
      << log;
}

}  // namespace
}  // namespace swarmbox::physics

namespace swarmbox::physics {
namespace {

// Camera determinism: a due frame goes out before the sample of its step, which says so.
TEST_F(SimServerTest, CameraFrameGoesOutBeforeItsSampleWhichSaysSo) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  for (int k = 0; k < 51; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  // 5 Hz at 250 Hz: frames at steps 0 and 50 (the first one due at once).
  std::vector<std::string> framed;
  for (std::size_t n = 0; n < agents_.published.size(); ++n) {
    const std::string& line = agents_.published[n];
    if (line.rfind("camera ", 0) != 0) continue;
    framed.push_back(line);
    ASSERT_LT(n + 1, agents_.published.size());
    EXPECT_EQ(agents_.published[n + 1], "sample " + line.substr(7) + " camera_frame");
  }
  EXPECT_EQ(framed, (std::vector<std::string>{"camera a 0", "camera b 0", "camera a 50", "camera b 50"}));
  EXPECT_EQ(std::count_if(agents_.published.begin(), agents_.published.end(),
                          [](const std::string& l) { return l.find("camera_frame") != std::string::npos; }),
            4);
}

// The x500's thermal camera (airframe `thermal:`) is taken with each camera frame and goes out
// just before it: the agent waits for the colour frame and finds the thermal one there already.
TEST_F(SimServerTest, AThermalFrameGoesOutJustBeforeItsCameraFrame) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  for (int k = 0; k < 51; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  std::vector<std::string> thermal;
  for (std::size_t n = 0; n < agents_.published.size(); ++n) {
    const std::string& line = agents_.published[n];
    if (line.rfind("thermal ", 0) != 0) continue;
    thermal.push_back(line);
    ASSERT_LT(n + 1, agents_.published.size());
    EXPECT_EQ(agents_.published[n + 1], "camera " + line.substr(8));
  }
  EXPECT_EQ(thermal,
            (std::vector<std::string>{"thermal a 0", "thermal b 0", "thermal a 50", "thermal b 50"}));
}

// The shipped x500 triggers its camera by distance (x500.yaml, camera_trigger.hpp): a drone holding
// its position takes its first frame at once, then one per trigger_interval_max_s (0.5 s, on the
// 5 Hz grid: 0.6 s), not 5 a second.
TEST(SimServerCameraTrigger, TheShippedX500HoldingItsPositionTakesAFrameAtItsFloorInterval) {
  auto world = testing::MakeWorld(testing::CalmWorld());
  const Airframe af = testing::LoadShippedAirframe("x500");
  ASSERT_DOUBLE_EQ(af.camera.trigger_distance_m, 3.0);
  ASSERT_DOUBLE_EQ(af.camera.trigger_interval_max_s, 0.5);
  const double u = af.HoverRotorSpeed() / af.motor.max_rot_velocity_rad_s;
  testing::Spawn(*world, testing::MakeSpawn("a", af, Vec3{0, 0, 10}, 0, u));
  testing::FakeClock clock;
  ScriptedAgents agents{clock};
  agents.throttle = u;
  agents.alive = {{"a", true}};
  std::FILE* out = std::tmpfile();
  ASSERT_NE(out, nullptr);
  SimServerOptions o;
  o.rtf = 0;
  o.lockstep = {.timeout_ns = 200 * kMs, .join_timeout_ns = 500 * kMs};
  SimServer server(*world, agents, clock, nullptr, o, out);
  std::atomic<bool> stop{false};
  for (int k = 0; k < 301; ++k) ASSERT_TRUE(server.RunStep(stop).ok());
  std::fclose(out);
  std::vector<std::string> framed;
  for (const std::string& line : agents.published) {
    if (line.rfind("camera ", 0) == 0) framed.push_back(line);
  }
  EXPECT_EQ(framed, (std::vector<std::string>{"camera a 0", "camera a 150", "camera a 300"}));
}

// World commands inside the answers: applied once every drone answered, before the world steps,
// in drone order then seq; the topic's come after them.
TEST_F(SimServerTest, AnswerWorldCommandsApplyInDroneOrderThenSeqBeforeTheStep) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  const double ax_before = world_->sensors(0).imu.accel_m_s2.x;
  agents_.answer_world["b"] = {{"a", "imu_bias_jump", {2.0, 0, 0, 0, 0, 0}, 7}, {"b", "gps_degrade", {1.0, 5.0, 8.0}, 3}};
  agents_.answer_world["a"] = {{"b", "gps_dropout", {1.0}, 9}};
  agents_.world_commands = {{"", "wind_gust", {1, 0, 0, 0.5}, 1}};
  // The answers to step 1 carry them (the samples of step 1 are answered with them).
  ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_NEAR(world_->sensors(0).imu.accel_m_s2.x - ax_before, 2.0, 0.2);  // before World::Step()
  const std::string log = ReadFile(out_);
  EXPECT_EQ(log,
            "t=0.004 node=physics event=world_command command=gps_dropout target=b\n"
            "t=0.004 node=physics event=world_command command=gps_degrade target=b\n"
            "t=0.004 node=physics event=world_command command=imu_bias_jump target=a\n"
            "t=0.004 node=physics event=world_command command=wind_gust target=\"\"\n");
}

RadioPlan PlanOf(const std::string& json) {
  auto doc = yaml::Parse(json, "plan.json");
  EXPECT_TRUE(doc.ok()) << doc.error().ToString();
  auto plan = ParseRadioPlan(*doc);
  EXPECT_TRUE(plan.ok()) << plan.error().ToString();
  return *plan;
}

// drone_out kill: out at exactly at_s (no sample after, motors off, no drone_lost), the rest
// goes on without waiting for it.
TEST_F(SimServerTest, KillLandsAtExactlyItsSimulatedTime) {
  SimServerOptions o = Options(1.0);
  o.rtf = 0;
  o.plan = PlanOf(R"({"schedule": [{"at_s": 0.4, "name": "k", "kind": "drone_out", "mode": "kill",
                                     "targets": ["b"], "duration_s": 0}]})");
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.Run(stop_).ok());
  EXPECT_EQ(world_->step_count(), 250u);
  EXPECT_EQ(agents_.last_step["b"], 100u);  // t_100 = 0.4 s: its last sample
  EXPECT_EQ(agents_.samples["b"], 101);
  EXPECT_EQ(agents_.last_step["a"], 249u);
  EXPECT_TRUE(world_->Truth(1).lost);
  EXPECT_LT(world_->Truth(1).rotor_speed_rad_s[0], world_->Truth(0).rotor_speed_rad_s[0] / 2);
  const std::string log = ReadFile(out_);
  EXPECT_EQ(log.rfind("t=0.400 node=physics event=drone_out drone=b fault=k mode=kill\n", 0), 0u) << log;
  EXPECT_EQ(log.find("drone_lost"), std::string::npos) << log;
  // The world never waited for b: the fake wall clock moved 1 ms per answered step only.
  EXPECT_LT(clock_.now_ns, 300 * kMs);
}

// stop with a duration: back after it as a joining drone, answered at once here.
TEST_F(SimServerTest, StoppedDroneComesBackAfterItsDurationAndRejoins) {
  SimServerOptions o = Options(1.0);
  o.rtf = 0;
  o.plan = PlanOf(R"({"schedule": [{"at_s": 0.2, "name": "s", "kind": "drone_out", "mode": "stop",
                                     "targets": ["b"], "duration_s": 0.3}]})");
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  ASSERT_TRUE(server.Run(stop_).ok());
  // Samples for steps 0..50, then from 126 (t_125 = 0.5 s: back, published from the next step).
  EXPECT_EQ(agents_.samples["b"], 51 + 124);
  EXPECT_FALSE(world_->Truth(1).lost);
  EXPECT_EQ(ReadFile(out_),
            "t=0.200 node=physics event=drone_out drone=b fault=s mode=stop\n"
            "t=0.500 node=physics event=drone_back drone=b fault=s\n");
}

// Back but silent: the lockstep waits for its first answer up to the join timeout, then it is lost.
TEST_F(SimServerTest, DroneBackButSilentIsWaitedForUpToTheJoinTimeout) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  o.plan = PlanOf(R"({"schedule": [{"at_s": 0.1, "name": "p", "kind": "drone_out", "mode": "pause",
                                     "targets": ["b"], "duration_s": 0.1}]})");
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  for (int k = 0; k <= 25; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  agents_.alive["b"] = false;
  const std::int64_t wall_before = clock_.now_ns;
  for (int k = 26; k <= 50; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());  // back at t_50
  EXPECT_LT(clock_.now_ns - wall_before, 100 * kMs);                        // nobody waited yet
  ASSERT_TRUE(server.RunStep(stop_).ok());                                   // step 51 waits for b
  EXPECT_GE(clock_.now_ns - wall_before, 500 * kMs);                         // its join timeout
  EXPECT_TRUE(world_->Truth(1).lost);
  const std::string log = ReadFile(out_);
  EXPECT_NE(log.find("t=0.200 node=physics event=drone_back drone=b fault=p\nt=0.204 node=physics event=drone_lost a=b\n"),
            std::string::npos)
      << log;
}

// raft_leader targets: the drone whose flag turned true most recently; ties by drone order.
TEST_F(SimServerTest, RaftLeaderTargetIsTheDroneThatBecameLeaderLast) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  o.plan = PlanOf(R"({"schedule": [{"at_s": 0.2, "name": "kl", "kind": "drone_out", "mode": "kill",
                                     "targets": ["raft_leader"]}]})");
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  agents_.leader["a"] = true;
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  agents_.leader["b"] = true;  // b too, later (a stale flag on a: a partitioned old leader)
  for (int k = 10; k <= 50; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_TRUE(world_->Truth(1).lost);
  EXPECT_FALSE(world_->Truth(0).lost);
  EXPECT_EQ(ReadFile(out_),
            "t=0.200 node=physics event=raft_leader_resolved fault=kl drone=b\n"
            "t=0.200 node=physics event=drone_out drone=b fault=kl mode=kill\n");
}

TEST_F(SimServerTest, RaftLeaderTieGoesToDroneOrderAndNoLeaderSkipsTheFault) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  o.plan = PlanOf(R"({"schedule": [
      {"at_s": 0.02, "name": "none", "kind": "drone_out", "mode": "kill", "targets": ["raft_leader"]},
      {"at_s": 0.1, "name": "tie", "kind": "drone_out", "mode": "kill", "targets": ["raft_leader"]}]})");
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  for (int k = 0; k < 10; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  agents_.leader["a"] = true;
  agents_.leader["b"] = true;  // both in the same step
  for (int k = 10; k <= 25; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_EQ(ReadFile(out_),
            "t=0.020 node=physics event=fault_skipped fault=none reason=\"no drone leads the Raft group\"\n"
            "t=0.100 node=physics event=raft_leader_resolved fault=tie drone=a\n"
            "t=0.100 node=physics event=drone_out drone=a fault=tie mode=kill\n");
}

// world_command entries land at their simulated time.
TEST_F(SimServerTest, PlanWorldCommandAppliesAtItsTime) {
  SimServerOptions o = Options(0);
  o.rtf = 0;
  o.plan = PlanOf(R"({"schedule": [{"at_s": 0.05, "name": "g", "kind": "world_command", "target": "a",
                                     "command": "gps_dropout", "args": [1.0]}]})");
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  for (int k = 0; k < 20; ++k) ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_EQ(ReadFile(out_), "t=0.052 node=physics event=world_command command=gps_dropout target=a\n");
}

}  // namespace
}  // namespace swarmbox::physics

namespace swarmbox::physics {
namespace {

// The start's account (joining.hpp): a line every wall second while the first step waits, the
// same on sim/status, then event=joined once.
TEST_F(SimServerTest, JoiningLinesNameTheMissingDronesEverySecondUntilEveryDroneJoined) {
  // Given b, whose agent answers only from 2.5 s of wall time on (a container still starting),
  agents_.alive_from_ns["b"] = 2500 * kMs;
  SimServerOptions o = Options(0);
  o.lockstep.join_timeout_ns = 5000 * kMs;
  SimServer server(*world_, agents_, clock_, nullptr, o, out_);
  // when the first step runs,
  ASSERT_TRUE(server.RunStep(stop_).ok());
  // then at 1 s and 2 s the server said who was missing, and once b answered (the first re-sent
  // sample past 2.5 s: re-sends are 200 ms apart on a clock polled every 20 ms) that the start
  // was complete.
  EXPECT_EQ(ReadFile(out_),
            "t=0.000 node=physics event=joining joined=1 expected=2 missing=b\n"
            "t=0.000 node=physics event=joining joined=1 expected=2 missing=b\n"
            "t=0.000 node=physics event=joined joined=2 expected=2 lost=0 wait_s=2.614\n");
  ASSERT_EQ(agents_.statuses.size(), 3u);
  // (at the first look at the clock past each second: the wait polls every 20 ms)
  EXPECT_GE(agents_.statuses[0].wall_ns, 1000 * kMs);
  EXPECT_LT(agents_.statuses[0].wall_ns, 1020 * kMs);
  EXPECT_GE(agents_.statuses[1].wall_ns, 2000 * kMs);
  EXPECT_LT(agents_.statuses[1].wall_ns, 2020 * kMs);
  EXPECT_EQ(agents_.statuses[0].status.missing, std::vector<std::string>{"b"});
  EXPECT_FALSE(agents_.statuses[1].done);
  EXPECT_TRUE(agents_.statuses[2].done);
  EXPECT_EQ(agents_.statuses[2].status.joined, 2u);
  EXPECT_FALSE(world_->Truth(1).lost);
  // Later steps say nothing more about joining.
  ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_EQ(agents_.statuses.size(), 3u);
}

TEST_F(SimServerTest, AQuickCompleteStartPrintsNothingButPublishesItsEnd) {
  SimServer server(*world_, agents_, clock_, nullptr, Options(0), out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  EXPECT_EQ(ReadFile(out_), "");
  ASSERT_EQ(agents_.statuses.size(), 1u);
  EXPECT_TRUE(agents_.statuses[0].done);
  EXPECT_EQ(agents_.statuses[0].status.expected, 2u);
}

// The join timeout counts from the latest join: drones that keep joining are all waited for,
// however long the whole start takes; a drone is given up only when nobody joined for that long.
TEST_F(SimServerTest, TheJoinTimeoutWaitsWhileDronesKeepJoining) {
  // Given a join timeout of 500 ms, a answering from 0.4 s and b from 0.8 s (1.6x the timeout),
  agents_.alive_from_ns["a"] = 400 * kMs;
  agents_.alive_from_ns["b"] = 800 * kMs;
  SimServer server(*world_, agents_, clock_, nullptr, Options(0), out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());
  // then both joined and neither was lost.
  EXPECT_FALSE(world_->Truth(0).lost);
  EXPECT_FALSE(world_->Truth(1).lost);
  EXPECT_EQ(ReadFile(out_), "");
}

TEST_F(SimServerTest, ADroneThatNeverJoinsIsNamedInTheJoinedLine) {
  agents_.alive["b"] = false;
  SimServer server(*world_, agents_, clock_, nullptr, Options(0), out_);
  ASSERT_TRUE(server.RunStep(stop_).ok());  // a at once; b lost 500 ms after a joined
  EXPECT_EQ(ReadFile(out_),
            "t=0.000 node=physics event=drone_lost a=b\n"
            "t=0.000 node=physics event=joined joined=1 expected=2 lost=1 wait_s=0.501 missing=b\n");
}

TEST(Joining, MissingListShowsTenNamesThenACount) {
  std::vector<std::string> names;
  for (int i = 1; i <= 12; ++i) names.push_back("scout_" + std::to_string(i));
  EXPECT_EQ(MissingList(names),
            "scout_1,scout_2,scout_3,scout_4,scout_5,scout_6,scout_7,scout_8,scout_9,scout_10,+2");
  EXPECT_EQ(MissingList({"lifter"}), "lifter");
  EXPECT_EQ(MissingList({}), "-");
  EXPECT_EQ(MissingList(names, 2), "scout_1,scout_2,+10");
}

TEST(Joining, ClockIsDueEverySecondAndOnceAfterAStall) {
  JoiningClock clock(1000 * kMs);
  EXPECT_FALSE(clock.Due(5000 * kMs));  // not begun
  clock.Begin(100 * kMs);
  EXPECT_FALSE(clock.Due(1099 * kMs));
  EXPECT_TRUE(clock.Due(1100 * kMs));
  EXPECT_FALSE(clock.Due(1500 * kMs));
  EXPECT_TRUE(clock.reported());
  EXPECT_TRUE(clock.Due(5300 * kMs));  // a stalled server: one line, not four
  EXPECT_FALSE(clock.Due(6000 * kMs));
  EXPECT_TRUE(clock.Due(6100 * kMs));
  EXPECT_DOUBLE_EQ(clock.End(6200 * kMs), 6.1);
  EXPECT_FALSE(clock.Due(9000 * kMs));
  EXPECT_FALSE(clock.active());
}

}  // namespace
}  // namespace swarmbox::physics
