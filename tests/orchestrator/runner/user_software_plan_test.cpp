// The plan of a trial with the user's software: library and external brains (agent flags, the
// brain's container, argv, labels, environment, images), components (levels by priority, networks,
// readiness, collected files, labels), the physics server's waits, and the compose export.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "swarmbox/docker/tar_archive.hpp"

#include "swarmbox/runner/compose_export.hpp"
#include "swarmbox/runner/plan.hpp"
#include "swarmbox/runner/user_images.hpp"

namespace swarmbox::runner {
namespace {

using ::testing::Contains;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::Not;

// The value after `flag` in argv ("" when absent).
std::string FlagValue(const std::vector<std::string>& argv, std::string_view flag) {
  auto it = std::find(argv.begin(), argv.end(), flag);
  return it == argv.end() || it + 1 == argv.end() ? std::string() : *(it + 1);
}

class UserSoftwarePlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    spec_ = dsl::TrialSpec::Named("byo")
                .Seed(3)
                .World("worlds/open_field.yaml")
                .Drone("scout_1", "x500", {0, 0, 0})
                .Drone("scout_2", "x500", {3, 0, 0})
                .Drone("scout_3", "x500", {6, 0, 0})
                .Timeout(dsl::Duration::Seconds(120));
    dsl::BrainSpec lib = dsl::BrainSpec::Library("/b/librendezvous.so", "rendezvous", *yaml::Parse("{radius_m: 6}"));
    lib.host_path = lib.path;
    lib.rate_hz = 125;
    dsl::BrainSpec prog = dsl::BrainSpec::Program("/b/swarmbox_c_brain", {"--radius-m", "6"});
    prog.host_path = prog.path;
    prog.offboard.timeout_ms = 800;
    prog.offboard.hold_ms = 0;
    spec_.Brain("scout_1", lib).Brain("scout_2", prog);
    dsl::UserComponentSpec ground = dsl::UserComponentSpec::Program("ground", "/b/ground");
    ground.host_path = ground.ref;
    ground.args = {"--out", "/tmp/ground.csv"};
    ground.networks = {"sim"};
    ground.priority = 10;
    ground.ready = "event=ready";
    ground.collect = {"/tmp/ground.csv"};
    ground.env = {{"LEVEL", "debug"}};
    dsl::UserComponentSpec rec = dsl::UserComponentSpec::Image("recorder", "rec:local");
    rec.args = {"--all"};
    rec.priority = 200;
    dsl::UserComponentSpec gs = dsl::UserComponentSpec::Image("gcs", "gcs:local");
    gs.priority = 100;
    gs.networks = {"sim"};
    spec_.Component(ground).Component(rec).Component(gs);
    options_.run_id = "20261126-050000-abcd";
    options_.images = {"swarmbox/physics:p", "swarmbox/agent:a"};
    options_.images.drone_agents["scout_1"] = "swarmbox/agent-brain:l";
    options_.images.brains["scout_2"] = "swarmbox/brain:c";
    options_.images.components = {{"ground", "swarmbox/component:g"}, {"recorder", "rec:local"}, {"gcs", "gcs:local"}};
    options_.subnets = {*Ipv4Net::Parse("10.200.8.0/24"), *Ipv4Net::Parse("10.200.9.0/24")};
    options_.trials_dir = "/src/trials";
  }

  std::unique_ptr<dsl::Trial> Plan() {
    auto trial = PlanTrial(spec_, options_);
    EXPECT_TRUE(trial) << trial.error().ToString();
    return trial ? std::move(*trial) : nullptr;
  }

  dsl::TrialSpec spec_;
  PlanOptions options_;
};

TEST_F(UserSoftwarePlanTest, StartOrderFollowsThePriorities) {
  auto trial = Plan();
  ASSERT_TRUE(trial);
  std::vector<std::string> ids;
  for (dsl::Plugin* p : trial->Plugins()) ids.push_back(p->id());
  // ground (10) before physics; the brain before the agents; gcs (100) with the drones; recorder
  // (200) last.
  EXPECT_THAT(ids, ElementsAre("ground", "physics", "scout_2-brain", "gcs", "scout_1", "scout_2", "scout_3",
                               "recorder"));
  auto level = [&](std::string_view id) {
    int p = 0;
    for (const dsl::Component* c = trial->Find(id); c != nullptr && c != trial.get(); c = c->parent()) {
      p = c->run_priority();
    }
    return p;
  };
  EXPECT_LT(level("ground"), level("physics"));
  EXPECT_LT(level("physics"), level("scout_2-brain"));
  EXPECT_LT(level("scout_2-brain"), level("scout_1"));
  EXPECT_EQ(level("gcs"), level("scout_1"));  // one level: started together
  EXPECT_LT(level("scout_1"), level("recorder"));
  // Each plugin's own priority is its level too: the engine orders creations by plugin priority
  // across groups (a creation waits for the lower ones'), so they must agree with the start order
  // (with the brain at 0 inside its group, physics' creation waited for it: a deadlock).
  int previous = 0;
  for (dsl::Plugin* p : trial->Plugins()) {
    EXPECT_EQ(p->run_priority(), level(p->id())) << p->id();
    EXPECT_GE(p->run_priority(), previous) << p->id();
    previous = p->run_priority();
  }
}

