// The radio plan JSON (radio_plan.hpp): the contract's example, and errors at file:line:col.
#include "radio_plan.hpp"

#include <gtest/gtest.h>

namespace swarmbox::physics {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

Result<RadioPlan> Parse(const std::string& json) {
  auto doc = yaml::Parse(json, "plan.json");
  if (!doc) return doc.error();
  return ParseRadioPlan(*doc);
}

TEST(RadioPlan, ParsesTheContractExampleSortedByTime) {
  auto plan = Parse(R"({
  "seed": 42,
  "mesh": {"delay_ms": 100, "jitter_ms": 20, "distribution": "normal", "loss": 0.05,
           "rate_kbit": 0, "duplicate": 0},
  "schedule": [
    {"at_s": 30.0, "name": "kill_leader", "kind": "drone_out", "mode": "kill",
     "targets": ["raft_leader"], "duration_s": 0},
    {"at_s": 20.0, "name": "deg", "kind": "radio", "targets": ["scout_1"],
     "impairment": {"delay_ms": 300, "loss": 0.2}, "duration_s": 10},
    {"at_s": 40.0, "name": "split", "kind": "partition",
     "groups": [["scout_1"], ["scout_2", "scout_3", "lifter"]], "oneway": false, "duration_s": 20},
    {"at_s": 5.0, "name": "gps", "kind": "world_command", "target": "scout_1",
     "command": "gps_dropout", "args": [10.0]}
  ]
})");
  ASSERT_TRUE(plan.ok()) << plan.error().ToString();
  EXPECT_EQ(plan->seed, std::optional<std::uint64_t>(42));
  ASSERT_TRUE(plan->mesh.has_value());
  EXPECT_EQ(*plan->mesh, (PlanImpairment{100, 20, "normal", 0.05, 0, 0}));
  ASSERT_EQ(plan->schedule.size(), 4u);
  const PlanEntry& gps = plan->schedule[0];
  EXPECT_EQ(gps.kind, PlanEntry::Kind::kWorldCommand);
  EXPECT_EQ(gps.at_ns, 5 * kS);
  EXPECT_EQ(gps.target, "scout_1");
  EXPECT_EQ(gps.command, "gps_dropout");
  EXPECT_EQ(gps.args, std::vector<double>{10.0});
  const PlanEntry& deg = plan->schedule[1];
  EXPECT_EQ(deg.kind, PlanEntry::Kind::kRadio);
  EXPECT_EQ(deg.duration_ns, 10 * kS);
  EXPECT_EQ(deg.impairment, (PlanImpairment{300, 0, "normal", 0.2, 0, 0}));
  const PlanEntry& kill = plan->schedule[2];
  EXPECT_EQ(kill.kind, PlanEntry::Kind::kDroneOut);
  EXPECT_EQ(kill.mode, PlanEntry::Mode::kKill);
  EXPECT_EQ(kill.targets, std::vector<std::string>{"raft_leader"});
  EXPECT_EQ(kill.where, "plan.json:6:5");
  const PlanEntry& split = plan->schedule[3];
  EXPECT_EQ(split.kind, PlanEntry::Kind::kPartition);
  ASSERT_EQ(split.groups.size(), 2u);
  EXPECT_EQ(split.groups[1].size(), 3u);
  EXPECT_FALSE(split.oneway);
  EXPECT_TRUE(CheckRadioPlan(*plan, {"scout_1", "scout_2", "scout_3", "lifter"}).ok());
}

TEST(RadioPlan, AnEmptyPlanHasNoMeshAndNoSchedule) {
  auto plan = Parse("{}");
  ASSERT_TRUE(plan.ok()) << plan.error().ToString();
  EXPECT_FALSE(plan->seed.has_value());
  EXPECT_FALSE(plan->mesh.has_value());
  EXPECT_TRUE(plan->schedule.empty());
}

TEST(RadioPlan, ErrorsPointAtTheEntry) {
  auto expect_error = [](const std::string& json, const std::string& message) {
    auto plan = Parse(json);
    ASSERT_FALSE(plan.ok()) << json;
    EXPECT_EQ(plan.error().ToString(), message);
  };
  expect_error(R"({"schedule": [
  {"at_s": 1, "name": "x", "kind": "explode"}]})",
               "plan.json:2:3: unknown kind 'explode' (drone_out, world_command, radio, partition)");
  expect_error(R"({"schedule": [
  {"at_s": 1, "name": "k", "kind": "drone_out", "mode": "kill", "targets": ["a"], "duration_s": 5}]})",
               "plan.json:2:3: a kill stays out: duration_s must be 0");
  expect_error(R"({"schedule": [
  {"at_s": 1, "name": "s", "kind": "drone_out", "mode": "stop", "targets": ["a"]}]})",
               "plan.json:2:3: mode stop needs duration_s > 0 (the drone comes back after it)");
  expect_error(R"({"schedule": [
  {"at_s": -1, "name": "s", "kind": "drone_out", "mode": "kill", "targets": ["a"]}]})",
               "plan.json:2:3: at_s must be a simulated time >= 0");
  expect_error(R"({"mesh": {"loss": 5}})", "plan.json:1:10: mesh: loss and duplicate are probabilities in [0, 1]");
  expect_error(R"({"mesh": {"distribution": "experimental"}})",
               "plan.json:1:10: mesh: distribution 'experimental' is not one of normal, uniform, pareto, paretonormal");
  expect_error(R"({"mesh": {"reorder_gap": 5}})", "plan.json:1:11: unknown key 'reorder_gap' in mesh (accepted: delay_ms, jitter_ms, distribution, loss, rate_kbit, "
               "duplicate)");
  expect_error(R"({"schedule": [
  {"at_s": 1, "name": "p", "kind": "partition", "groups": [["a"]]}]})",
               "plan.json:2:3: a partition needs at least two groups");
  expect_error(R"({"schedule": [
  {"at_s": 1, "name": "r", "kind": "radio", "targets": ["a"]}]})",
               "plan.json:2:3: missing required key 'impairment' in schedule entry");
}

TEST(RadioPlan, CheckNamesUnknownDronesAndBadWorldCommands) {
  auto plan = Parse(R"({"schedule": [
  {"at_s": 1, "name": "r", "kind": "radio", "targets": ["raft_leader"], "impairment": {"loss": 0.1}}]})");
  ASSERT_TRUE(plan.ok()) << plan.error().ToString();
  Status s = CheckRadioPlan(*plan, {"a", "b"});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().ToString(), "plan.json:2:3: entry 'r': unknown drone 'raft_leader'");
  auto cmd = Parse(R"({"schedule": [
  {"at_s": 1, "name": "g", "kind": "world_command", "target": "a", "command": "gps_dropout"}]})");
  ASSERT_TRUE(cmd.ok()) << cmd.error().ToString();
  s = CheckRadioPlan(*cmd, {"a", "b"});
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().ToString(), "plan.json:2:3: entry 'g': gps_dropout: needs a drone and duration_s > 0");
  auto out = Parse(R"({"schedule": [
  {"at_s": 1, "name": "k", "kind": "drone_out", "mode": "kill", "targets": ["c"]}]})");
  ASSERT_TRUE(out.ok());
  EXPECT_EQ(CheckRadioPlan(*out, {"a", "b"}).error().message(), "entry 'k': unknown drone 'c'");
}

}  // namespace
}  // namespace swarmbox::physics
