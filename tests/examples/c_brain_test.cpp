// examples/c_brain (swarmbox_c_brain) as an agent meets it: this process plays the agent over the
// bus library (publishes BrainInputs of a scripted flight on offboard/scout_2/input, reads the
// BrainOutputs on offboard/scout_2/output, both kLockstep), the C program runs as a child on a DDS
// domain of its own (64..71) with CYCLONEDDS_URI binding it to lo. Checked: every
// input is answered by exactly one output with its sim_time_ns, and the rendezvous protocol
// (design of issue #24): takeoff first, a `pos` proposal once hovering (again after 2 s of
// simulated time), the slot setpoint once every member's `pos` is committed, `arrived` near the
// slot, land hold_s after every `arrived`, rendezvous_complete once landed; SIGTERM -> exit 0.
#include <gtest/gtest.h>
#include <unistd.h>

#include <csignal>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include "support/child_process.hpp"
#include "support/files.hpp"
#include "support/logged_child.hpp"
#include "swarmbox/bus/participant.hpp"
#include "swarmbox/bus/topics.hpp"

namespace swarmbox {
namespace {

using namespace std::chrono_literals;

constexpr std::int64_t kPeriodNs = 20'000'000;  // an external brain's default period (50 Hz)
constexpr auto kAnswerTimeout = 10s;            // a hang guard, never a speed assertion

// DDS domains 64..71: even for the flight, odd for the other case (ctest runs them side by side),
// spread by process id over concurrent runs.
int Domain(int slot) { return 64 + slot + 2 * static_cast<int>(::getpid() % 4); }

// Cyclone DDS of the child: lo, multicast on (as the bus binds its own participants).
constexpr const char* kCycloneUri =
    "<CycloneDDS><Domain Id=\"any\"><General><Interfaces><NetworkInterface name=\"lo\" "
    "multicast=\"true\"/></Interfaces><AllowMulticast>true</AllowMulticast></General>"
    "</Domain></CycloneDDS>";

std::vector<std::uint8_t> Bytes(const std::string& text) { return {text.begin(), text.end()}; }
std::string Text(const std::vector<std::uint8_t>& bytes) { return {bytes.begin(), bytes.end()}; }

class CBrain : public ::testing::Test {
 protected:
  // Joins domain Domain(slot) as the agent of scout_2.
  void Join(int slot) {
    domain_ = Domain(slot);
    dir_ = testing::MakeTempDir("swarmbox-c-brain-");
    ASSERT_FALSE(dir_.empty());
    auto p = bus::Participant::Create({.backend = "cyclonedds", .domain_id = domain_, .interface = "lo"});
    ASSERT_TRUE(p) << p.error().ToString();
    participant_ = std::move(*p);
    auto in = participant_->CreatePublisher<bus::BrainInput>(bus::OffboardInputTopic("scout_2"),
                                                             bus::Qos::kLockstep);
    ASSERT_TRUE(in) << in.error().ToString();
    input_ = std::move(*in);
    auto out = participant_->CreateSubscriber<bus::BrainOutput>(bus::OffboardOutputTopic("scout_2"),
                                                                bus::Qos::kLockstep);
    ASSERT_TRUE(out) << out.error().ToString();
    output_ = std::move(*out);
  }
  void TearDown() override {
    brain_.reset();
    if (!dir_.empty()) std::filesystem::remove_all(dir_);
  }

  // Starts the brain (members deliberately unsorted) and shakes hands as the agent does: the first
  // input is resent until answered (matching is seen per side: the child's reader may not know our
  // writer yet and would miss it), then the answers to the copies are drained (each the same).
  void StartBrain(const bus::BrainInput& first) {
    ::setenv("CYCLONEDDS_URI", kCycloneUri, 1);
    brain_.emplace(std::vector<std::string>{SWARMBOX_C_BRAIN_BIN, "--drone", "scout_2", "--domain",
                                            std::to_string(domain_), "--members",
                                            "scout_3,scout_1,scout_2", "--hold-s", "3"},
                   dir_ + "/brain.log");
    ASSERT_TRUE(brain_->running()) << brain_->spawn_error();
    ASSERT_TRUE(brain_->WaitForLog("answering offboard/scout_2/input", kAnswerTimeout)) << brain_->ReadLog();
    ASSERT_TRUE(input_->WaitForSubscribers(1, kAnswerTimeout));
    ASSERT_TRUE(output_->WaitForPublishers(1, kAnswerTimeout));
    bool answered = false;
    bus::BrainOutput out;
    const auto deadline = std::chrono::steady_clock::now() + kAnswerTimeout;
    while (!answered && std::chrono::steady_clock::now() < deadline) {
      ASSERT_TRUE(input_->Publish(first));
      answered = output_->TakeFor(out, 100ms);
    }
    ASSERT_TRUE(answered) << "no answer to the first input\n" << brain_->ReadLog();
    first_ = out;
    while (output_->TakeFor(out, 300ms)) {
      ASSERT_EQ(out.sim_time_ns, first.sim_time_ns) << "an answer to an input never sent";
      ASSERT_EQ(out, first_) << "a resent input answered differently";
    }
  }

