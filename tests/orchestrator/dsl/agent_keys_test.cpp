// The trial keys the agents are run with (shared contract): mission, raft, radio. Defaults, values,
// --set overrides, errors at file:line:col, and the resolved document.
#include <gtest/gtest.h>

#include <set>
#include <string>

#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::dsl {
namespace {

constexpr const char* kTrial = R"(name: keys
world: worlds/open_field.yaml
drones:
  - {name: scout_1, airframe: x500}
  - {name: scout_2, airframe: x500, pose: [3, 0, 0]}
mission: {kind: plan, plan: "takeoff:3,hover:2,land", inference_latency_ms: 60}
raft: {tick_ms: 20, heartbeat_ms: 100, election_timeout_ms: 800}
radio: {ping_every_ms: 500}
timeout: {sim: 60s}
)";

constexpr const char* kBare = R"(name: bare
world: worlds/open_field.yaml
drones:
  - {name: scout_1, airframe: x500}
timeout: {sim: 60s}
)";

LoadOptions Opts(std::vector<std::string> overrides = {}) {
  LoadOptions o;
  o.trials_dir = "/trials";
  o.file_exists = [](const std::string& p) {
    return p == "/trials/worlds/open_field.yaml" || p == "/trials/airframes/x500.yaml";
  };
  o.overrides = std::move(overrides);
  return o;
}

TEST(AgentKeys, DefaultsAreTheSarMissionAndRadioStableRaftTimings) {
  auto spec = LoadTrialText(kBare, "bare.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->mission.kind, MissionKind::kSar);
  EXPECT_EQ(spec->mission.inference_latency_ms, 40);
  EXPECT_EQ(spec->raft.tick_ms, 50);
  EXPECT_EQ(spec->raft.heartbeat_ms, 200);
  EXPECT_EQ(spec->raft.election_timeout_ms, 1500);
  EXPECT_EQ(spec->raft.voters, 5);
  EXPECT_EQ(spec->radio.ping_every_ms, 200);
}

TEST(AgentKeys, ValuesAreRead) {
  auto spec = LoadTrialText(kTrial, "keys.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->mission.kind, MissionKind::kPlan);
  EXPECT_EQ(spec->mission.plan, "takeoff:3,hover:2,land");
  EXPECT_EQ(spec->mission.inference_latency_ms, 60);
  EXPECT_EQ(spec->raft.tick_ms, 20);
  EXPECT_EQ(spec->raft.heartbeat_ms, 100);
  EXPECT_EQ(spec->raft.election_timeout_ms, 800);
  EXPECT_EQ(spec->radio.ping_every_ms, 500);
}

TEST(AgentKeys, SetOverridesThem) {
  auto spec = LoadTrialText(kBare, "bare.yaml",
                            Opts({"mission.kind=plan", "mission.plan=takeoff:5,land", "raft.heartbeat_ms=250",
                                  "raft.election_timeout_ms=2000", "radio.ping_every_ms=0", "raft.voters=3"}));
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->mission.kind, MissionKind::kPlan);
  EXPECT_EQ(spec->mission.plan, "takeoff:5,land");
  EXPECT_EQ(spec->raft.heartbeat_ms, 250);
  EXPECT_EQ(spec->raft.election_timeout_ms, 2000);
  EXPECT_EQ(spec->raft.voters, 3);
  EXPECT_EQ(spec->radio.ping_every_ms, 0);

  auto bad = LoadTrialText(kBare, "bare.yaml", Opts({"raft.heartbeat_ms=75"}));
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().where(), "--set raft.heartbeat_ms:1:1");
  EXPECT_NE(bad.error().message().find("'heartbeat_ms' (75) must be a multiple of tick_ms (50)"), std::string::npos)
      << bad.error().ToString();
}

struct BadCase {
  const char* find;
  const char* replace;
  const char* where;
  const char* message;
};

constexpr const char* kTuned = R"(name: tuned
world: worlds/open_field.yaml
drones:
  - {name: scout_1, airframe: x500}
mission: {kind: sar, inference_latency_ms: 40, tuning: {scout_altitude_m: 12, scout_min_clearance_m: 5.5}}
timeout: {sim: 60s}
)";

