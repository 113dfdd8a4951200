// Trial files -> TrialSpec. Good files decode to the model; bad ones fail with file:line:col and a
// message that says what is wrong (cases as data).
#include "swarmbox/dsl/trial_loader.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <set>
#include <string>

namespace swarmbox::dsl {
namespace {

constexpr const char* kExample = R"(name: sar-search
seed: 42
middleware: cyclonedds
world: worlds/open_field.yaml
physics: {rtf: 1.0}
drones:
  - {name: scout_1, airframe: x500, pose: [0, 0, 0]}
  - {name: scout_2, airframe: x500, pose: [3, 0, 0]}
  - {name: lifter, airframe: x8_heavy, pose: [0, -10, 0], payload: stretcher}
network:
  mesh: {delay_ms: 100, jitter_ms: 20, loss: 0.05}
faults:
  - {at: 30s, kill: raft_leader}
end:
  - {on: "event=mission_complete", outcome: success}
  - {on: "event=collision", outcome: failure, reason: collision}
timeout: {sim: 600s, outcome: timeout}
)";

LoadOptions FakeTree() {
  LoadOptions o;
  o.trials_dir = "/trials";
  o.file_exists = [](const std::string& p) {
    static const std::set<std::string> files = {"/trials/worlds/open_field.yaml",
                                                "/trials/airframes/x500.yaml",
                                                "/trials/airframes/x8_heavy.yaml"};
    return files.count(p) > 0;
  };
  return o;
}

TEST(LoadTrial, DecodesTheArchitectureExample) {
  auto spec = LoadTrialText(kExample, "sar.yaml", FakeTree());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->name, "sar-search");
  EXPECT_EQ(spec->seed, 42u);
  EXPECT_EQ(spec->middleware, Middleware::kCycloneDds);
  EXPECT_EQ(spec->world, "worlds/open_field.yaml");
  EXPECT_DOUBLE_EQ(spec->rtf, 1.0);
  ASSERT_EQ(spec->drones.size(), 3u);
  EXPECT_EQ(spec->drones[2].name, "lifter");
  EXPECT_EQ(spec->drones[2].airframe, "x8_heavy");
  EXPECT_EQ(spec->drones[2].payload, "stretcher");
  EXPECT_DOUBLE_EQ(spec->drones[2].pose[1], -10.0);
  EXPECT_EQ(spec->drones[1].mark.ToString(), "sar.yaml:8:5");
  ASSERT_EQ(spec->mesh.rules.size(), 1u);
  EXPECT_DOUBLE_EQ(spec->mesh.rules[0].spec.delay_ms, 100);
  EXPECT_DOUBLE_EQ(spec->mesh.rules[0].spec.loss, 0.05);
  ASSERT_EQ(spec->faults.size(), 1u);
  EXPECT_EQ(spec->faults[0].kind(), "kill");
  EXPECT_EQ(spec->faults[0].start.at_ms, 30000);
  EXPECT_EQ(spec->faults[0].target()->ToString(), "raft_leader");
  ASSERT_EQ(spec->end.size(), 2u);
  EXPECT_EQ(spec->end[1].on, "event=collision");
  EXPECT_EQ(spec->end[1].outcome, Outcome::kFailure);
  EXPECT_EQ(spec->end[1].reason, "collision");
  EXPECT_EQ(spec->timeout.sim.ms(), 600000);
  EXPECT_EQ(spec->timeout.outcome, Outcome::kTimeout);
}

TEST(LoadTrial, FaultsUseTheFaultInjectorsSchema) {
  std::string text = std::string(kExample);
  text.replace(text.find("faults:"), text.find("end:") - text.find("faults:"), R"(faults:
  - {at: 30s, kill: raft_leader}
  - {at: 40s, duration: 10s, pause: scout_2}
  - {at: 1m, duration: 20s, partition: {groups: [[scout_1, scout_2], [lifter]]}}
  - {at: 10s, duration: 5s, gps_dropout: scout_1}
  - {at: 50s, duration: 3s, wind_gust: {speed_m_s: 8, direction_deg: 90}}
)");
  auto spec = LoadTrialText(text, "sar.yaml", FakeTree());
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_EQ(spec->faults.size(), 5u);
  EXPECT_EQ(spec->faults[0].kind(), "kill");
  EXPECT_EQ(spec->faults[0].start.at_ms, 30000);
  EXPECT_EQ(spec->faults[2].kind(), "partition");
  EXPECT_EQ(spec->faults[1].duration_ms, 10000);
  EXPECT_TRUE(spec->faults_node.is_sequence());
}