  // Publishes `in` and returns the one answer; the test fails if the next output answers
  // anything else (a duplicate or a missing answer shows here).
  bus::BrainOutput Exchange(const bus::BrainInput& in) {
    EXPECT_TRUE(input_->Publish(in));
    bus::BrainOutput out;
    if (!output_->TakeFor(out, kAnswerTimeout)) {
      ADD_FAILURE() << "no answer to t=" << in.sim_time_ns << " ns\n" << brain_->ReadLog();
      return out;
    }
    EXPECT_EQ(out.sim_time_ns, in.sim_time_ns) << "answered another input";
    EXPECT_EQ(out.drone, "scout_2");
    return out;
  }

  int domain_ = 0;
  std::string dir_;
  std::unique_ptr<bus::Participant> participant_;
  std::unique_ptr<bus::Publisher<bus::BrainInput>> input_;
  std::unique_ptr<bus::Subscriber<bus::BrainOutput>> output_;
  std::optional<testing::LoggedChild> brain_;
  bus::BrainOutput first_;
};

// One scripted BrainInput at `t_ns`: the vehicle's mode and position (landed in init, idle, landed).
bus::BrainInput Input(std::int64_t t_ns, const std::string& mode, double x, double y, double z) {
  bus::BrainInput in;
  in.drone = "scout_2";
  in.sim_time_ns = t_ns;
  in.vehicle.drone = "scout_2";
  in.vehicle.sim_time_ns = t_ns;
  in.vehicle.step = static_cast<std::uint64_t>(t_ns / 4'000'000);
  in.vehicle.position_enu_m = {x, y, z};
  in.vehicle.flight_mode = mode;
  in.vehicle.landed = mode == "init" || mode == "idle" || mode == "landed";
  in.vehicle.armed = !in.vehicle.landed;
  in.vehicle.battery_fraction = 0.9;
  in.leader = "scout_1";
  return in;
}

void Commit(bus::BrainInput& in, std::uint64_t index, const std::string& text) {
  in.committed.push_back({index, Bytes(text)});
}

void FlightEvent(bus::BrainInput& in, const std::string& name) {
  in.flight_events.push_back({.node = "scout_2", .sim_time_ns = in.sim_time_ns, .name = name, .fields = {}});
}

std::vector<std::string> Proposals(const bus::BrainOutput& out) {
  std::vector<std::string> texts;
  for (const auto& p : out.proposals) texts.push_back(Text(p.data));
  return texts;
}

std::vector<std::string> Commands(const bus::BrainOutput& out) {
  std::vector<std::string> names;
  for (const auto& c : out.commands) names.push_back(c.command);
  return names;
}

TEST_F(CBrain, FliesTheRendezvousAnsweringEveryInputOnce) {
  ASSERT_NO_FATAL_FAILURE(Join(0));
  std::int64_t t = 0;
  // Landed, the estimator not ready ("init": the flight stack would refuse a takeoff): wait.
  ASSERT_NO_FATAL_FAILURE(StartBrain(Input(t, "init", 0.0, 0.0, 0.0)));
  EXPECT_TRUE(first_.commands.empty());
  EXPECT_TRUE(first_.setpoint.empty());
  EXPECT_EQ(first_.status, "rendezvous/takeoff");

  // 1. Landed and ready: takeoff(altitude_m) first, once.
  auto out = Exchange(Input(t += kPeriodNs, "idle", 1.0, -2.0, 0.0));
  ASSERT_EQ(out.commands.size(), 1u);
  EXPECT_EQ(out.commands[0].command, "takeoff");
  EXPECT_DOUBLE_EQ(out.commands[0].param, 10.0);
  EXPECT_TRUE(out.setpoint.empty());
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_EQ(out.status, "rendezvous/takeoff");
  out = Exchange(Input(t += kPeriodNs, "takeoff", 1.0, -2.0, 3.0));
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(out.status, "rendezvous/takeoff");

  // 2. Hovering: propose its position there, the same entry again 2 s (simulated) later until
  // committed.
  auto hover = Input(t += kPeriodNs, "hold", 1.2344, -2.5, 10.0);
  FlightEvent(hover, "hover");
  const std::int64_t proposed_ns = t;
  out = Exchange(hover);
  EXPECT_EQ(Proposals(out), std::vector<std::string>{"pos scout_2 1.234 -2.500"});
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(out.status, "rendezvous/voting");
  out = Exchange(Input(t += kPeriodNs, "hold", 1.3, -2.5, 10.0));
  EXPECT_TRUE(out.proposals.empty());
  t = proposed_ns + 2'000'000'000 - kPeriodNs;
  out = Exchange(Input(t, "hold", 1.3, -2.5, 10.0));
  EXPECT_TRUE(out.proposals.empty()) << "re-proposed before 2 s";
  out = Exchange(Input(t += kPeriodNs, "hold", 1.3, -2.5, 10.0));
  EXPECT_EQ(Proposals(out), std::vector<std::string>{"pos scout_2 1.234 -2.500"}) << "not the same entry";
  EXPECT_EQ(out.status, "rendezvous/voting");

  // 3. A `pos` of every member committed (the first per member counts; other entries ignored):
  // P = mean in sorted member order; scout_2 is index 1 of 3: slot = P + 6 (cos 2pi/3, sin 2pi/3).
  auto all_pos = Input(t += kPeriodNs, "hold", 1.3, -2.5, 10.0);
  Commit(all_pos, 5, "pos scout_1 0.000 0.000");
  Commit(all_pos, 6, "pos scout_2 1.234 -2.500");
  Commit(all_pos, 7, "victim 3 4");
  Commit(all_pos, 9, "pos scout_1 100.000 100.000");
  Commit(all_pos, 12, "pos scout_3 3.000 6.000");
  out = Exchange(all_pos);
  const double px = ((0.0 + 1.234) + 3.0) / 3.0;
  const double py = ((0.0 + -2.5) + 6.0) / 3.0;
  const double a = 2.0 * std::numbers::pi * 1.0 / 3.0;
  const double sx = px + 6.0 * std::cos(a);
  const double sy = py + 6.0 * std::sin(a);
  ASSERT_EQ(out.setpoint.size(), 1u);
  EXPECT_NEAR(out.setpoint[0].position_enu_m[0], sx, 1e-9);
  EXPECT_NEAR(out.setpoint[0].position_enu_m[1], sy, 1e-9);
  EXPECT_EQ(out.setpoint[0].position_enu_m[2], 10.0);
  for (std::size_t axis = 0; axis < 3; ++axis) {
    EXPECT_TRUE(std::isnan(out.setpoint[0].velocity_enu_m_s[axis]));
    EXPECT_TRUE(std::isnan(out.setpoint[0].acceleration_enu_m_s2[axis]));
  }
  EXPECT_TRUE(std::isnan(out.setpoint[0].yaw_rad));
  EXPECT_TRUE(std::isnan(out.setpoint[0].yawspeed_rad_s));
  EXPECT_TRUE(out.proposals.empty());
  EXPECT_EQ(out.status, "rendezvous/flying");
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].name, "rendezvous_point");
  EXPECT_EQ(out.events[0].node, "scout_2");
  EXPECT_EQ(out.events[0].fields, (std::vector<bus::KeyValue>{{"x", "1.411"}, {"y", "1.167"}}));

