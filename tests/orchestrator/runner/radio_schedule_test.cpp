// The radio plan of a channel trial (ARCHITECTURE.md "Faults", the radio plan): the mesh impairment, every
// fault at a simulated time as the physics server's entry, targets resolved except raft_leader,
// what stays with the runner, refusals, and the JSON itself.
#include "swarmbox/runner/radio_schedule.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <random>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/faults/physics_plan.hpp"

namespace swarmbox::runner {
namespace {

using ::testing::ElementsAre;
using ::testing::HasSubstr;

dsl::TrialSpec Trial() {
  return dsl::TrialSpec::Named("plan")
      .Seed(7)
      .World("worlds/open_field.yaml")
      .Drone("scout_1", "x500", {0, 0, 0})
      .Drone("scout_2", "x500", {3, 0, 0})
      .Drone("scout_3", "x500", {6, 0, 0})
      .Drone("lifter", "x8_heavy", {0, -10, 0})
      .Timeout(dsl::Duration::Seconds(600));
}

TEST(RadioSchedule, TheMeshImpairmentIsEverySendersEgress) {
  dsl::TrialSpec spec = Trial().Mesh("{delay_ms: 100, jitter_ms: 20, distribution: normal, loss: 0.05}");
  auto plan = PlanRadioSchedule(spec);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_EQ(plan->seed, 7u);
  ASSERT_TRUE(plan->mesh);
  EXPECT_EQ(plan->mesh->delay_ms, 100);
  EXPECT_EQ(plan->mesh->jitter_ms, 20);
  EXPECT_EQ(plan->mesh->distribution, faults::DelayDistribution::kNormal);
  EXPECT_EQ(plan->mesh->loss, 0.05);
  EXPECT_TRUE(plan->schedule.empty());
  EXPECT_EQ(RadioScheduleJson(*plan),
            R"({"seed":7,"mesh":{"delay_ms":100,"jitter_ms":20,"distribution":"normal","loss":0.05,)"
            R"("rate_kbit":0,"duplicate":0},"schedule":[]})");

  auto unimpaired = PlanRadioSchedule(Trial());
  ASSERT_TRUE(unimpaired);
  EXPECT_FALSE(unimpaired->mesh);
  EXPECT_EQ(RadioScheduleJson(*unimpaired), R"({"seed":7,"schedule":[]})");
}

// Every kind at a simulated time, in time order; the design's example entries.
TEST(RadioSchedule, FaultsAtSimulatedTimesBecomeThePhysicsServersEntries) {
  dsl::TrialSpec spec =
      Trial()
          .Fault("{name: split, at: 40s, duration: 20s, partition: {groups: [[scout_1]], oneway: false}}")
          .Fault("{name: kill_leader, at: 30s, kill: raft_leader}")
          .Fault("{name: deg, at: 20s, duration: 10s, radio: {target: scout_1, delay_ms: 300, loss: 0.2}}")
          .Fault("{name: gps, at: 5s, duration: 10s, gps_dropout: scout_1}")
          .Fault("{name: nap, at: 50s, duration: 3s, pause: \"scout_*\"}")
          .Fault("{name: term, at: 60s, duration: 20s, kill: {target: scout_3, signal: SIGTERM}}")
          .Fault("{name: reboot, at: 70s, restart: lifter}")
          .Fault("{name: halt, at: 80s, stop: {target: scout_2, timeout: 5s}}");
  auto plan = PlanRadioSchedule(spec);
  ASSERT_TRUE(plan) << plan.error().ToString();
  std::vector<std::string> names;
  for (const ScheduleEntry& e : plan->schedule) names.push_back(e.name);
  EXPECT_THAT(names, ElementsAre("gps", "deg", "kill_leader", "split", "nap", "term", "reboot", "halt"));

  const ScheduleEntry& gps = plan->schedule[0];
  EXPECT_EQ(gps.kind, ScheduleEntry::Kind::kWorldCommand);
  EXPECT_EQ(gps.at_s, 5.0);
  EXPECT_EQ(gps.target, "scout_1");
  EXPECT_EQ(gps.command, "gps_dropout");
  EXPECT_THAT(gps.args, ElementsAre(10.0));

  const ScheduleEntry& deg = plan->schedule[1];
  EXPECT_EQ(deg.kind, ScheduleEntry::Kind::kRadio);
  EXPECT_THAT(deg.targets, ElementsAre("scout_1"));
  EXPECT_EQ(deg.impairment.delay_ms, 300);
  EXPECT_EQ(deg.impairment.loss, 0.2);
  EXPECT_EQ(deg.duration_s, 10.0);

  // raft_leader is the physics server's to resolve, at the entry's time.
  const ScheduleEntry& kill = plan->schedule[2];
  EXPECT_EQ(kill.kind, ScheduleEntry::Kind::kDroneOut);
  EXPECT_EQ(kill.mode, faults::ProcessAction::kKill);
  EXPECT_THAT(kill.targets, ElementsAre("raft_leader"));
  EXPECT_EQ(kill.duration_s, 0.0);

  // The drones in no group are one more group.
  const ScheduleEntry& split = plan->schedule[3];
  EXPECT_EQ(split.kind, ScheduleEntry::Kind::kPartition);
  EXPECT_THAT(split.groups, ElementsAre(ElementsAre("scout_1"), ElementsAre("scout_2", "scout_3", "lifter")));
  EXPECT_FALSE(split.oneway);
  EXPECT_EQ(split.duration_s, 20.0);

  // A glob is resolved against the drones, in trial order.
  EXPECT_EQ(plan->schedule[4].mode, faults::ProcessAction::kPause);
  EXPECT_THAT(plan->schedule[4].targets, ElementsAre("scout_1", "scout_2", "scout_3"));
  EXPECT_EQ(plan->schedule[4].duration_s, 3.0);
  // In the physics server's modes: a kill that ends is out for its duration and back as a new
  // process (restart); a restart is out for one lockstep step; a stop without an end lasts the
  // rest of the trial.
  EXPECT_EQ(plan->schedule[5].mode, faults::ProcessAction::kRestart);
  EXPECT_EQ(plan->schedule[5].duration_s, 20.0);
  EXPECT_EQ(plan->schedule[6].mode, faults::ProcessAction::kRestart);
  EXPECT_EQ(plan->schedule[6].duration_s, 0.004);
  EXPECT_EQ(plan->schedule[7].mode, faults::ProcessAction::kStop);
  EXPECT_EQ(plan->schedule[7].duration_s, faults::kUntilEndS);

  const std::string json = RadioScheduleJson(*plan);
  auto doc = yaml::Parse(json, "radio_plan.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_THAT(json, HasSubstr(R"({"at_s":30,"name":"kill_leader","kind":"drone_out","mode":"kill",)"
                              R"("targets":["raft_leader"],"duration_s":0})"));
  EXPECT_THAT(json,
              HasSubstr(R"({"at_s":20,"name":"deg","kind":"radio","targets":["scout_1"],)"
                        R"("impairment":{"delay_ms":300,"jitter_ms":0,"distribution":"uniform","loss":0.2,)"
                        R"("rate_kbit":0,"duplicate":0},"duration_s":10})"));
  EXPECT_THAT(
      json,
      HasSubstr(R"({"at_s":40,"name":"split","kind":"partition",)"
                R"("groups":[["scout_1"],["scout_2","scout_3","lifter"]],"oneway":false,"duration_s":20})"));
  EXPECT_THAT(json, HasSubstr(R"({"at_s":5,"name":"gps","kind":"world_command","target":"scout_1",)"
                              R"("command":"gps_dropout","args":[10]})"));
  EXPECT_THAT(json, HasSubstr(R"("name":"reboot","kind":"drone_out","mode":"restart","targets":["lifter"],)"
                              R"("duration_s":0.004})"));
}

// `random` draws from the trial's seed (std::mt19937_64, rng() % drones, in firing order: the
// fault injector's ResolveTarget), so a trial replays the same choice; `all` is every drone.
TEST(RadioSchedule, RandomTargetsComeFromTheTrialsSeed) {
  dsl::TrialSpec spec = Trial()
                            .Fault("{name: second, at: 20s, stop: random}")
                            .Fault("{name: first, at: 10s, kill: random}")
                            .Fault("{name: everyone, at: 30s, duration: 5s, radio: {loss: 0.5}}");
  const std::vector<std::string> drones = {"scout_1", "scout_2", "scout_3", "lifter"};
  std::mt19937_64 rng(7);
  const std::string first = drones[rng() % drones.size()];
  const std::string second = drones[rng() % drones.size()];
  auto plan = PlanRadioSchedule(spec);
  ASSERT_TRUE(plan) << plan.error().ToString();
  ASSERT_EQ(plan->schedule.size(), 3u);
  EXPECT_EQ(plan->schedule[0].name, "first");
  EXPECT_THAT(plan->schedule[0].targets, ElementsAre(first));
  EXPECT_THAT(plan->schedule[1].targets, ElementsAre(second));
  EXPECT_THAT(plan->schedule[2].targets, ElementsAre("scout_1", "scout_2", "scout_3", "lifter"));
  auto again = PlanRadioSchedule(spec);
  ASSERT_TRUE(again);
  EXPECT_EQ(RadioScheduleJson(*again), RadioScheduleJson(*plan));
}

// World commands are the ones faults::PlanPhysicsFault makes; an imu_bias with a duration is taken
// back by its negated jump at its end; a wind gust acts on the world ("" target).
TEST(RadioSchedule, SensorAndWorldFaultsAreWorldCommandsWithTheirUndoAtTheEnd) {
  dsl::TrialSpec spec =
      Trial()
          .Fault("{name: bias, at: 40s, duration: 30s, imu_bias: {target: lifter, accel_m_s2: [0.3, 0, 0]}}")
          .Fault("{name: gust, at: 60s, duration: 5s, wind_gust: {speed_m_s: 12, direction_deg: 270}}")
          .Fault(
              "{name: fix, at: 50s, duration: 20s, gps_degrade: {target: scout_1, h_acc_m: 5, v_acc_m: 8}}");
  auto plan = PlanRadioSchedule(spec);
  ASSERT_TRUE(plan) << plan.error().ToString();
  ASSERT_EQ(plan->schedule.size(), 4u);
  EXPECT_EQ(plan->schedule[0].command, "imu_bias_jump");
  EXPECT_THAT(plan->schedule[0].args, ElementsAre(0.3, 0, 0, 0, 0, 0));
  EXPECT_EQ(plan->schedule[1].command, "gps_degrade");
  EXPECT_THAT(plan->schedule[1].args, ElementsAre(20, 5, 8));
  EXPECT_EQ(plan->schedule[2].command, "wind_gust");
  EXPECT_EQ(plan->schedule[2].target, "");
  EXPECT_THAT(plan->schedule[2].args, ElementsAre(12, 0, 0, 5));
  EXPECT_EQ(plan->schedule[3].name, "bias");
  EXPECT_EQ(plan->schedule[3].at_s, 70.0);
  EXPECT_THAT(plan->schedule[3].args, ElementsAre(-0.3, 0, 0, 0, 0, 0));
}

// Faults triggered by a log event or a wall time stay with the runner's injector.
TEST(RadioSchedule, FaultsOnLogEventsOrWallTimeStayWithTheRunner) {
  dsl::TrialSpec spec = Trial()
                            .Fault("{name: reboot, on: \"event=leader_elected\", restart: raft_leader}")
                            .Fault("{name: freeze, at_wall: 15s, duration: 3s, pause: scout_2}")
                            .Fault("{name: kill_leader, at: 30s, kill: raft_leader}");
  auto plan = PlanRadioSchedule(spec);
  ASSERT_TRUE(plan) << plan.error().ToString();
  ASSERT_EQ(plan->schedule.size(), 1u);
  EXPECT_EQ(plan->schedule[0].name, "kill_leader");
  EXPECT_FALSE(InRadioSchedule(spec.faults[0]));
  EXPECT_FALSE(InRadioSchedule(spec.faults[1]));
  EXPECT_TRUE(InRadioSchedule(spec.faults[2]));
}

TEST(RadioSchedule, RefusesANetemTrialAndWhatTheChannelDoesNotCarryOut) {
  dsl::TrialSpec netem = Trial();
  netem.radio.model = dsl::RadioModel::kNetem;
  auto none = PlanRadioSchedule(netem);
  ASSERT_FALSE(none);
  EXPECT_THAT(none.error().message(), HasSubstr("runs radio.model netem"));

  auto corrupt = PlanRadioSchedule(Trial().Mesh("{loss: 0.1, corrupt: 0.01}"));
  ASSERT_FALSE(corrupt);
  EXPECT_EQ(corrupt.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(corrupt.error().message(), HasSubstr("network.mesh: 'corrupt' is not carried out"));

  auto per_destination = PlanRadioSchedule(Trial().Fault(
      "{name: link, at: 5s, radio: {target: scout_1, rules: [{to: [lifter], delay_ms: 400}]}}"));
  ASSERT_FALSE(per_destination);
  EXPECT_THAT(per_destination.error().message(), HasSubstr("fault link: 'to' is not carried out"));

  auto wall =
      PlanRadioSchedule(Trial().Fault("{name: storm, at_wall: 5s, partition: {groups: [[scout_1]]}}"));
  ASSERT_FALSE(wall);
  EXPECT_THAT(wall.error().message(), HasSubstr("at simulated times only"));
}

}  // namespace
}  // namespace swarmbox::runner
