// The plan of the shipped trial: networks, names, labels, addresses, argv, priorities, files.
#include "swarmbox/runner/plan.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>

#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/runner/compose_export.hpp"

namespace swarmbox::runner {
namespace {

using ::testing::Contains;
using ::testing::ElementsAre;

class PlanTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // The netem model's tree (mesh network, fault sidecars); PlanChannelTest plans the channel's.
    dsl::LoadOptions load;
    load.overrides = {"radio.model=netem"};
    auto spec = dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/sar_search.yaml", load);
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
  // truth.csv, and the recording (record: is on by default).
  EXPECT_THAT(physics.artifacts, ElementsAre("/swarmbox/out/truth.csv", "/swarmbox/out/recording.mcap"));
  EXPECT_THAT(physics.argv, Contains("/swarmbox/trials/worlds/open_field.yaml"));
  EXPECT_THAT(physics.argv, Contains("lifter:x8_heavy:0,-10,0:0:stretcher:ground"));
  EXPECT_THAT(physics.argv, Contains("/swarmbox/trials/airframes"));
  EXPECT_THAT(physics.argv, Contains("600"));  // --max-sim-time
  EXPECT_THAT(physics.argv, ::testing::Not(Contains("--clock-every")));  // no sim-time faults
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
  EXPECT_EQ(ok->at("x8_heavy/stretcher"), 15.0);  // empty; loaded, payload_attach makes it 80 kg
  spec_.drones[3].payload = "piano";
  auto masses = LoadPayloadMasses(spec_, std::string(SWARMBOX_SOURCE_DIR) + "/trials");
  ASSERT_FALSE(masses);
  EXPECT_EQ(masses.error().message(), "drone lifter: airframe x8_heavy has no payload 'piano'");
  EXPECT_NE(masses.error().where().find("sar_search.yaml:30:5"), std::string::npos);
}

TEST_F(PlanTest, MissingImagesOrRunIdAreRefused) {
  options_.images.agent.clear();
  auto trial = PlanTrial(spec_, options_);
  ASSERT_FALSE(trial);
  EXPECT_EQ(trial.error().message(), "PlanTrial: images for physics and agent are needed");
}

// The shared contract's agent flags: Raft on the mesh for every drone (members in trial order, the
// trial's seed, the raft: timings); mission kind plan flies the trial's plan.
TEST_F(PlanTest, AgentsGetTheRaftMembersSeedTimingsAndTheirMission) {
  spec_.raft = {25, 150, 900};
  spec_.mission = {dsl::MissionKind::kPlan, "takeoff:4,hover:3,land", 40};
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  const std::vector<std::string>& argv = (*trial)->FindPlugin("scout_2")->spec().argv;
  auto value_of = [&](const std::string& flag) -> std::string {
    auto it = std::find(argv.begin(), argv.end(), flag);
    return it == argv.end() || it + 1 == argv.end() ? "<absent>" : *(it + 1);
  };
  EXPECT_EQ(value_of("--name"), "scout_2");
  EXPECT_EQ(value_of("--members"), "scout_1,scout_2,scout_3,lifter");
  EXPECT_EQ(value_of("--seed"), "42");
  EXPECT_EQ(value_of("--raft-tick-ms"), "25");
  EXPECT_EQ(value_of("--raft-heartbeat-ms"), "150");
  EXPECT_EQ(value_of("--raft-election-timeout-ms"), "900");
  EXPECT_EQ(value_of("--raft-voters"), "<absent>");  // 4 drones, 5 voters: every drone votes
  EXPECT_EQ(value_of("--mission"), "plan");
  EXPECT_EQ(value_of("--plan"), "takeoff:4,hover:3,land");
  EXPECT_EQ(value_of("--world"), "<absent>");  // the agent refuses --world/--payload with plan
  EXPECT_EQ(value_of("--payload"), "<absent>");
  EXPECT_EQ(value_of("--ping-every-ms"), "200");  // radio: the default
  EXPECT_EQ(value_of("--ping-peers"), "3");
  EXPECT_EQ(value_of("--sim-interface"), "eth0");
  EXPECT_EQ(value_of("--mesh-interface"), "eth1");
  // The start's patience, and the stall bound for 4 drones: 5 s + 0.15 s per drone.
  EXPECT_EQ(value_of("--sample-timeout"), "60");
  EXPECT_EQ(value_of("--stall-timeout"), "5.6");
}

TEST(AgentStallTimeout, GrowsWithTheFleet) {
  EXPECT_DOUBLE_EQ(AgentStallTimeoutS(1), 5.15);
  EXPECT_DOUBLE_EQ(AgentStallTimeoutS(10), 6.5);
  EXPECT_DOUBLE_EQ(AgentStallTimeoutS(101), 20.15);
}

// The recording (record:): the physics server writes it where truth.csv is and it is collected the
// same way; the agents send their telemetry at the same rate. record.enabled false: neither.
TEST_F(PlanTest, RecordingIsPassedAndCollectedUnlessOff) {
  spec_.record.rate_hz = 20;
  spec_.record.jpeg_quality = 60;
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  auto value_in = [](const std::vector<std::string>& argv, const std::string& flag) -> std::string {
    auto it = std::find(argv.begin(), argv.end(), flag);
    return it == argv.end() || it + 1 == argv.end() ? "<absent>" : *(it + 1);
  };
  const dsl::ContainerSpec& physics = (*trial)->FindPlugin("physics")->spec();
  EXPECT_EQ(value_in(physics.argv, "--record"), "/swarmbox/out/recording.mcap");
  EXPECT_EQ(value_in(physics.argv, "--record-rate-hz"), "20");
  EXPECT_EQ(value_in(physics.argv, "--record-camera-hz"), "1");
  EXPECT_EQ(value_in(physics.argv, "--record-camera-scale"), "0.5");
  EXPECT_EQ(value_in(physics.argv, "--record-jpeg-quality"), "60");
  EXPECT_NE(std::find(physics.artifacts.begin(), physics.artifacts.end(), "/swarmbox/out/recording.mcap"),
            physics.artifacts.end());
  EXPECT_EQ(value_in((*trial)->FindPlugin("scout_2")->spec().argv, "--telemetry-hz"), "20");

  spec_.record.enabled = false;
  auto off = PlanTrial(spec_, options_);
  ASSERT_TRUE(off) << off.error().ToString();
  const dsl::ContainerSpec& quiet = (*off)->FindPlugin("physics")->spec();
  EXPECT_EQ(value_in(quiet.argv, "--record"), "<absent>");
  EXPECT_EQ(quiet.artifacts, std::vector<std::string>{"/swarmbox/out/truth.csv"});
  EXPECT_EQ(value_in((*off)->FindPlugin("scout_2")->spec().argv, "--telemetry-hz"), "<absent>");
}

// swarmbox run --view: the physics server serves the live view on every address of its container,
// Docker publishes that port on the host address asked for.
TEST_F(PlanTest, ViewIsServedAndPublishedOnTheHost) {
  options_.view = ViewBinding{"127.0.0.1", 9000};
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  const dsl::ContainerSpec& physics = (*trial)->FindPlugin("physics")->spec();
  auto it = std::find(physics.argv.begin(), physics.argv.end(), "--view");
  ASSERT_NE(it, physics.argv.end());
  EXPECT_EQ(*(it + 1), "0.0.0.0:8765");
  ASSERT_EQ(physics.ports.size(), 1u);
  EXPECT_EQ(physics.ports[0].container_port, 8765);
  EXPECT_EQ(physics.ports[0].host_ip, "127.0.0.1");
  EXPECT_EQ(physics.ports[0].host_port, 9000);
  EXPECT_TRUE((*trial)->FindPlugin("scout_1")->spec().ports.empty());
}

TEST(ViewAddress, DefaultsAndErrors) {
  auto d = ParseViewAddress("");
  ASSERT_TRUE(d);
  EXPECT_EQ(d->url(), "http://127.0.0.1:8765/");
  auto full = ParseViewAddress("0.0.0.0:9001");
  ASSERT_TRUE(full);
  EXPECT_EQ(full->host_ip, "0.0.0.0");
  EXPECT_EQ(full->host_port, 9001);
  auto addr_only = ParseViewAddress("192.168.1.20");
  ASSERT_TRUE(addr_only);
  EXPECT_EQ(addr_only->host_port, 8765);
  for (const char* bad : {"localhost:80", "1.2.3:80", "1.2.3.4:0", "1.2.3.4:70000", "1.2.3.4:", "1.2.3.256:80"}) {
    auto r = ParseViewAddress(bad);
    ASSERT_FALSE(r) << bad;
    EXPECT_NE(r.error().message().find("expected ADDR:PORT"), std::string::npos) << bad;
  }
}

// Raft at swarm scale: raft.voters = V below the drone count makes the first V drones in trial
// order the voting set, the same list on every drone (orchestrator/dsl/README.md, `voters`).
TEST_F(PlanTest, AgentsGetTheFirstVotersDronesAsTheRaftVotingSet) {
  spec_.raft.voters = 2;
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  for (const char* drone : {"scout_1", "scout_3", "lifter"}) {
    const std::vector<std::string>& argv = (*trial)->FindPlugin(drone)->spec().argv;
    auto it = std::find(argv.begin(), argv.end(), "--raft-voters");
    ASSERT_NE(it, argv.end()) << drone;
    ASSERT_NE(it + 1, argv.end()) << drone;
    EXPECT_EQ(*(it + 1), "scout_1,scout_2") << drone;
  }
  spec_.raft.voters = 0;  // every drone votes: no flag
  auto all = PlanTrial(spec_, options_);
  ASSERT_TRUE(all) << all.error().ToString();
  const std::vector<std::string>& argv = (*all)->FindPlugin("scout_1")->spec().argv;
  EXPECT_EQ(std::find(argv.begin(), argv.end(), "--raft-voters"), argv.end());
}

// Mission kind sar: the world file in the container, the perception latency, and the lifter's
// payload (it lies on the ground under the lifter, as the physics server places it); no --plan.
TEST_F(PlanTest, SarAgentsGetTheWorldLatencyAndTheLifterItsPayload) {
  spec_.mission.inference_latency_ms = 55;
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  auto argv_of = [&](const char* drone) { return (*trial)->FindPlugin(drone)->spec().argv; };
  auto value_of = [](const std::vector<std::string>& argv, const std::string& flag) -> std::string {
    auto it = std::find(argv.begin(), argv.end(), flag);
    return it == argv.end() || it + 1 == argv.end() ? "<absent>" : *(it + 1);
  };
  const auto lifter = argv_of("lifter");
  EXPECT_EQ(value_of(lifter, "--mission"), "sar");
  EXPECT_EQ(value_of(lifter, "--world"), "/swarmbox/trials/worlds/open_field.yaml");
  EXPECT_EQ(value_of(lifter, "--inference-latency-ms"), "55");
  EXPECT_EQ(value_of(lifter, "--payload"), "stretcher");
  EXPECT_EQ(value_of(lifter, "--plan"), "<absent>");
  EXPECT_EQ(value_of(argv_of("scout_1"), "--payload"), "<absent>");
  EXPECT_EQ(value_of(argv_of("scout_1"), "--mission"), "sar");
  EXPECT_EQ(value_of(argv_of("scout_1"), "--mission-tuning"), "<absent>");  // no tuning: the defaults
}

// mission.tuning: every SAR agent gets it as one argv element of JSON (yaml::EmitJson), in order.
TEST_F(PlanTest, SarAgentsGetTheMissionTuningAsJson) {
  auto tuning = yaml::Parse("{scout_altitude_m: 12, scout_min_clearance_m: 5, fusion_prior: 0.25}");
  ASSERT_TRUE(tuning) << tuning.error().ToString();
  spec_.mission.tuning = *tuning;
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  for (const char* drone : {"scout_1", "lifter"}) {
    const std::vector<std::string>& argv = (*trial)->FindPlugin(drone)->spec().argv;
    auto it = std::find(argv.begin(), argv.end(), "--mission-tuning");
    ASSERT_NE(it, argv.end()) << drone;
    ASSERT_NE(it + 1, argv.end()) << drone;
    EXPECT_EQ(*(it + 1), R"({"scout_altitude_m":12,"scout_min_clearance_m":5,"fusion_prior":0.25})") << drone;
  }
}

// With a fault sidecar image, a trial that impairs the mesh gets one sidecar per drone owning the
// drone's addresses; the agents join their sidecar's namespace; the faults Step sits between.
TEST_F(PlanTest, NetworkFaultsGiveEachAgentASidecarThatOwnsItsNamespace) {
  options_.faults_image = "swarmbox/faults:f00";
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  std::vector<std::string> ids;
  for (auto* p : (*trial)->Plugins()) ids.push_back(p->id());
  EXPECT_THAT(ids, ElementsAre("physics", "scout_1-faults", "scout_2-faults", "scout_3-faults", "lifter-faults",
                               "scout_1", "scout_2", "scout_3", "lifter"));
  dsl::Component* step = (*trial)->Find("faults");
  ASSERT_NE(step, nullptr);
  EXPECT_EQ(step->run_priority(), 3);
  EXPECT_EQ((*trial)->Find("sidecars")->run_priority(), 2);
  EXPECT_EQ((*trial)->Find("drones")->run_priority(), 4);

  const dsl::ContainerSpec& sidecar = (*trial)->FindPlugin("lifter-faults")->spec();
  EXPECT_EQ(sidecar.image, "swarmbox/faults:f00");
  EXPECT_EQ(sidecar.name, "sar-search-20261121-101000-7f3a-lifter-faults");
  EXPECT_EQ(sidecar.labels.at("swarmbox.component"), "lifter-faults");
  EXPECT_THAT(sidecar.argv, ElementsAre("/usr/bin/swarmbox-netemd", "sleep"));
  EXPECT_THAT(sidecar.cap_add, ElementsAre("NET_ADMIN"));
  EXPECT_THAT(sidecar.cap_drop, ElementsAre("ALL"));
  EXPECT_TRUE(sidecar.no_new_privileges);
  ASSERT_EQ(sidecar.networks.size(), 2u);
  EXPECT_EQ(sidecar.networks[0].ipv4, "10.200.8.13");
  EXPECT_EQ(sidecar.networks[1].ipv4, "10.200.9.13");

  const dsl::ContainerSpec& lifter = (*trial)->FindPlugin("lifter")->spec();
  EXPECT_EQ(lifter.network_of, "lifter-faults");
  EXPECT_TRUE(lifter.networks.empty());
  EXPECT_TRUE(lifter.hostname.empty());
  EXPECT_TRUE(lifter.cap_add.empty());
  EXPECT_TRUE((*trial)->FindPlugin("physics")->spec().cap_add.empty());

  // compose: the agent shares its sidecar's network (compose carries out no faults itself).
  const std::string compose = ComposeYaml(**trial, {});
  EXPECT_NE(compose.find("network_mode: \"service:lifter-faults\""), std::string::npos) << compose;
  EXPECT_NE(compose.find("- \"NET_ADMIN\""), std::string::npos);
}

// Least privilege: what every agent and the physics server are created with.
TEST_F(PlanTest, AgentsAndPhysicsRunConfinedWithTheDefaultLimits) {
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  for (dsl::Plugin* p : (*trial)->Plugins()) {
    const dsl::ContainerSpec& c = p->spec();
    SCOPED_TRACE(p->id());
    EXPECT_THAT(c.cap_drop, ElementsAre("ALL"));
    EXPECT_TRUE(c.cap_add.empty());
    EXPECT_TRUE(c.no_new_privileges);
    EXPECT_TRUE(c.read_only_rootfs);
    EXPECT_THAT(c.volumes, ElementsAre("/swarmbox"));
    ASSERT_EQ(c.tmpfs.size(), 1u);
    EXPECT_EQ(c.tmpfs[0].path, "/tmp");
    EXPECT_EQ(c.tmpfs[0].size_mib, kScratchTmpfsMib);
    EXPECT_EQ(c.memory_mib, dsl::kDefaultLimits.memory_mib);
    EXPECT_EQ(c.pids_limit, dsl::kDefaultLimits.pids);
    // Everything copied in before the start lies in the volume (the root filesystem refuses it).
    for (const dsl::InputFile& in : c.inputs) EXPECT_EQ(in.container_path.rfind("/swarmbox/", 0), 0u);
    for (const std::string& d : c.scratch_dirs) EXPECT_EQ(d.rfind("/swarmbox/", 0), 0u);
  }
  // The WAL in the volume: it survives a restart fault, which a tmpfs would not.
  const auto& argv = (*trial)->FindPlugin("scout_1")->spec().argv;
  auto it = std::find(argv.begin(), argv.end(), "--raft-dir");
  ASSERT_NE(it, argv.end());
  EXPECT_EQ(*(it + 1), "/swarmbox/state/raft");
  EXPECT_THAT((*trial)->FindPlugin("scout_1")->spec().scratch_dirs, ElementsAre("/swarmbox/state"));
}

TEST_F(PlanTest, LimitsComeFromTheTrialWithDroneAndPhysicsOverrides) {
  spec_.Limits({300, 128});
  spec_.drones[1].limits = {64, 0};  // scout_2: memory only, pids from the trial
  spec_.physics_limits = {0, 64};
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  const dsl::ContainerSpec& scout_1 = (*trial)->FindPlugin("scout_1")->spec();
  EXPECT_EQ(scout_1.memory_mib, 300);
  EXPECT_EQ(scout_1.pids_limit, 128);
  const dsl::ContainerSpec& scout_2 = (*trial)->FindPlugin("scout_2")->spec();
  EXPECT_EQ(scout_2.memory_mib, 64);
  EXPECT_EQ(scout_2.pids_limit, 128);
  const dsl::ContainerSpec& physics = (*trial)->FindPlugin("physics")->spec();
  EXPECT_EQ(physics.memory_mib, 300);
  EXPECT_EQ(physics.pids_limit, 64);
}

TEST_F(PlanTest, SimTimeFaultsMakeThePhysicsClockFiner) {
  spec_.Fault("{at: 30s, kill: raft_leader}");
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  const auto& argv = (*trial)->FindPlugin("physics")->spec().argv;
  auto it = std::find(argv.begin(), argv.end(), "--clock-every");
  ASSERT_NE(it, argv.end());
  EXPECT_EQ(*(it + 1), "0.5");
}

TEST_F(PlanTest, WithoutAFaultsImageOrNetworkFaultsThereAreNoSidecars) {
  auto trial = PlanTrial(spec_, options_);  // mesh block, but no faults image (swarmbox compose)
  ASSERT_TRUE(trial);
  EXPECT_EQ((*trial)->Find("faults"), nullptr);
  EXPECT_EQ((*trial)->FindPlugin("scout_1-faults"), nullptr);
  spec_.mesh = {};
  options_.faults_image = "swarmbox/faults:f00";
  EXPECT_FALSE(NeedsFaultSidecars(spec_));
  trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  EXPECT_EQ((*trial)->FindPlugin("scout_1-faults"), nullptr);
  EXPECT_EQ((*trial)->FindPlugin("scout_1")->spec().networks.size(), 2u);
  spec_.Fault("{at: 10s, duration: 5s, partition: {groups: [[scout_1], [scout_2]]}}");
  EXPECT_TRUE(NeedsFaultSidecars(spec_));
}

// A sensor or environment fault's exec in the physics container: the same sim bus as PhysicsArgv.
TEST(PhysicsCommandArgvTest, SendsOnThePhysicsServersBusWithTheWorldAsDash) {
  EXPECT_THAT(PhysicsCommandArgv(dsl::Middleware::kFastDds, {"scout_1", "gps_dropout", {3.0}}),
              ElementsAre("/usr/local/bin/swarmbox-physics", "--sim-interface", "eth0", "--domain", "0",
                          "--middleware", "fastdds", "--send-command", "scout_1", "gps_dropout", "3"));
  EXPECT_THAT(PhysicsCommandArgv(dsl::Middleware::kCycloneDds, {"", "wind_gust", {12.0, 0.0, -1.5, 1e6}}),
              ElementsAre("/usr/local/bin/swarmbox-physics", "--sim-interface", "eth0", "--domain", "0",
                          "--middleware", "cyclonedds", "--send-command", "-", "wind_gust", "12", "0", "-1.5",
                          "1e+06"));
  // gps_degrade: duration_s, then the horizontal and vertical 1-sigma accuracy [m].
  EXPECT_THAT(PhysicsCommandArgv(dsl::Middleware::kCycloneDds, {"scout_1", "gps_degrade", {4.0, 5.0, 8.5}}),
              ElementsAre("/usr/local/bin/swarmbox-physics", "--sim-interface", "eth0", "--domain", "0",
                          "--middleware", "cyclonedds", "--send-command", "scout_1", "gps_degrade", "4", "5",
                          "8.5"));
}

// radio.model channel (the default): one network, no sidecars, the channel's flags and files.
class PlanChannelTest : public ::testing::Test {
 protected:
  void SetUp() override {
    auto spec = dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/sar_search.yaml");
    ASSERT_TRUE(spec) << spec.error().ToString();
    spec_ = *spec;
    ASSERT_EQ(spec_.radio.model, dsl::RadioModel::kChannel);
    options_.run_id = "20261121-101000-7f3a";
    options_.images = {"swarmbox/physics:abc", "swarmbox/agent:def"};
    options_.subnets = {*Ipv4Net::Parse("10.200.8.0/24"), *Ipv4Net::Parse("10.200.9.0/24")};
    options_.trials_dir = "/src/trials";
    options_.faults_image = "swarmbox/faults:f00";  // sar_search impairs the mesh: no sidecar anyway
    options_.radio_plan_path = "/runs/sar-search-20261121-101000-7f3a/radio_plan.json";
  }
  static std::string ValueOf(const std::vector<std::string>& argv, const std::string& flag) {
    auto it = std::find(argv.begin(), argv.end(), flag);
    return it == argv.end() || it + 1 == argv.end() ? "<absent>" : *(it + 1);
  }
  dsl::TrialSpec spec_;
  PlanOptions options_;
};

TEST_F(PlanChannelTest, NoMeshNetworkAndNoSidecars) {
  EXPECT_FALSE(NeedsFaultSidecars(spec_));
  spec_.Fault("{at: 10s, duration: 5s, partition: {groups: [[scout_1], [scout_2]]}}");
  EXPECT_FALSE(NeedsFaultSidecars(spec_));
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial) << trial.error().ToString();
  auto nets = (*trial)->Networks();
  ASSERT_EQ(nets.size(), 1u);
  EXPECT_EQ(nets[0]->id(), "sim");
  std::vector<std::string> ids;
  for (auto* p : (*trial)->Plugins()) ids.push_back(p->id());
  EXPECT_THAT(ids, ElementsAre("physics", "scout_1", "scout_2", "scout_3", "lifter"));
  EXPECT_EQ((*trial)->Find("faults"), nullptr);
  EXPECT_EQ((*trial)->Find("drones")->run_priority(), 2);
  const dsl::ContainerSpec& lifter = (*trial)->FindPlugin("lifter")->spec();
  ASSERT_EQ(lifter.networks.size(), 1u);
  EXPECT_EQ(lifter.networks[0].network, "sim");
  EXPECT_EQ(lifter.networks[0].ipv4, "10.200.8.13");
  EXPECT_EQ(lifter.hostname, "lifter");
  EXPECT_TRUE(lifter.network_of.empty());
}