TEST_F(UserSoftwarePlanTest, ALibraryBrainRunsInItsAgentWithTheContractsFlags) {
  auto trial = Plan();
  ASSERT_TRUE(trial);
  const dsl::ContainerSpec& a = trial->FindPlugin("scout_1")->spec();
  EXPECT_EQ(a.image, "swarmbox/agent-brain:l");
  EXPECT_EQ(FlagValue(a.argv, "--brain"), "library");
  EXPECT_EQ(FlagValue(a.argv, "--brain-library"), "/swarmbox/brains/librendezvous.so");
  EXPECT_EQ(FlagValue(a.argv, "--brain-name"), "rendezvous");
  EXPECT_EQ(FlagValue(a.argv, "--brain-args"), R"({"radius_m":6})");
  EXPECT_EQ(FlagValue(a.argv, "--brain-rate-hz"), "125");
  EXPECT_EQ(FlagValue(a.argv, "--world"), "/swarmbox/trials/worlds/open_field.yaml");
  EXPECT_EQ(FlagValue(a.argv, "--members"), "scout_1,scout_2,scout_3");
  EXPECT_THAT(a.argv, Not(Contains("--mission")));  // the builtin brain's key
  EXPECT_THAT(a.argv, Not(Contains("--offboard-timeout-ms")));
  // A builtin drone is as before.
  const dsl::ContainerSpec& b = trial->FindPlugin("scout_3")->spec();
  EXPECT_EQ(b.image, "swarmbox/agent:a");
  EXPECT_EQ(FlagValue(b.argv, "--mission"), "sar");
  EXPECT_THAT(b.argv, Not(Contains("--brain")));
}

TEST_F(UserSoftwarePlanTest, AnExternalBrainGetsItsOwnContainerOnSim) {
  auto trial = Plan();
  ASSERT_TRUE(trial);
  const dsl::ContainerSpec& agent = trial->FindPlugin("scout_2")->spec();
  EXPECT_EQ(FlagValue(agent.argv, "--brain"), "external");
  EXPECT_EQ(FlagValue(agent.argv, "--offboard-timeout-ms"), "800");
  EXPECT_EQ(FlagValue(agent.argv, "--offboard-hold-ms"), "0");
  EXPECT_THAT(agent.argv, Not(Contains("--brain-library")));
  // Discovery on sim as a star: the agent names the physics server and its own brain, which has
  // the well-known index 0 (bus/cyclone_config.hpp); a drone without a brain names the server only.
  EXPECT_THAT(agent.argv, testing::IsSupersetOf({"physics", "brain-scout-2"}));
  EXPECT_EQ(std::count(agent.argv.begin(), agent.argv.end(), std::string("--sim-peer")), 2);
  const dsl::ContainerSpec& plain = trial->FindPlugin("scout_1")->spec();
  EXPECT_EQ(FlagValue(plain.argv, "--sim-peer"), "physics");
  EXPECT_EQ(std::count(plain.argv.begin(), plain.argv.end(), std::string("--sim-peer")), 1);
  EXPECT_EQ(FlagValue(trial->FindPlugin("physics")->spec().argv, "--participant-index"), "0");

  const dsl::ContainerSpec& brain = trial->FindPlugin("scout_2-brain")->spec();
  EXPECT_EQ(brain.name, "byo-20261126-050000-abcd-scout_2-brain");
  EXPECT_EQ(brain.image, "swarmbox/brain:c");
  EXPECT_FALSE(brain.argv_is_cmd);
  EXPECT_THAT(brain.argv, ElementsAre("/usr/local/bin/swarmbox_c_brain", "--drone", "scout_2", "--domain", "0",
                                      "--members", "scout_1,scout_2,scout_3", "--radius-m", "6"));
  EXPECT_EQ(brain.labels.at("swarmbox.role"), "brain");
  EXPECT_EQ(brain.labels.at("swarmbox.run"), "20261126-050000-abcd");
  EXPECT_EQ(brain.labels.at("swarmbox.component"), "scout_2-brain");
  EXPECT_THAT(brain.env.at("CYCLONEDDS_URI"), HasSubstr("<NetworkInterface name=\"eth0\" multicast=\"true\"/>"));
  EXPECT_THAT(brain.env.at("CYCLONEDDS_URI"), HasSubstr("<ParticipantIndex>0</ParticipantIndex>"));
  ASSERT_EQ(brain.networks.size(), 1u);
  EXPECT_EQ(brain.networks[0].network, "sim");
  EXPECT_EQ(brain.networks[0].ipv4, "10.200.8.13");  // after the three drones (.10-.12)
  EXPECT_THAT(brain.networks[0].aliases, ElementsAre("scout_2-brain", "brain-scout-2"));
  EXPECT_THAT(brain.cap_drop, ElementsAre("ALL"));
  EXPECT_TRUE(brain.no_new_privileges);
  EXPECT_EQ(brain.memory_mib, 512);
}