  out = Exchange(Input(t += kPeriodNs, "position", 0.0, 0.0, 10.0));
  ASSERT_EQ(out.setpoint.size(), 1u);
  EXPECT_TRUE(out.events.empty()) << "rendezvous_point twice";
  EXPECT_EQ(out.status, "rendezvous/flying");

  // 4. Within 1 m of the slot: `arrived`, once until 2 s have passed.
  out = Exchange(Input(t += kPeriodNs, "position", sx + 0.6, sy - 0.7, 10.0));
  EXPECT_EQ(Proposals(out), std::vector<std::string>{"arrived scout_2"});
  EXPECT_EQ(out.setpoint.size(), 1u);
  EXPECT_EQ(out.status, "rendezvous/arrived");
  out = Exchange(Input(t += kPeriodNs, "position", sx, sy, 10.0));
  EXPECT_TRUE(out.proposals.empty());
  auto two_arrived = Input(t += kPeriodNs, "position", sx, sy, 10.0);
  Commit(two_arrived, 14, "arrived scout_2");
  Commit(two_arrived, 15, "arrived scout_1");
  out = Exchange(two_arrived);
  EXPECT_EQ(out.status, "rendezvous/arrived");
  EXPECT_TRUE(out.commands.empty());

  // 5. Every `arrived` committed: hold_s (3 s, simulated) on the slot, then land.
  auto all_arrived = Input(t += kPeriodNs, "position", sx, sy, 10.0);
  Commit(all_arrived, 16, "arrived scout_3");
  const std::int64_t all_arrived_ns = t;
  out = Exchange(all_arrived);
  EXPECT_EQ(out.status, "rendezvous/landing");
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(out.setpoint.size(), 1u);
  t = all_arrived_ns + 3'000'000'000 - kPeriodNs;
  out = Exchange(Input(t, "position", sx, sy, 10.0));
  EXPECT_TRUE(out.commands.empty()) << "landed before hold_s";
  out = Exchange(Input(t += kPeriodNs, "position", sx, sy, 10.0));
  EXPECT_EQ(Commands(out), std::vector<std::string>{"land"});
  EXPECT_TRUE(out.setpoint.empty());
  EXPECT_EQ(out.status, "rendezvous/landing");
  out = Exchange(Input(t += kPeriodNs, "land", sx, sy, 4.0));
  EXPECT_TRUE(out.commands.empty());
  EXPECT_TRUE(out.events.empty());
  EXPECT_EQ(out.status, "rendezvous/landing");