TEST_F(PlanChannelTest, AgentsRunTheChannelRadioWithoutMeshFlags) {
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  for (const std::string d : {"scout_1", "lifter"}) {
    const auto& argv = (*trial)->FindPlugin(d)->spec().argv;
    EXPECT_EQ(ValueOf(argv, "--radio-model"), "channel") << d;
    EXPECT_EQ(ValueOf(argv, "--mesh-interface"), "<absent>") << d;
    EXPECT_EQ(ValueOf(argv, "--mesh-domain"), "<absent>") << d;
    EXPECT_EQ(ValueOf(argv, "--sim-interface"), "eth0") << d;
    EXPECT_EQ(ValueOf(argv, "--members"), "scout_1,scout_2,scout_3,lifter") << d;
    EXPECT_EQ(ValueOf(argv, "--ping-every-ms"), "200") << d;
  }
}

TEST_F(PlanChannelTest, ThePhysicsServerGetsTheProfileAndThePlanCopiedIn) {
  spec_.Fault("{at: 30s, kill: raft_leader}");
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  const dsl::ContainerSpec& physics = (*trial)->FindPlugin("physics")->spec();
  EXPECT_EQ(ValueOf(physics.argv, "--radio-model"), "channel");
  EXPECT_EQ(ValueOf(physics.argv, "--radio-profile"), "/swarmbox/trials/radios/wifi_5ghz_mesh.yaml");
  EXPECT_EQ(ValueOf(physics.argv, "--radio-plan"), "/swarmbox/radio_plan.json");
  // Faults at simulated times are the physics server's: no finer clock for the runner's timeline.
  EXPECT_EQ(ValueOf(physics.argv, "--clock-every"), "<absent>");
  bool profile = false;
  bool plan = false;
  for (const dsl::InputFile& in : physics.inputs) {
    if (in.container_path == "/swarmbox/trials/radios/wifi_5ghz_mesh.yaml") {
      profile = true;
      EXPECT_EQ(in.host_path, "/src/trials/radios/wifi_5ghz_mesh.yaml");
    }
    if (in.container_path == "/swarmbox/radio_plan.json") {
      plan = true;
      EXPECT_EQ(in.host_path, options_.radio_plan_path);
    }
  }
  EXPECT_TRUE(profile);
  EXPECT_TRUE(plan);
  // The agents need neither.
  for (const dsl::InputFile& in : (*trial)->FindPlugin("scout_1")->spec().inputs) {
    EXPECT_EQ(in.container_path.find("radio"), std::string::npos) << in.container_path;
  }

  // A profile by path; no plan file: no --radio-plan.
  spec_.radio.profile = "radios/lab/bench.yaml";
  options_.radio_plan_path.clear();
  trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  const auto& argv = (*trial)->FindPlugin("physics")->spec().argv;
  EXPECT_EQ(ValueOf(argv, "--radio-profile"), "/swarmbox/trials/radios/lab/bench.yaml");
  EXPECT_EQ(ValueOf(argv, "--radio-plan"), "<absent>");
}