struct BadCase {
  const char* find;     // text in kExample to replace
  const char* replace;  // with this
  const char* where;    // expected file:line:col
  const char* message;  // expected part of the message
};

TEST(LoadTrial, ReportsBadInputWithFileLineColumn) {
  const BadCase cases[] = {
      {"seed: 42", "seed: 42\ncolour: red", "sar.yaml:3:1", "unknown key 'colour' in trial"},
      {"seed: 42", "seed: many", "sar.yaml:2:7", "'seed': expected an integer"},
      {"world: worlds/open_field.yaml\n", "", "sar.yaml:1:1", "missing required key 'world' in trial"},
      {"world: worlds/open_field.yaml", "world: worlds/moon.yaml", "sar.yaml:4:8",
       "world 'worlds/moon.yaml' not found (no file /trials/worlds/moon.yaml)"},
      {"airframe: x8_heavy", "airframe: x9", "sar.yaml:9:30",
       "unknown airframe 'x9' (no file /trials/airframes/x9.yaml)"},
      {"middleware: cyclonedds", "middleware: zenoh", "sar.yaml:3:13", "unknown middleware 'zenoh'"},
      {"pose: [3, 0, 0]", "pose: [3, 0]", "sar.yaml:8:43", "expected a list of 3 values"},
      {"name: scout_2", "name: scout_1", "sar.yaml:8:12", "drone name 'scout_1' is used twice"},
      {"{at: 30s, kill: raft_leader}", "{at: 30s, explode: raft_leader}", "sar.yaml:13:15",
       "unknown key 'explode' in fault"},
      {"{at: 30s, kill: raft_leader}", "{at: 30s, kill: scout_9}", "sar.yaml:13:5",
       "unknown drone 'scout_9' (drones: scout_1, scout_2, lifter)"},
      {"{at: 30s, kill: raft_leader}", "{at: 30 seconds, kill: raft_leader}", "sar.yaml:13:10",
       "30 seconds"},
      {"{at: 30s, kill: raft_leader}", "{kill: raft_leader}", "sar.yaml:13:5",
       "a fault needs exactly one start: at (simulated time), at_wall (wall time) or on"},
      {"{at: 30s, kill: raft_leader}", "{at: 30s, kill: raft_leader, pause: scout_1}",
       "sar.yaml:13:5", "a fault has exactly one kind; got both 'kill' and 'pause'"},
      {"{at: 30s, kill: raft_leader}", "{at: 30s, kill: raft_leader, for: 3s}", "sar.yaml:13:34",
       "unknown key 'for' in fault"},
      {"outcome: failure", "outcome: disaster", "sar.yaml:16:38", "unknown outcome 'disaster'"},
      {"\"event=collision\"", "\"event=(collision\"", "sar.yaml:16:10",
       "'on' is not a valid regular expression"},
      {"loss: 0.05", "loss: 5", "sar.yaml:11:46", "'loss' is a probability in [0, 1]"},
      {"timeout: {sim: 600s, outcome: timeout}", "timeout: {outcome: timeout}", "sar.yaml:17:10",
       "missing required key 'sim' in timeout"},
      {"name: sar-search", "name: SAR Search", "sar.yaml:1:7", "trial name 'SAR Search' must be"},
      {"{at: 30s, kill: raft_leader}", "{at: 601s, kill: raft_leader}", "sar.yaml:13:5",
       "fault fault_0 at 601s is after the timeout (10m)"},
  };
  for (const BadCase& c : cases) {
    std::string text = kExample;
    const auto pos = text.find(c.find);
    ASSERT_NE(pos, std::string::npos) << c.find;
    text.replace(pos, std::string(c.find).size(), c.replace);
    auto spec = LoadTrialText(text, "sar.yaml", FakeTree());
    ASSERT_FALSE(spec) << c.replace;
    EXPECT_EQ(spec.error().where(), c.where) << c.replace << " -> " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos)
        << c.replace << " -> " << spec.error().ToString();
  }
}

constexpr const char* kLimited = R"(name: limited
world: worlds/open_field.yaml
physics: {rtf: 0, limits: {pids: 64}}
limits: {memory_mib: 300, pids: 128}
drones:
  - {name: scout_1, airframe: x500}
  - {name: scout_2, airframe: x500, limits: {memory_mib: 16}}