  // Landed (the flight event comes first; vehicle.landed may follow a step later):
  // rendezvous_complete once, then done.
  auto landed = Input(t += kPeriodNs, "land", sx, sy, 0.0);
  FlightEvent(landed, "landed");
  out = Exchange(landed);
  ASSERT_EQ(out.events.size(), 1u);
  EXPECT_EQ(out.events[0].name, "rendezvous_complete");
  EXPECT_EQ(out.events[0].fields, (std::vector<bus::KeyValue>{{"members", "3"}}));
  EXPECT_EQ(out.status, "rendezvous/done");
  out = Exchange(Input(t += kPeriodNs, "landed", sx, sy, 0.0));
  EXPECT_TRUE(out.events.empty());
  EXPECT_TRUE(out.commands.empty());
  EXPECT_EQ(out.status, "rendezvous/done");

  // No answer beyond one per input.
  bus::BrainOutput extra;
  EXPECT_FALSE(output_->TakeFor(extra, 300ms)) << "an extra answer to t=" << extra.sim_time_ns;

  // SIGTERM: exit 0.
  ASSERT_TRUE(brain_->Terminate());
  EXPECT_EQ(brain_->Wait(10s), 0) << brain_->ReadLog();
  EXPECT_NE(brain_->ReadLog().find("node=scout_2 status=rendezvous/done"), std::string::npos)
      << brain_->ReadLog();
}

TEST_F(CBrain, AnswersARepeatedInputTheSameAndSigintEndsItWithExitZero) {
  ASSERT_NO_FATAL_FAILURE(Join(1));
  const auto first = Input(0, "idle", 0.0, 0.0, 0.0);
  ASSERT_NO_FATAL_FAILURE(StartBrain(first));
  EXPECT_EQ(Commands(first_), std::vector<std::string>{"takeoff"});
  // The agent resends its first input until it hears an answer: every copy gets the same answer
  // (the takeoff is not lost to whichever copy the agent keeps), the brain steps once.
  for (int copy = 0; copy < 2; ++copy) EXPECT_EQ(Exchange(first), first_);
  EXPECT_TRUE(Exchange(Input(kPeriodNs, "takeoff", 0.0, 0.0, 1.0)).commands.empty());
  ASSERT_TRUE(brain_->Signal(SIGINT));
  EXPECT_EQ(brain_->Wait(10s), 0) << brain_->ReadLog();
}

TEST(CBrainCommandLine, RefusesABadCommandLineWithExitTwoAndTheReason) {
  const std::string dir = testing::MakeTempDir("swarmbox-c-brain-args-");
  ASSERT_FALSE(dir.empty());
  struct Case {
    std::vector<std::string> args;
    std::string reason;
  };
  const std::vector<Case> cases = {
      {{"--drone", "scout_1"}, "--members is required"},
      {{"--members", "a,b"}, "--drone is required"},
      {{"--drone", "c", "--members", "a,b"}, "--members 'a,b': does not name --drone"},
      {{"--drone", "a", "--members", "a,b,a"}, "a member is named twice"},
      {{"--drone", "a-1", "--members", "a-1"}, "--drone 'a-1': a drone name is [A-Za-z0-9_]+"},
      {{"--drone", "a", "--members", "a", "--hold-s", "soon"}, "--hold-s 'soon': not a number"},
      {{"--drone", "a", "--members", "a", "--domain", "233"}, "an integer 0 to 232"},
      {{"--drone", "a", "--members", "a", "--speed", "3"}, "flag '--speed': unknown flag"},
  };
  for (const auto& c : cases) {
    std::vector<std::string> argv = {SWARMBOX_C_BRAIN_BIN};
    argv.insert(argv.end(), c.args.begin(), c.args.end());
    auto r = testing::RunToEnd(argv, 10s, dir);
    ASSERT_TRUE(r) << r.error().ToString();
    EXPECT_EQ(r->code, 2) << c.reason;
    EXPECT_NE(r->err.find(c.reason), std::string::npos) << r->err;
  }
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox
