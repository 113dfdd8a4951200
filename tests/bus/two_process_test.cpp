// Lockstep across two processes, same vendor and across vendors: this process plays the physics
// server (publishes SensorSample step k, waits for the ActuatorCommand of step k), a child
// swarmbox-bus-echo plays the agent. Domains 140..143 (see bus_test_util.hpp).
#include <gtest/gtest.h>

#include "bus_echo.hpp"
#include "bus_test_util.hpp"
#include "message_samples.hpp"
#include "support/child_process.hpp"

namespace swarmbox::bus {
namespace {

struct Pair {
  std::string parent;
  std::string child;
  int domain;
};

class BusTwoProcess : public ::testing::TestWithParam<Pair> {};

TEST_P(BusTwoProcess, LockstepAnswersEveryStepInOrder) {
  const Pair& pair = GetParam();
  testing::EchoOptions echo{.backend = pair.child, .domain_id = pair.domain, .kind = "lockstep",
                            .drone = "drone_1"};
  std::vector<std::string> argv = {SWARMBOX_BUS_ECHO_PATH};
  for (auto& a : testing::EchoArgs(echo)) argv.push_back(a);
  auto child = swarmbox::testing::ChildProcess::Spawn(argv);  // killed by its destructor on every path
  ASSERT_TRUE(child) << child.error().ToString();

  auto p = testing::MakeParticipant(pair.parent, pair.domain);
  ASSERT_TRUE(p);
  auto sensor = p->CreatePublisher<SensorSample>(SensorTopic("drone_1"), Qos::kLockstep);
  auto command = p->CreateSubscriber<ActuatorCommand>(kActuatorTopic, Qos::kLockstep);
  ASSERT_TRUE(sensor && command);
  ASSERT_TRUE((*sensor)->WaitForSubscribers(1, testing::kMatchTimeout));
  ASSERT_TRUE((*command)->WaitForPublishers(1, testing::kMatchTimeout));
  ASSERT_TRUE(child->running());

  constexpr std::uint64_t kSteps = 500;
  SensorSample s = testing::FullSensorSample(1);
  s.drone = "drone_1";
  ActuatorCommand cmd;

  // Handshake: matching is seen per side, so the child's reader may not know our writer yet
  // when our writer already counts it (a volatile reader then misses earlier samples). Resend
  // step 0 every 100 ms until it is answered, as the physics server does after a timeout.
  s.step = 0;
  bool handshaken = false;
  const auto deadline = std::chrono::steady_clock::now() + testing::kMatchTimeout;
  while (!handshaken && std::chrono::steady_clock::now() < deadline) {
    ASSERT_TRUE((*sensor)->Publish(s));
    handshaken = (*command)->TakeFor(cmd, std::chrono::milliseconds(100));
  }
  ASSERT_TRUE(handshaken) << "no answer to step 0 within " << testing::kMatchTimeout.count() << " s";
  ASSERT_EQ(cmd.step, 0u);

  // Strict lockstep: every step is answered with its own step number, in order. Duplicate answers
  // to the resent step 0 may still arrive and are skipped.
  std::uint64_t answered = 1;
  for (std::uint64_t step = 1; step < kSteps; ++step) {
    s.step = step;
    s.sim_time_ns = static_cast<std::int64_t>(step) * 4'000'000;
    ASSERT_TRUE((*sensor)->Publish(s));
    // 2 s per step: reliable delivery on loopback takes well under a millisecond; the slack covers
    // a loaded shared machine.
    do {
      ASSERT_TRUE((*command)->TakeFor(cmd, std::chrono::seconds(2))) << "no command for step " << step;
      ASSERT_LE(cmd.step, step) << "answer to a step not yet sent";
      ASSERT_TRUE(cmd.step == step || cmd.step == 0) << "stale answer " << cmd.step << " at step " << step;
    } while (cmd.step != step);
    ASSERT_EQ(cmd.drone, "drone_1");
    ASSERT_EQ(cmd.sim_time_ns, s.sim_time_ns);
    ++answered;
  }
  EXPECT_EQ(answered, kSteps);
  const int code = child->Stop(std::chrono::seconds(5));
  EXPECT_EQ(code, 0) << "echo did not exit cleanly on SIGTERM, exit code " << code;
}

INSTANTIATE_TEST_SUITE_P(
    Pairs, BusTwoProcess,
    ::testing::Values(Pair{"cyclonedds", "cyclonedds", 140}, Pair{"fastdds", "fastdds", 141},
                      Pair{"cyclonedds", "fastdds", 142}, Pair{"fastdds", "cyclonedds", 143}),
    [](const auto& param_info) { return param_info.param.parent + "_with_" + param_info.param.child; });

}  // namespace
}  // namespace swarmbox::bus