timeout: {sim: 60s}
)";

TEST(LoadTrial, LimitsApplyToEveryContainerWithDroneAndPhysicsOverrides) {
  auto spec = LoadTrialText(kLimited, "limited.yaml", FakeTree());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->LimitsOf(&spec->drones[0]).memory_mib, 300);
  EXPECT_EQ(spec->LimitsOf(&spec->drones[0]).pids, 128);
  EXPECT_EQ(spec->LimitsOf(&spec->drones[1]).memory_mib, 16);
  EXPECT_EQ(spec->LimitsOf(&spec->drones[1]).pids, 128);  // not overridden: the trial's
  EXPECT_EQ(spec->LimitsOf(nullptr).memory_mib, 300);
  EXPECT_EQ(spec->LimitsOf(nullptr).pids, 64);
  // Without `limits:` the defaults hold; the resolved document says which were used.
  auto plain = LoadTrialText(kExample, "sar.yaml", FakeTree());
  ASSERT_TRUE(plain);
  EXPECT_EQ(plain->LimitsOf(&plain->drones[0]).memory_mib, kDefaultLimits.memory_mib);
  EXPECT_EQ(plain->LimitsOf(nullptr).pids, kDefaultLimits.pids);
  auto again = LoadTrialText(yaml::Emit(ToDocument(*spec)), "again.yaml", FakeTree());
  ASSERT_TRUE(again) << again.error().ToString();
  EXPECT_EQ(again->LimitsOf(&again->drones[1]).memory_mib, 16);
  EXPECT_EQ(again->LimitsOf(nullptr).pids, 64);
  EXPECT_EQ(again->limits.memory_mib, 300);
}

TEST(LoadTrial, BadLimitsPointAtTheirKey) {
  const BadCase cases[] = {
      {"limits: {memory_mib: 300", "limits: {memory_mib: 5", "limited.yaml:4:22",
       "'memory_mib' must be >= 6 [MiB] (Docker's minimum)"},
      {"pids: 128}", "pids: 8}", "limited.yaml:4:33", "'pids' must be >= 16"},
      {"pids: 128}", "pids: 128, cpus: 2}", "limited.yaml:4:38", "unknown key 'cpus' in limits"},
      {"limits: {memory_mib: 16}", "limits: {memory_mib: lots}", "limited.yaml:7:58",
       "'memory_mib': expected an integer"},
      {"limits: {pids: 64}", "limits: {pids: 0}", "limited.yaml:3:34", "'pids' must be >= 16"},
  };
  for (const BadCase& c : cases) {
    std::string text = kLimited;
    const auto pos = text.find(c.find);
    ASSERT_NE(pos, std::string::npos) << c.find;
    text.replace(pos, std::string(c.find).size(), c.replace);
    auto spec = LoadTrialText(text, "limited.yaml", FakeTree());
    ASSERT_FALSE(spec) << c.replace;
    EXPECT_EQ(spec.error().where(), c.where) << c.replace << " -> " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos)
        << c.replace << " -> " << spec.error().ToString();
  }
}

TEST(LoadTrial, OverridesApplyBeforeChecking) {
  LoadOptions o = FakeTree();
  o.overrides = {"network.mesh.loss=0.1", "seed=7", "drones.lifter.pose=[1, 2, 3]",
                 "physics.rtf=0"};
  auto spec = LoadTrialText(kExample, "sar.yaml", o);
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_DOUBLE_EQ(spec->mesh.rules[0].spec.loss, 0.1);
  EXPECT_EQ(spec->seed, 7u);
  EXPECT_DOUBLE_EQ(spec->drones[2].pose[2], 3.0);
  EXPECT_DOUBLE_EQ(spec->rtf, 0.0);
  // The resolved document holds the overridden values (it is written as trial.yaml).
  EXPECT_EQ(spec->document.Find("seed")->scalar(), "7");
}

TEST(LoadTrial, BadOverridesPointAtTheSetFlag) {
  LoadOptions o = FakeTree();
  o.overrides = {"seed=seven"};
  auto spec = LoadTrialText(kExample, "sar.yaml", o);
  ASSERT_FALSE(spec);
  EXPECT_EQ(spec.error().where(), "--set seed:1:1");
  EXPECT_NE(spec.error().message().find("expected an integer"), std::string::npos);

  o.overrides = {"network.mesh.los=0.1"};
  spec = LoadTrialText(kExample, "sar.yaml", o);
  ASSERT_FALSE(spec);
  EXPECT_EQ(spec.error().where(), "--set network.mesh.los:1:1");
  EXPECT_NE(spec.error().message().find("unknown key 'los' in network.mesh"), std::string::npos);
}