// mission.tuning: SarBrain's numbers by name, kept in order for the agent's --mission-tuning.
TEST(AgentKeys, MissionTuningIsAMappingOfNumbersForTheSarMission) {
  auto spec = LoadTrialText(kTuned, "tuned.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_TRUE(spec->mission.tuning.is_mapping());
  ASSERT_EQ(spec->mission.tuning.entries().size(), 2u);
  EXPECT_EQ(spec->mission.tuning.entries()[0].first.scalar(), "scout_altitude_m");
  EXPECT_EQ(spec->mission.TuningJson(), R"({"scout_altitude_m":12,"scout_min_clearance_m":5.5})");
  auto bare = LoadTrialText(kBare, "bare.yaml", Opts());
  ASSERT_TRUE(bare) << bare.error().ToString();
  EXPECT_EQ(bare->mission.TuningJson(), "");  // no tuning, no flag
  auto set = LoadTrialText(kBare, "bare.yaml", Opts({"mission.tuning.scout_altitude_m=15"}));
  ASSERT_TRUE(set) << set.error().ToString();
  EXPECT_EQ(set->mission.TuningJson(), R"({"scout_altitude_m":15})");
}

TEST(AgentKeys, MissionTuningThatIsNotAMappingOfNumbersFailsAtItsKey) {
  const BadCase cases[] = {
      {"tuning: {scout_altitude_m: 12, scout_min_clearance_m: 5.5}", "tuning: 12", "tuned.yaml:5:56",
       "'tuning' must be a mapping of numbers by name"},
      {"tuning: {scout_altitude_m: 12, scout_min_clearance_m: 5.5}", "tuning: [12]", "tuned.yaml:5:56",
       "'tuning' must be a mapping of numbers by name"},
      {"scout_altitude_m: 12", "scout_altitude_m: low", "tuned.yaml:5:75", "tuning 'scout_altitude_m' must be a number"},
      {"scout_altitude_m: 12", "scout_altitude_m: \"12\"", "tuned.yaml:5:75", "tuning 'scout_altitude_m' must be a number"},
      {"scout_altitude_m: 12", "scout_altitude_m: {m: 12}", "tuned.yaml:5:75", "tuning 'scout_altitude_m' must be a number"},
      {"scout_altitude_m: 12", "scout_altitude_m: .inf", "tuned.yaml:5:75", "tuning 'scout_altitude_m' must be a number"},
      {"scout_altitude_m: 12", "start: 12", "tuned.yaml:5:57", "'start' is not a tuning number"},
      {"kind: sar", "kind: plan", "tuned.yaml:5:57", "'tuning' belongs to mission kind sar"},
  };
  for (const BadCase& c : cases) {
    std::string text = kTuned;
    const auto pos = text.find(c.find);
    ASSERT_NE(pos, std::string::npos) << c.find;
    text.replace(pos, std::string(c.find).size(), c.replace);
    auto spec = LoadTrialText(text, "tuned.yaml", Opts());
    ASSERT_FALSE(spec) << c.replace;
    EXPECT_EQ(spec.error().where(), c.where) << c.replace << " -> " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos) << c.replace << " -> " << spec.error().ToString();
  }
}

TEST(AgentKeys, BadValuesFailAtFileLineColumn) {
  const BadCase cases[] = {
      {"kind: plan", "kind: rescue", "keys.yaml:6:17", "unknown mission kind 'rescue' (expected sar or plan)"},
      {"kind: plan", "kind: sar", "keys.yaml:6:28", "'plan' belongs to mission kind plan"},
      {"\"takeoff:3,hover:2,land\"", "\"takeoff:3, land\"", "keys.yaml:6:29", "without spaces"},
      {"inference_latency_ms: 60", "inference_latency_ms: -1", "keys.yaml:6:77", "'inference_latency_ms' must be in [0, 10000]"},
      {"inference_latency_ms: 60", "latency: 60", "keys.yaml:6:55", "unknown key 'latency' in mission"},
      {"tick_ms: 20", "tick_ms: 0", "keys.yaml:7:17", "'tick_ms' must be > 0"},
      {"heartbeat_ms: 100", "heartbeat_ms: 90", "keys.yaml:7:35", "must be a multiple of tick_ms (20)"},
      {"election_timeout_ms: 800", "election_timeout_ms: 810", "keys.yaml:7:61", "must be a multiple of tick_ms"},
      {"election_timeout_ms: 800", "election_timeout_ms: 100", "keys.yaml:7:61",
       "'election_timeout_ms' (100) must be longer than heartbeat_ms (100)"},
      {"heartbeat_ms: 100", "heartbeat_ms: many", "keys.yaml:7:35", "expected an integer"},
      {"election_timeout_ms: 800", "election_timeout_ms: 800, voters: -1", "keys.yaml:7:74", "'voters' must be >= 0"},
      {"ping_every_ms: 500", "ping_every_ms: -5", "keys.yaml:8:24", "'ping_every_ms' must be >= 0"},
      {"ping_every_ms: 500", "ping_ms: 500", "keys.yaml:8:9", "unknown key 'ping_ms' in radio"},
  };
  for (const BadCase& c : cases) {
    std::string text = kTrial;
    const auto pos = text.find(c.find);
    ASSERT_NE(pos, std::string::npos) << c.find;
    text.replace(pos, std::string(c.find).size(), c.replace);
    auto spec = LoadTrialText(text, "keys.yaml", Opts());
    ASSERT_FALSE(spec) << c.replace;
    EXPECT_EQ(spec.error().where(), c.where) << c.replace << " -> " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos) << c.replace << " -> " << spec.error().ToString();
  }
}

TEST(AgentKeys, TheResolvedDocumentReadsBackToTheSameKeys) {
  auto spec = LoadTrialText(kTrial, "keys.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  const std::string text = yaml::Emit(ToDocument(*spec));
  auto again = LoadTrialText(text, "again.yaml", Opts());
  ASSERT_TRUE(again) << again.error().ToString() << "\n" << text;
  EXPECT_EQ(again->mission.kind, MissionKind::kPlan);
  EXPECT_EQ(again->mission.plan, spec->mission.plan);
  EXPECT_EQ(again->mission.inference_latency_ms, 60);
  EXPECT_EQ(again->raft.election_timeout_ms, 800);
  EXPECT_EQ(again->radio.ping_every_ms, 500);

  TrialSpec built = TrialSpec::Named("built").World("worlds/open_field.yaml").Drone("scout_1", "x500", {0, 0, 0});
  built.Mission({MissionKind::kSar, std::string(kDefaultFlightPlan), 25}).Raft({25, 100, 1000}).Radio({100});
  built.Timeout(Duration::Seconds(30));
  auto read = LoadTrialText(yaml::Emit(ToDocument(built)), "built.yaml", Opts());
  ASSERT_TRUE(read) << read.error().ToString();
  EXPECT_EQ(read->mission.kind, MissionKind::kSar);
  EXPECT_EQ(read->mission.inference_latency_ms, 25);
  EXPECT_EQ(read->raft.tick_ms, 25);
  EXPECT_EQ(read->radio.ping_every_ms, 100);
}

}  // namespace
}  // namespace swarmbox::dsl
