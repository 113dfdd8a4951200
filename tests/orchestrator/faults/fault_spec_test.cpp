#include "swarmbox/faults/fault_spec.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using testing::Yaml;

const std::vector<std::string> kDrones = {"scout_1", "scout_2", "scout_3", "lifter"};

Result<std::vector<Fault>> Parse(const std::string& text) { return ParseFaults(Yaml(text)); }

TEST(FaultSpec, ParsesTheArchitectureExample) {
  auto faults = Parse("- {at: 30s, kill: raft_leader}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  ASSERT_EQ(faults->size(), 1u);
  const Fault& f = (*faults)[0];
  EXPECT_EQ(f.id, "fault_0");
  EXPECT_EQ(f.kind(), "kill");
  EXPECT_EQ(f.start.clock, FaultStart::Clock::kSim);
  EXPECT_EQ(f.start.at_ms, 30000);
  EXPECT_FALSE(f.duration_ms.has_value());
  const auto& p = std::get<ProcessFault>(f.action);
  EXPECT_EQ(p.target.kind, FaultTarget::Kind::kRaftLeader);
  EXPECT_EQ(p.signal, "SIGKILL");
}

TEST(FaultSpec, ParsesStartsDurationsAndTargets) {
  auto faults = Parse(
      "- {name: freeze, at_wall: 10s, duration: 20s, pause: [scout_1, scout_2]}\n"
      "- {on: \"event=leader_elected\", duration: 1.5s, stop: {target: random, timeout: 5s}}\n"
      "- {at: 40s, radio: {target: \"scout_*\", delay_ms: 200}}\n"
      "- {at: 41s, kill: {target: lifter, signal: SIGTERM}}\n"
      "- {at: 42s, restart: all}\n");
  ASSERT_TRUE(faults) << faults.error().ToString();
  ASSERT_EQ(faults->size(), 5u);
  const Fault& pause = (*faults)[0];
  EXPECT_EQ(pause.id, "freeze");
  EXPECT_EQ(pause.start.clock, FaultStart::Clock::kWall);
  EXPECT_EQ(pause.start.at_ms, 10000);
  EXPECT_EQ(pause.duration_ms, 20000);
  EXPECT_EQ(pause.target()->names, (std::vector<std::string>{"scout_1", "scout_2"}));
  const Fault& stop = (*faults)[1];
  EXPECT_EQ(stop.start.clock, FaultStart::Clock::kEvent);
  EXPECT_EQ(stop.start.event_pattern, "event=leader_elected");
  EXPECT_EQ(stop.start.ToString(), "on event=leader_elected");
  EXPECT_EQ(stop.duration_ms, 1500);
  EXPECT_EQ(std::get<ProcessFault>(stop.action).timeout_s, 5);
  EXPECT_EQ(stop.target()->kind, FaultTarget::Kind::kRandom);
  EXPECT_EQ((*faults)[2].target()->kind, FaultTarget::Kind::kPattern);
  EXPECT_EQ((*faults)[2].target()->pattern, "scout_*");
  EXPECT_EQ(std::get<ProcessFault>((*faults)[3].action).signal, "SIGTERM");
  EXPECT_EQ((*faults)[4].target()->kind, FaultTarget::Kind::kAll);
  EXPECT_EQ((*faults)[4].id, "fault_4");
}

TEST(FaultSpec, RadioDefaultsToAllAgents) {
  auto faults = Parse("- {at: 1s, radio: {loss: 0.2}}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  const auto& radio = std::get<RadioFault>((*faults)[0].action);
  EXPECT_EQ(radio.target.kind, FaultTarget::Kind::kAll);
  ASSERT_EQ(radio.rules.size(), 1u);
  EXPECT_EQ(radio.rules[0].spec.loss, 0.2);
}

TEST(FaultSpec, ParsesAGpsDegradationWithItsAccuracies) {
  auto faults = Parse("- {at: 30s, duration: 20s, gps_degrade: {target: scout_1, h_acc_m: 5, v_acc_m: 8.5}}\n"
                      "- {on: \"event=leader_elected\", gps_degrade: {target: raft_leader, h_acc_m: 1000, v_acc_m: 0.5}}\n");
  ASSERT_TRUE(faults) << faults.error().ToString();
  EXPECT_EQ((*faults)[0].kind(), "gps_degrade");
  const auto& degrade = std::get<GpsDegrade>((*faults)[0].action);
  EXPECT_EQ(degrade.h_acc_m, 5.0);
  EXPECT_EQ(degrade.v_acc_m, 8.5);
  EXPECT_EQ((*faults)[0].target()->names, std::vector<std::string>{"scout_1"});
  EXPECT_EQ((*faults)[1].target()->kind, FaultTarget::Kind::kRaftLeader);
  EXPECT_TRUE(ValidateFaults(*faults, kDrones));
}

TEST(FaultSpec, ValidationNamesAGpsDegradationsUnknownDrone) {
  auto faults = Parse("- {at: 3s, gps_degrade: {target: scout_9, h_acc_m: 5, v_acc_m: 8}}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  Status s = ValidateFaults(*faults, kDrones);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("unknown drone 'scout_9'"), std::string::npos) << s.error().message();
}

TEST(FaultSpec, ParsesPartitionsAndSensorFaults) {
  auto faults = Parse(
      "- {at: 60s, duration: 30s, partition: {groups: [[scout_1, scout_2], [lifter]], oneway: true}}\n"
      "- {at: 20s, duration: 10s, gps_dropout: scout_2}\n"
      "- {at: 25s, imu_bias: {target: lifter, accel_m_s2: [0.2, 0, 0], gyro_rad_s: [0, 0, 0.01]}}\n"
      "- {at: 50s, duration: 5s, wind_gust: {speed_m_s: 12, direction_deg: 270}}\n");
  ASSERT_TRUE(faults) << faults.error().ToString();
  const auto& p = std::get<PartitionFault>((*faults)[0].action);
  EXPECT_TRUE(p.oneway);
  EXPECT_EQ(p.groups.size(), 2u);
  EXPECT_EQ((*faults)[1].kind(), "gps_dropout");
  EXPECT_EQ((*faults)[1].target()->names, std::vector<std::string>{"scout_2"});
  const auto& bias = std::get<ImuBias>((*faults)[2].action);
  EXPECT_EQ(bias.accel_m_s2[0], 0.2);
  EXPECT_EQ(bias.gyro_rad_s[2], 0.01);
  const auto& gust = std::get<WindGust>((*faults)[3].action);
  EXPECT_EQ(gust.speed_m_s, 12);
  EXPECT_EQ(gust.direction_deg, 270);
  EXPECT_EQ((*faults)[3].target(), nullptr);
  EXPECT_TRUE(ValidateFaults(*faults, kDrones));
}

struct BadFault {
  const char* yaml;
  const char* where;
  const char* message;
};

class FaultSpecRejects : public ::testing::TestWithParam<BadFault> {};

TEST_P(FaultSpecRejects, WithReasonAndPlace) {
  auto faults = Parse(GetParam().yaml);
  ASSERT_FALSE(faults);
  EXPECT_EQ(faults.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(faults.error().where(), GetParam().where);
  EXPECT_NE(faults.error().message().find(GetParam().message), std::string::npos) << faults.error().message();
}

INSTANTIATE_TEST_SUITE_P(
    Cases, FaultSpecRejects,
    ::testing::Values(
        BadFault{"- {kill: scout_1}", "trial.yaml:1:3", "exactly one start"},
        BadFault{"- {at: 1s, at_wall: 2s, kill: scout_1}", "trial.yaml:1:3", "exactly one start"},
        BadFault{"- {at: 30, kill: scout_1}", "trial.yaml:1:8", "missing unit"},
        BadFault{"- {at: 3s}", "trial.yaml:1:3", "a fault needs one kind"},
        BadFault{"- {at: 3s, kill: a, pause: b}", "trial.yaml:1:3", "exactly one kind"},
        BadFault{"- {at: 3s, explode: a}", "trial.yaml:1:12", "unknown key 'explode' in fault"},
        BadFault{"- {at: 3s, duration: 2s, restart: a}", "trial.yaml:1:22", "cannot have a 'duration'"},
        BadFault{"- {at: 3s, duration: 0s, kill: a}", "trial.yaml:1:22", "'duration' must be positive"},
        BadFault{"- {on: leader_elected, kill: a}", "trial.yaml:1:8", "a log pattern"},
        BadFault{"- {at: 3s, kill: {target: a, signal: KILL}}", "trial.yaml:1:38", "a signal name"},
        BadFault{"- {at: 3s, kill: {signal: SIGTERM}}", "trial.yaml:1:18", "missing required key 'target'"},
        BadFault{"- {at: 3s, kill: \"a b\"}", "trial.yaml:1:18", "neither a drone name"},
        BadFault{"- {at: 3s, pause: [a, a]}", "trial.yaml:1:23", "listed twice"},
        BadFault{"- {at: 3s, partition: {groups: [[a], []]}}", "trial.yaml:1:38", "group 1 is empty"},
        BadFault{"- {at: 3s, wind_gust: {speed_m_s: 500}}", "trial.yaml:1:35", "'speed_m_s' must be in [0, 100]"},
        BadFault{"- {at: 3s, imu_bias: {target: a}}", "trial.yaml:1:22", "imu_bias changes nothing"},
        BadFault{"- {at: 3s, gps_degrade: a}", "trial.yaml:1:25", "expected gps_degrade to be a mapping"},
        BadFault{"- {at: 3s, gps_degrade: {h_acc_m: 5, v_acc_m: 8}}", "trial.yaml:1:25",
                 "missing required key 'target' in gps_degrade"},
        BadFault{"- {at: 3s, gps_degrade: {target: a, h_acc_m: 5}}", "trial.yaml:1:25",
                 "missing required key 'v_acc_m' in gps_degrade"},
        BadFault{"- {at: 3s, gps_degrade: {target: a, h_acc_m: 0, v_acc_m: 8}}", "trial.yaml:1:46",
                 "'h_acc_m' is the degraded 1-sigma accuracy in metres, in (0, 1000]; got 0 (for no fix at all use "
                 "gps_dropout)"},
        BadFault{"- {at: 3s, gps_degrade: {target: a, h_acc_m: 5, v_acc_m: 1e4}}", "trial.yaml:1:58",
                 "'v_acc_m' is the degraded 1-sigma accuracy in metres, in (0, 1000]; got 10000"},
        BadFault{"- {at: 3s, gps_degrade: {target: a, h_acc_m: 5, v_acc_m: 8, hdop: 3}}", "trial.yaml:1:61",
                 "unknown key 'hdop' in gps_degrade"},
        BadFault{"- {at: 3s, radio: {target: a, loss: 2}}", "trial.yaml:1:37", "'loss' is a probability"},
        BadFault{"- {at: 1s, name: x, kill: a}\n- {at: 2s, name: x, kill: b}", "trial.yaml:2:3",
                 "two faults are named 'x'"}));

TEST(FaultSpec, ValidationNamesTheUnknownDrone) {
  auto faults = Parse("- {at: 1s, kill: scout_1}\n- {at: 2s, pause: [scout_2, scout_9]}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  Status s = ValidateFaults(*faults, kDrones);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().where(), "trial.yaml:2:3");
  EXPECT_EQ(s.error().message(), "unknown drone 'scout_9' (drones: scout_1, scout_2, scout_3, lifter)");
}

TEST(FaultSpec, ValidationRefusesAPatternThatMatchesNothing) {
  auto faults = Parse("- {at: 1s, radio: {target: \"relay_*\", loss: 0.1}}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  Status s = ValidateFaults(*faults, kDrones);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("pattern 'relay_*' matches no drone"), std::string::npos);
}

TEST(FaultSpec, ValidationRefusesPerDestinationRuleWithUnknownPeer) {
  auto faults = Parse("- {at: 1s, radio: {target: scout_1, loss: 0.1, to: [ghost]}}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  Status s = ValidateFaults(*faults, kDrones);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("unknown peer 'ghost'"), std::string::npos) << s.error().message();
}

TEST(FaultSpec, ValidationRefusesARuleToTheTargetItself) {
  auto faults = Parse("- {at: 1s, radio: {target: scout_1, loss: 0.1, to: [scout_1]}}");
  ASSERT_TRUE(faults) << faults.error().ToString();
  Status s = ValidateFaults(*faults, kDrones);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message(), "per-destination rule names its own target 'scout_1'");
}

TEST(FaultSpec, ValidationRefusesBadPartitions) {
  auto twice = Parse("- {at: 1s, partition: {groups: [[scout_1], [scout_1, scout_2]]}}");
  ASSERT_TRUE(twice);
  Status s = ValidateFaults(*twice, kDrones);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().message(), "drone 'scout_1' is in two partition groups");
  auto one_group = Parse("- {at: 1s, partition: {groups: [[scout_1, scout_2, scout_3, lifter]]}}");
  ASSERT_TRUE(one_group);
  s = ValidateFaults(*one_group, kDrones);
  ASSERT_FALSE(s);
  EXPECT_NE(s.error().message().find("at least two groups"), std::string::npos);
  // One named group and the implicit rest make two.
  auto with_rest = Parse("- {at: 1s, partition: {groups: [[scout_1]]}}");
  ASSERT_TRUE(with_rest);
  EXPECT_TRUE(ValidateFaults(*with_rest, kDrones));
}

TEST(FaultSpec, EmptyOrAbsentListHasNoFaults) {
  auto none = ParseFaults(yaml::Node());
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->empty());
  auto bad = Parse("{at: 1s}");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message(), "expected 'faults' to be a list");
}

}  // namespace
}  // namespace swarmbox::faults
