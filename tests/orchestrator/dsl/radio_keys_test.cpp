// The radio model keys (`radio: {model, profile}`): defaults, names and paths, --set, errors at
// file:line:col, and what the simulated channel refuses (with the reason) where netem takes it.
#include <gtest/gtest.h>

#include <string>

#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::dsl {
namespace {

constexpr const char* kTrial = R"(name: radio
world: worlds/open_field.yaml
drones:
  - {name: scout_1, airframe: x500}
  - {name: scout_2, airframe: x500, pose: [3, 0, 0]}
  - {name: lifter, airframe: x500, pose: [0, -10, 0]}
radio: {model: channel, profile: telemetry_900mhz, ping_every_ms: 250}
timeout: {sim: 60s}
)";

LoadOptions Opts(std::vector<std::string> overrides = {}) {
  LoadOptions o;
  o.trials_dir = "/trials";
  o.file_exists = [](const std::string& p) {
    return p == "/trials/worlds/open_field.yaml" || p == "/trials/airframes/x500.yaml" ||
           p == "/trials/radios/telemetry_900mhz.yaml" || p == "/trials/radios/lab/bench.yaml";
  };
  o.overrides = std::move(overrides);
  return o;
}

// The trial with `replace` in place of the first occurrence of `find`.
std::string With(std::string_view find, std::string_view replace) {
  std::string text = kTrial;
  const auto pos = text.find(find);
  EXPECT_NE(pos, std::string::npos) << find;
  if (pos != std::string::npos) text.replace(pos, find.size(), replace);
  return text;
}

TEST(RadioKeys, DefaultIsTheChannelWithTheWifiMeshProfile) {
  auto spec =
      LoadTrialText(With("radio: {model: channel, profile: telemetry_900mhz, ping_every_ms: 250}\n", ""),
                    "bare.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->radio.model, RadioModel::kChannel);
  EXPECT_EQ(spec->radio.profile, "wifi_5ghz_mesh");
  EXPECT_EQ(RadioProfileFile(spec->radio), "radios/wifi_5ghz_mesh.yaml");
  EXPECT_EQ(spec->radio.ping_every_ms, 200);
  EXPECT_EQ(spec->radio.ping_peers, 3);
}

TEST(RadioKeys, PingPeersIsReadSetAndKeptInTheResolvedDocument) {
  auto spec = LoadTrialText(With("ping_every_ms: 250", "ping_every_ms: 1000, ping_peers: 1"), "radio.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->radio.ping_peers, 1);
  auto set = LoadTrialText(kTrial, "radio.yaml", Opts({"radio.ping_peers=5"}));
  ASSERT_TRUE(set) << set.error().ToString();
  EXPECT_EQ(set->radio.ping_peers, 5);
  auto again = LoadTrialText(yaml::Emit(ToDocument(*set)), "again.yaml", Opts());
  ASSERT_TRUE(again) << again.error().ToString();
  EXPECT_EQ(again->radio.ping_peers, 5);
}

TEST(RadioKeys, AProfileNameResolvesUnderRadiosAndAPathUnderTheTrialsDirectory) {
  auto spec = LoadTrialText(kTrial, "radio.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->radio.model, RadioModel::kChannel);
  EXPECT_EQ(spec->radio.profile, "telemetry_900mhz");
  EXPECT_EQ(RadioProfileFile(spec->radio), "radios/telemetry_900mhz.yaml");
  EXPECT_EQ(spec->radio.ping_every_ms, 250);

  auto path = LoadTrialText(kTrial, "radio.yaml", Opts({"radio.profile=radios/lab/bench.yaml"}));
  ASSERT_TRUE(path) << path.error().ToString();
  EXPECT_EQ(RadioProfileFile(path->radio), "radios/lab/bench.yaml");
}

TEST(RadioKeys, SetNetemKeepsTheRealStack) {
  auto spec = LoadTrialText(kTrial, "radio.yaml", Opts({"radio.model=netem"}));
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->radio.model, RadioModel::kNetem);
  EXPECT_EQ(RadioModelName(spec->radio.model), "netem");
  // netem needs no profile: one that does not exist is not looked for.
  auto missing =
      LoadTrialText(With("telemetry_900mhz", "no_such_radio"), "radio.yaml", Opts({"radio.model=netem"}));
  EXPECT_TRUE(missing) << missing.error().ToString();
}

TEST(RadioKeys, BadValuesFailAtFileLineColumnWithTheReason) {
  struct Case {
    std::string_view find, replace, where, message;
  };
  const Case cases[] = {
      {"model: channel", "model: wifi", "radio.yaml:7:16", "unknown radio model 'wifi' (expected channel"},
      {"profile: telemetry_900mhz", "profile: no_such_radio", "radio.yaml:7:34",
       "radio profile 'no_such_radio' not found (no file /trials/radios/no_such_radio.yaml)"},
      {"profile: telemetry_900mhz", "profile: /etc/radio.yaml", "radio.yaml:7:34",
       "'profile' must be a radio profile name"},
      {"profile: telemetry_900mhz", "profile: ../radio.yaml", "radio.yaml:7:34",
       "inside the trials directory"},
      {"ping_every_ms: 250", "ping_every: 250", "radio.yaml:7:52", "unknown key 'ping_every' in radio"},
      {"ping_every_ms: 250", "ping_every_ms: 250, ping_peers: 0", "radio.yaml:7:84", "'ping_peers' must be >= 1"},
  };
  for (const Case& c : cases) {
    auto spec = LoadTrialText(With(c.find, c.replace), "radio.yaml", Opts());
    ASSERT_FALSE(spec) << c.replace;
    EXPECT_EQ(spec.error().where(), c.where) << c.replace << " -> " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos) << spec.error().ToString();
  }
}

// What the channel does not carry out is refused before anything starts, where it is written and
// why; the same trial with radio.model netem loads.
TEST(RadioKeys, TheChannelRefusesWhatItDoesNotCarryOutAndNetemTakesIt) {
  struct Case {
    std::string_view block, where, message;
  };
  const Case cases[] = {
      {"network:\n  mesh: {delay_ms: 100, jitter_ms: 20, correlation: 0.25}\n", "radio.yaml:10:9",
       "network.mesh: 'correlation' is not carried out by the simulated radio channel"},
      {"network:\n  mesh: {delay_ms: 100, to: [scout_2]}\n", "radio.yaml:10:9", "'to'"},
      {"network:\n  mesh: {gilbert_elliott: {p: 0.02, r: 0.25}}\n", "radio.yaml:10:9", "'gilbert_elliott'"},
      {"network:\n  mesh: {loss: 0.1, loss_correlation: 0.5}\n", "radio.yaml:10:9", "'loss_correlation'"},
      {"faults:\n  - {name: bits, at: 5s, radio: {target: scout_1, corrupt: 0.01}}\n", "radio.yaml:10:33",
       "fault bits: 'corrupt' is not carried out by the simulated radio channel (radio.model channel): a "
       "frame "
       "arrives whole or not at all; radio.model: netem (the real network stack) does"},
      {"faults:\n  - {name: late, at: 5s, radio: {delay_ms: 50, reorder: 0.2}}\n", "radio.yaml:10:33",
       "'reorder'"},
      {"faults:\n  - {name: storm, at_wall: 5s, radio: {loss: 0.5}}\n", "radio.yaml:10:5",
       "fault storm (radio, at_wall 5s): the simulated radio channel (radio.model channel) takes radio "
       "faults and "
       "partitions at simulated times only (at:)"},
      {"faults:\n  - {on: \"event=leader_elected\", partition: {groups: [[scout_1]]}}\n", "radio.yaml:10:5",
       "takes radio faults and partitions at simulated times only"},
  };
  for (const Case& c : cases) {
    const std::string text = std::string(kTrial) + std::string(c.block);
    auto spec = LoadTrialText(text, "radio.yaml", Opts());
    ASSERT_FALSE(spec) << c.block;
    EXPECT_EQ(spec.error().where(), c.where) << c.block << " -> " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos) << spec.error().ToString();
    auto netem = LoadTrialText(text, "radio.yaml", Opts({"radio.model=netem"}));
    EXPECT_TRUE(netem) << c.block << " -> " << netem.error().ToString();
  }
}