TEST_F(UserSoftwarePlanTest, AnImageBrainKeepsItsEntrypoint) {
  dsl::BrainSpec img = dsl::BrainSpec::Image("mine/brain:2", {"-v"});
  spec_.Brain("scout_3", img);
  options_.images.brains["scout_3"] = "mine/brain:2";
  auto trial = Plan();
  ASSERT_TRUE(trial);
  const dsl::ContainerSpec& brain = trial->FindPlugin("scout_3-brain")->spec();
  EXPECT_TRUE(brain.argv_is_cmd);
  EXPECT_THAT(brain.argv, ElementsAre("--drone", "scout_3", "--domain", "0", "--members", "scout_1,scout_2,scout_3", "-v"));
}

TEST_F(UserSoftwarePlanTest, ThePhysicsServerOutwaitsTheAgentsBrainBounds) {
  auto trial = Plan();
  ASSERT_TRUE(trial);
  const auto& argv = trial->FindPlugin("physics")->spec().argv;
  const double step = std::stod(FlagValue(argv, "--step-timeout"));
  const double join = std::stod(FlagValue(argv, "--join-timeout"));
  EXPECT_GT(step * 1000, kAgentBrainWaitMs);
  EXPECT_GT(join * 1000, kAgentBrainStartMs);
  // No external brain: the server's join default stays; on the channel its step timeout is the
  // channel's liveness net (kChannelStepTimeoutS), with netem the server's default.
  spec_.drones[1].brain = {};
  auto plain = PlanTrial(spec_, options_);
  ASSERT_TRUE(plain);
  const auto& plain_argv = (*plain)->FindPlugin("physics")->spec().argv;
  EXPECT_EQ(std::stod(FlagValue(plain_argv, "--step-timeout")), kChannelStepTimeoutS);
  EXPECT_THAT(plain_argv, Not(Contains("--join-timeout")));
  EXPECT_EQ((*plain)->FindPlugin("scout_2-brain"), nullptr);
  spec_.radio.model = dsl::RadioModel::kNetem;
  auto netem = PlanTrial(spec_, options_);
  ASSERT_TRUE(netem);
  EXPECT_THAT((*netem)->FindPlugin("physics")->spec().argv, Not(Contains("--step-timeout")));
}

TEST_F(UserSoftwarePlanTest, ComponentsAreLabelledNetworkedReadyAndCollected) {
  auto trial = Plan();
  ASSERT_TRUE(trial);
  const dsl::ContainerSpec& g = trial->FindPlugin("ground")->spec();
  EXPECT_EQ(g.name, "byo-20261126-050000-abcd-ground");
  EXPECT_EQ(g.image, "swarmbox/component:g");
  EXPECT_THAT(g.argv, ElementsAre("/usr/local/bin/ground", "--out", "/tmp/ground.csv"));
  EXPECT_FALSE(g.argv_is_cmd);
  EXPECT_EQ(g.labels.at("swarmbox.role"), "component");
  EXPECT_EQ(g.labels.at("swarmbox.component"), "ground");
  EXPECT_EQ(g.env.at("LEVEL"), "debug");
  EXPECT_EQ(g.env.at("SWARMBOX_RUN"), "20261126-050000-abcd");
  EXPECT_THAT(g.env.at("CYCLONEDDS_URI"), HasSubstr("eth0"));
  EXPECT_EQ(g.ready_pattern, "event=ready");
  EXPECT_THAT(g.artifacts, ElementsAre("/tmp/ground.csv"));
  EXPECT_EQ(g.artifacts_dir, "components/ground");
  ASSERT_EQ(g.networks.size(), 1u);
  EXPECT_EQ(g.networks[0].ipv4, "10.200.8.14");  // after the drones and scout_2's brain
  EXPECT_FALSE(g.no_network);

  const dsl::ContainerSpec& r = trial->FindPlugin("recorder")->spec();
  EXPECT_TRUE(r.argv_is_cmd);
  EXPECT_THAT(r.argv, ElementsAre("--all"));
  EXPECT_TRUE(r.no_network);
  EXPECT_TRUE(r.networks.empty());
  EXPECT_EQ(r.env.count("CYCLONEDDS_URI"), 0u);
  EXPECT_EQ(r.image, "rec:local");
}

