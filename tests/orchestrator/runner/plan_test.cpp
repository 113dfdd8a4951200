// The plan of the shipped trial: networks, names, labels, addresses, argv, priorities, files.
#include "swarmbox/runner/plan.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::runner {
namespace {

using ::testing::Contains;
using ::testing::ElementsAre;

class PlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto spec = dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/sar_search.yaml");
    ASSERT_TRUE(spec) << spec.error().ToString();
    spec_ = *spec;
    options_.run_id = "20261121-101000-7f3a";
    options_.images = {"swarmbox/physics:abc", "swarmbox/agent:def"};
    options_.subnets = {*Ipv4Net::Parse("10.200.8.0/24"), *Ipv4Net::Parse("10.200.9.0/24")};
    options_.trials_dir = "/src/trials";
  }
  dsl::TrialSpec spec_;
  PlanOptions options_;
};

TEST_F(PlanTest, MakesTwoNetworksWithTheirSubnetsNamesAndLabels) {
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  auto nets = (*trial)->Networks();
  ASSERT_EQ(nets.size(), 2u);
  EXPECT_EQ(nets[0]->id(), "sim");
  EXPECT_EQ(nets[0]->spec().name, "sar-search-20261121-101000-7f3a-net1-sim");
  EXPECT_EQ(nets[0]->spec().subnet, "10.200.8.0/24");
  EXPECT_EQ(nets[0]->spec().gateway, "10.200.8.1");
  EXPECT_EQ(nets[1]->spec().subnet, "10.200.9.0/24");
  EXPECT_EQ(nets[1]->spec().labels.at("swarmbox.run"), "20261121-101000-7f3a");
  EXPECT_EQ(nets[1]->spec().labels.at("swarmbox.trial"), "sar-search");
  EXPECT_EQ(nets[1]->spec().labels.at("swarmbox.component"), "mesh");
  EXPECT_EQ(nets[0]->run_priority(), 0);
}

TEST_F(PlanTest, PhysicsThenOneAgentPerDroneWithFixedAddresses) {
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  auto plugins = (*trial)->Plugins();
  std::vector<std::string> ids;
  for (auto* p : plugins) ids.push_back(p->id());
  EXPECT_THAT(ids, ElementsAre("physics", "scout_1", "scout_2", "scout_3", "lifter"));

  const dsl::ContainerSpec& physics = plugins[0]->spec();
  EXPECT_EQ(plugins[0]->run_priority(), 1);
  EXPECT_EQ(physics.image, "swarmbox/physics:abc");
  EXPECT_EQ(physics.name, "sar-search-20261121-101000-7f3a-physics");
  EXPECT_EQ(physics.ready_pattern, "event=ready");
  ASSERT_EQ(physics.networks.size(), 1u);
  EXPECT_EQ(physics.networks[0].network, "sim");
  EXPECT_EQ(physics.networks[0].ipv4, "10.200.8.2");
  EXPECT_THAT(physics.artifacts, ElementsAre("/out/truth.csv"));
  EXPECT_THAT(physics.argv, Contains("/swarmbox/trials/worlds/open_field.yaml"));
  EXPECT_THAT(physics.argv, Contains("lifter:x8_heavy:0,-10,0:0:stretcher:ground"));
  EXPECT_THAT(physics.argv, Contains("/swarmbox/trials/airframes"));
  EXPECT_THAT(physics.argv, Contains("600"));  // --max-sim-time
  ASSERT_EQ(physics.inputs.size(), 3u);  // the world and two airframes, each once
  EXPECT_EQ(physics.inputs[0].host_path, "/src/trials/worlds/open_field.yaml");
  EXPECT_EQ(physics.inputs[0].container_path, "/swarmbox/trials/worlds/open_field.yaml");

  const dsl::ContainerSpec& lifter = plugins[4]->spec();
  EXPECT_EQ(lifter.image, "swarmbox/agent:def");
  ASSERT_EQ(lifter.networks.size(), 2u);
  EXPECT_EQ(lifter.networks[0].ipv4, "10.200.8.13");
  EXPECT_EQ(lifter.networks[1].network, "mesh");
  EXPECT_EQ(lifter.networks[1].ipv4, "10.200.9.13");
  EXPECT_EQ(lifter.labels.at("swarmbox.component"), "lifter");
  EXPECT_THAT(lifter.argv, Contains("0,-10,0"));  // --start
  EXPECT_THAT(lifter.argv, Contains("eth1"));     // --mesh-interface
  EXPECT_EQ(lifter.argv[0], "/usr/local/bin/swarmbox-agent");
}

TEST_F(PlanTest, EndConditionsAndTimeoutComeFromTheTrial) {
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  const auto& end = (*trial)->end_conditions();
  ASSERT_EQ(end.size(), 3u);
  EXPECT_EQ(end[2].pattern, "event=crash");
  EXPECT_EQ(end[2].outcome, dsl::Outcome::kFailure);
  EXPECT_EQ((*trial)->timeout().sim, dsl::Duration::Seconds(600));
  EXPECT_EQ((*trial)->timeout().clock_component, "physics");
  // rtf 1: 600 s * 1.5 + 120 s.
  EXPECT_EQ((*trial)->timeout().wall_guard, dsl::Duration::Seconds(1020));
}

TEST_F(PlanTest, PayloadsComeFromTheAirframe) {
  auto ok = LoadPayloadMasses(spec_, std::string(SWARMBOX_SOURCE_DIR) + "/trials");
  ASSERT_TRUE(ok) << ok.error().ToString();
  EXPECT_EQ(ok->at("x8_heavy/stretcher"), 80.0);
  spec_.drones[3].payload = "piano";
  auto masses = LoadPayloadMasses(spec_, std::string(SWARMBOX_SOURCE_DIR) + "/trials");
  ASSERT_FALSE(masses);
  EXPECT_EQ(masses.error().message(), "drone lifter: airframe x8_heavy has no payload 'piano'");
  EXPECT_NE(masses.error().where().find("sar_search.yaml:19:5"), std::string::npos);
}

TEST_F(PlanTest, MissingImagesOrRunIdAreRefused) {
  options_.images.agent.clear();
  auto trial = PlanTrial(spec_, options_);
  ASSERT_FALSE(trial);
  EXPECT_EQ(trial.error().message(), "PlanTrial: images for physics and agent are needed");
}

}  // namespace
}  // namespace swarmbox::runner