TEST(LoadTrial, MissingFileIsNotFound) {
  auto spec = LoadTrial("/nonexistent/trial.yaml");
  ASSERT_FALSE(spec);
  EXPECT_EQ(spec.error().code(), ErrorCode::kNotFound);
  EXPECT_EQ(spec.error().ToString(), "/nonexistent/trial.yaml: cannot open trial file");
}

TEST(LoadTrial, BuilderAndDocumentDescribeTheSameTrial) {
  TrialSpec built = TrialSpec::Named("sar-search")
                        .Seed(42)
                        .World("worlds/open_field.yaml")
                        .Drone("scout_1", "x500", {0, 0, 0})
                        .Drone("lifter", "x8_heavy", {0, -10, 0}, "stretcher")
                        .Mesh("{delay_ms: 100, jitter_ms: 20, loss: 0.05}")
                        .Fault("{at: 30s, kill: raft_leader}")
                        .EndOn("event=mission_complete", Outcome::kSuccess)
                        .EndOn("event=collision", Outcome::kFailure, "collision")
                        .Timeout(Duration::Minutes(10));
  const std::string text = yaml::Emit(ToDocument(built));
  auto loaded = LoadTrialText(text, "built.yaml", FakeTree());
  ASSERT_TRUE(loaded) << loaded.error().ToString() << "\n" << text;
  EXPECT_EQ(loaded->name, built.name);
  EXPECT_EQ(loaded->seed, built.seed);
  ASSERT_EQ(loaded->drones.size(), 2u);
  EXPECT_EQ(loaded->drones[1].payload, "stretcher");
  EXPECT_DOUBLE_EQ(loaded->mesh.rules[0].spec.jitter_ms, 20);
  ASSERT_EQ(loaded->faults.size(), 1u);
  EXPECT_EQ(loaded->faults[0].kind(), "kill");
  EXPECT_EQ(loaded->faults[0].target()->ToString(), "raft_leader");
  ASSERT_EQ(loaded->end.size(), 2u);
  EXPECT_EQ(loaded->end[1].reason, "collision");
  EXPECT_EQ(loaded->timeout.sim, Duration::Minutes(10));
}

TEST(LoadTrial, TrialsDirIsTheNearestTrialsFolder) {
  EXPECT_EQ(DefaultTrialsDir("/src/trials/faults/partition.yaml"), "/src/trials");
  EXPECT_EQ(DefaultTrialsDir("/src/trials/sar_search.yaml"), "/src/trials");
  EXPECT_EQ(DefaultTrialsDir("/elsewhere/mine.yaml"), "/elsewhere");
  EXPECT_EQ(DefaultTrialsDir("mine.yaml"), ".");
}

TEST(LoadTrial, ShippedTrialsLoadAgainstTheRealTrialsFolder) {
  // Every trial at the top of trials/ (the folders below have their own tests).
  int found = 0;
  for (const auto& e : std::filesystem::directory_iterator(std::string(SWARMBOX_SOURCE_DIR) + "/trials")) {
    if (e.path().extension() != ".yaml") continue;
    auto spec = LoadTrial(e.path().string());
    EXPECT_TRUE(spec) << e.path() << ": " << spec.error().ToString();
    ++found;
  }
  EXPECT_GE(found, 4);
  // The 100-drone trial: 100 scouts on a 10 x 10 grid 4 m apart, the lifter last, the area scaled.
  auto swarm = LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/swarm_100.yaml");
  ASSERT_TRUE(swarm) << swarm.error().ToString();
  ASSERT_EQ(swarm->drones.size(), 101u);
  EXPECT_EQ(swarm->drones[99].name, "scout_100");
  EXPECT_EQ(swarm->drones[99].pose, (std::array<double, 3>{36, 36, 0}));
  EXPECT_EQ(swarm->drones[100].name, "lifter");
  EXPECT_EQ(swarm->world_size_m, (std::array<double, 2>{600, 600}));
  EXPECT_DOUBLE_EQ(swarm->rtf, 0);
}

}  // namespace
}  // namespace swarmbox::dsl