// What the channel does carry out loads: the mesh impairment, radio faults and partitions at
// simulated times, process faults with any trigger.
TEST(RadioKeys, TheChannelTakesTheMeshAndFaultsAtSimulatedTimes) {
  const std::string text =
      std::string(kTrial) +
      "network:\n  mesh: {delay_ms: 100, jitter_ms: 20, distribution: normal, loss: 0.05, "
      "rate_kbit: 500, duplicate: 0.01}\n"
      "faults:\n"
      "  - {at: 20s, duration: 10s, radio: {target: scout_1, delay_ms: 300, loss: 0.2}}\n"
      "  - {at: 40s, duration: 20s, partition: {groups: [[scout_1], [scout_2]]}}\n"
      "  - {at: 30s, kill: raft_leader}\n"
      "  - {on: \"event=leader_elected\", restart: raft_leader}\n"
      "  - {at_wall: 5s, duration: 2s, pause: scout_2}\n";
  auto spec = LoadTrialText(text, "radio.yaml", Opts());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->faults.size(), 5u);
  EXPECT_FALSE(spec->mesh.empty());
}

TEST(RadioKeys, TheResolvedDocumentKeepsTheModelAndAProfileThatIsNotTheDefault) {
  auto spec = LoadTrialText(kTrial, "radio.yaml", Opts({"radio.model=netem"}));
  ASSERT_TRUE(spec) << spec.error().ToString();
  auto again = LoadTrialText(yaml::Emit(ToDocument(*spec)), "again.yaml", Opts());
  ASSERT_TRUE(again) << again.error().ToString();
  EXPECT_EQ(again->radio.model, RadioModel::kNetem);
  EXPECT_EQ(again->radio.profile, "telemetry_900mhz");
  EXPECT_EQ(again->radio.ping_every_ms, 250);

  TrialSpec built =
      TrialSpec::Named("built").World("worlds/open_field.yaml").Drone("scout_1", "x500", {0, 0, 0});
  built.Timeout(Duration::Seconds(30));
  const std::string text = yaml::Emit(ToDocument(built));
  EXPECT_NE(text.find("model: \"channel\""), std::string::npos) << text;
  EXPECT_EQ(text.find("profile"), std::string::npos) << text;  // the default stays implied
}

}  // namespace
}  // namespace swarmbox::dsl