TEST_F(PlanChannelTest, NetemKeepsTheFlagsOfBefore) {
  spec_.radio.model = dsl::RadioModel::kNetem;
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  EXPECT_EQ(ValueOf((*trial)->FindPlugin("physics")->spec().argv, "--radio-model"), "<absent>");
  EXPECT_EQ(ValueOf((*trial)->FindPlugin("physics")->spec().argv, "--radio-plan"), "<absent>");
  EXPECT_EQ(ValueOf((*trial)->FindPlugin("scout_1")->spec().argv, "--radio-model"), "<absent>");
  EXPECT_EQ(ValueOf((*trial)->FindPlugin("scout_1")->spec().argv, "--mesh-interface"), "eth1");
  EXPECT_NE((*trial)->FindPlugin("scout_1-faults"), nullptr);
}

TEST_F(PlanChannelTest, TheRadioProfileMustExistOnTheHost) {
  const std::string trials = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
  spec_.radio.profile = "no_such_radio";
  Status s = CheckRadioProfile(spec_, trials);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(s.error().message().find("radio profile 'no_such_radio' not found (no file " + trials +
                                     "/radios/no_such_radio.yaml)"),
            std::string::npos)
      << s.error().ToString();
  spec_.radio.profile = "worlds/open_field.yaml";  // any file there: only existence is checked here
  EXPECT_TRUE(CheckRadioProfile(spec_, trials));
  spec_.radio.model = dsl::RadioModel::kNetem;
  spec_.radio.profile = "no_such_radio";
  EXPECT_TRUE(CheckRadioProfile(spec_, trials));
}

// compose exports the channel: one network, the flags, the plan bind-mounted from next to the file.
TEST_F(PlanChannelTest, ComposeExportsTheChannel) {
  options_.run_id = "compose";
  options_.radio_plan_path = "./sar_search.compose.radio_plan.json";
  auto trial = PlanTrial(spec_, options_);
  ASSERT_TRUE(trial);
  ComposeOptions co;
  co.host_prefix = "/src/trials";
  co.relative_prefix = "../trials";
  const std::string text = ComposeYaml(**trial, co);
  auto doc = yaml::Parse(text, "compose.yaml");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(doc->Find("networks")->Find("mesh"), nullptr) << text;
  EXPECT_NE(doc->Find("networks")->Find("sim"), nullptr);
  EXPECT_NE(text.find("- \"../trials/radios/wifi_5ghz_mesh.yaml:/swarmbox/trials/radios/wifi_5ghz_mesh.yaml:ro\""),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("- \"./sar_search.compose.radio_plan.json:/swarmbox/radio_plan.json:ro\""), std::string::npos);
  EXPECT_NE(text.find("- \"--radio-model\"\n      - \"channel\""), std::string::npos);
  EXPECT_EQ(text.find("NET_ADMIN"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::runner