TEST_F(UserSoftwarePlanTest, AMissingImageIsAnError) {
  options_.images.components.erase("recorder");
  auto trial = PlanTrial(spec_, options_);
  ASSERT_FALSE(trial);
  EXPECT_THAT(trial.error().ToString(), HasSubstr("no image for component recorder"));
  options_.images.components["recorder"] = "rec:local";
  options_.images.brains.clear();
  trial = PlanTrial(spec_, options_);
  ASSERT_FALSE(trial);
  EXPECT_THAT(trial.error().ToString(), HasSubstr("no image for the brain of scout_2"));
}

TEST_F(UserSoftwarePlanTest, TheComposeExportHasTheBrainAndTheComponents) {
  auto trial = Plan();
  ASSERT_TRUE(trial);
  ComposeOptions o;
  o.builds["recorder"] = {"../rec", "Dockerfile"};
  const std::string text = ComposeYaml(*trial, o);
  EXPECT_THAT(text, HasSubstr("scout_2-brain:"));
  EXPECT_THAT(text, HasSubstr("swarmbox.role: \"brain\""));
  EXPECT_THAT(text, HasSubstr("swarmbox.role: \"component\""));
  EXPECT_THAT(text, HasSubstr("network_mode: \"none\""));
  EXPECT_THAT(text, HasSubstr("context: \"../rec\""));
  // The user's image keeps its entrypoint: a command only.
  const auto recorder = text.find("  recorder:");
  ASSERT_NE(recorder, std::string::npos);
  EXPECT_THAT(text.substr(recorder), HasSubstr("command:"));
}

TEST(UserImages, ImageSpecsOfTheUsersSoftware) {
  images::ImageSpec agent = AgentWithBrainImage("/build/swarmbox-agent", "/b/librendezvous.so");
  EXPECT_EQ(agent.repository, "swarmbox/agent-brain");
  ASSERT_EQ(agent.plugins.size(), 1u);
  EXPECT_EQ(agent.plugins[0].host_path, "/b/librendezvous.so");
  EXPECT_EQ(agent.plugins[0].image_path, "/swarmbox/brains/librendezvous.so");
  EXPECT_EQ(agent.executables[0].host_path, "/build/swarmbox-agent");

  images::ImageSpec prog = ProgramImage(kComponentRepository, "ground", "/b/ground", {"/out/a.csv", "/tmp/b.csv", "/c"});
  EXPECT_EQ(prog.repository, "swarmbox/component");
  EXPECT_THAT(prog.entrypoint, ElementsAre("/usr/local/bin/ground"));
  EXPECT_EQ(prog.directories.at("/out"), 01777u);  // writable for uid 1000
  EXPECT_EQ(prog.directories.at("/tmp"), 01777u);
  EXPECT_EQ(prog.directories.count("/"), 0u);
}

TEST(UserImages, ADockerfilesFolderPacksToTheSameContextEveryTime) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / "swarmbox-dockerfile-context-test";
  fs::remove_all(dir);
  fs::create_directories(dir / "conf");
  std::ofstream(dir / "Dockerfile.brain") << "FROM swarmbox/brain:base\nCOPY conf/ /etc/brain/\n";
  std::ofstream(dir / "conf" / "gains.yaml") << "kp: 2\n";
  auto a = PackDockerfileContext((dir / "Dockerfile.brain").string(), "scout_2-brain");
  ASSERT_TRUE(a) << a.error().ToString();
  EXPECT_EQ(a->dockerfile, "Dockerfile.brain");
  EXPECT_EQ(a->tag.rfind("swarmbox/user-scout_2-brain:", 0), 0u) << a->tag;
  auto entries = docker::ReadTar(a->tar);
  ASSERT_TRUE(entries) << entries.error().ToString();
  std::vector<std::string> paths;
  for (const docker::TarEntry& e : *entries) paths.push_back(e.path);
  EXPECT_THAT(paths, ::testing::IsSupersetOf({"Dockerfile.brain", "conf/gains.yaml"}));
  // Deterministic: the same folder, the same tag; a changed file, another.
  auto b = PackDockerfileContext((dir / "Dockerfile.brain").string(), "scout_2-brain");
  ASSERT_TRUE(b);
  EXPECT_EQ(a->tag, b->tag);
  std::ofstream(dir / "conf" / "gains.yaml") << "kp: 3\n";
  auto c = PackDockerfileContext((dir / "Dockerfile.brain").string(), "scout_2-brain");
  ASSERT_TRUE(c);
  EXPECT_NE(a->tag, c->tag);
  auto missing = PackDockerfileContext((dir / "nope").string(), "x");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::runner
