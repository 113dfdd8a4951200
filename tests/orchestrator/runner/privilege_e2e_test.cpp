// Least privilege on the real engine with the real programs. A short mission kind plan trial with
// a network.mesh impairment (so every agent has a fault sidecar) runs; while the agents fly, the
// test reads each container's HostConfig through the Engine API (GET /containers/{id}/json) and
// checks what plan.cpp promises: agents and the physics server with every capability dropped and
// none added, no-new-privileges, a read-only root filesystem with the volume at /swarmbox and the
// scratch tmpfs at /tmp, the trial's memory and pids limits; the sidecar with NET_ADMIN alone.
// The trial still succeeds (the Raft WAL is written in the volume, truth.csv is collected from it
// after the stop). A second trial gives one drone a memory limit it cannot live in: result.json
// says it was OOM-killed and the trial failed for that reason.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <thread>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/standard_images.hpp"
#include "swarmbox/runner/fault_image.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/plan.hpp"
#include "swarmbox/runner/runner.hpp"
#include "support/files.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::ElementsAre;
using ::testing::HasSubstr;
using ::testing::IsEmpty;

// A SAR agent peaks at 10-11 MiB (9-10 MiB anonymous) on sar_search; Docker's minimum, 6 MiB, lets
// its container start (measured: a bad-flag run exits 2 normally in it) but not the SAR mission
// (a plan flight does fit: measured, the trial succeeded).
constexpr int kOomDroneMemoryMib = 6;

class PrivilegeE2e : public ::testing::Test {
 protected:
  void SetUp() override {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
    api_ = std::move(*client);
    auto physics = images::EnsureImage(*api_, images::PhysicsImage(SWARMBOX_PHYSICS_BIN), {}, nullptr);
    ASSERT_TRUE(physics) << physics.error().ToString();
    auto agent = images::EnsureImage(*api_, images::AgentImage(SWARMBOX_AGENT_BIN), {}, nullptr);
    ASSERT_TRUE(agent) << agent.error().ToString();
    options_.images = {physics->tag, agent->tag};
    options_.run_id = NewRunId();
    options_.host = "privilege-e2e";
    options_.poll = std::chrono::milliseconds(50);
    mine_.equals[std::string(docker::kLabelRun)] = options_.run_id;
  }
  void TearDown() override {
    if (api_) (void)docker::RemoveLabelled(*api_, mine_, false);
  }

  static dsl::TrialSpec Flight(std::string name) {
    dsl::TrialSpec spec = dsl::TrialSpec::Named(std::move(name))
                              .Seed(23)
                              .World("worlds/open_field.yaml")
                              .Rtf(1.0)
                              .Drone("scout_1", "x500", {0, 0, 0})
                              .Drone("scout_2", "x500", {4, 0, 0})
                              .Mission({dsl::MissionKind::kPlan, "takeoff:3,hover:4,land", 40})
                              .EndOn("event=plan_complete", dsl::Outcome::kSuccess, {}, "scout_2")
                              .EndOn("event=crash", dsl::Outcome::kFailure, "crash")
                              .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout,
                                       dsl::Duration::Seconds(240));
    spec.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
    spec.radio.model = dsl::RadioModel::kNetem;  // fault sidecars with NET_ADMIN are inspected too
    return spec;
  }

  std::unique_ptr<docker::DockerClient> api_;
  RunOptions options_;
  docker::LabelSelector mine_;
};

// Agents and the physics server, as plan.cpp confines them.
void ExpectConfined(const docker::ContainerInfo& c, const dsl::ContainerLimits& limits) {
  SCOPED_TRACE(c.name);
  const docker::ContainerHostConfig& h = c.host_config;
  EXPECT_THAT(h.cap_drop, ElementsAre("ALL"));
  EXPECT_THAT(h.cap_add, IsEmpty());
  EXPECT_THAT(h.security_opt, ElementsAre("no-new-privileges"));
  EXPECT_TRUE(h.read_only_rootfs);
  EXPECT_EQ(h.memory_bytes, std::int64_t{limits.memory_mib} << 20);
  EXPECT_EQ(h.pids_limit, limits.pids);
  ASSERT_EQ(h.mounts.size(), 2u);
  EXPECT_EQ(h.mounts[0].type, docker::Mount::Type::kVolume);
  EXPECT_EQ(h.mounts[0].target, kContainerVolumeDir);
  EXPECT_FALSE(h.mounts[0].read_only);
  EXPECT_EQ(h.mounts[1].type, docker::Mount::Type::kTmpfs);
  EXPECT_EQ(h.mounts[1].target, kScratchTmpfsDir);
  EXPECT_EQ(h.mounts[1].tmpfs_size_bytes, kScratchTmpfsMib << 20);
}

TEST_F(PrivilegeE2e, AgentsPhysicsAndSidecarsRunWithLeastPrivilegeAndTheTrialSucceeds) {
  auto faults_image = EnsureFaultsImage(*api_, SWARMBOX_NETEMD_BIN, {});
  ASSERT_TRUE(faults_image) << faults_image.error().ToString();
  options_.faults_image = *faults_image;
  dsl::TrialSpec spec = Flight("privilege-e2e");
  spec.Mesh("{delay_ms: 20, loss: 0.02}");  // every agent gets a fault sidecar
  spec.Limits({400, 200});
  spec.drones[1].limits = {300, 0};  // scout_2: its own memory limit, the trial's pids
  const fs::path out = fs::temp_directory_path() / "swarmbox-privilege-e2e";
  fs::remove_all(out);
  options_.out_dir = out.string();

  SteadyClock clock;
  Result<RunOutcome> run = Error(ErrorCode::kInternal, "not run");
  std::atomic<bool> done{false};
  std::thread runner([&] {
    run = RunTrialSpec(spec, *api_, clock, options_);
    done.store(true);
  });
  auto name = [&](std::string_view component) { return ResourceName(spec.name, options_.run_id, component); };
  bool inspected = false;
  for (int i = 0; i < 600 && !done.load() && !inspected; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    auto scout_2 = api_->InspectContainer(name("scout_2"));
    if (!scout_2 || !scout_2->state.running) continue;
    inspected = true;
    auto physics = api_->InspectContainer(name("physics"));
    auto scout_1 = api_->InspectContainer(name("scout_1"));
    ASSERT_TRUE(physics) << physics.error().ToString();
    ASSERT_TRUE(scout_1) << scout_1.error().ToString();
    ExpectConfined(*physics, {400, 200});
    ExpectConfined(*scout_1, {400, 200});
    ExpectConfined(*scout_2, {300, 200});
    for (const std::string drone : {"scout_1", "scout_2"}) {
      auto sidecar = api_->InspectContainer(name(SidecarId(drone)));
      ASSERT_TRUE(sidecar) << sidecar.error().ToString();
      SCOPED_TRACE(sidecar->name);
      // tc and iptables-nft need NET_ADMIN, nothing else (no NET_RAW).
      EXPECT_THAT(sidecar->host_config.cap_drop, ElementsAre("ALL"));
      EXPECT_THAT(sidecar->host_config.cap_add, ElementsAre("NET_ADMIN"));
      EXPECT_THAT(sidecar->host_config.security_opt, ElementsAre("no-new-privileges"));
    }
  }
  runner.join();
  ASSERT_TRUE(inspected) << "the agents never ran";
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kSuccess) << run->result.verdict.ToString();
  // The mesh impairment was applied by the confined sidecars, Raft ran (its WAL in the volume),
  // truth.csv came out of the stopped physics container's volume.
  const std::string events = swarmbox::testing::ReadWholeFile((fs::path(run->trial_dir) / "events.jsonl").string());
  EXPECT_THAT(events, HasSubstr("{\"type\":\"mesh\",\"phase\":\"applied\",\"node\":\"scout_2\""));
  EXPECT_THAT(events, HasSubstr("\"event\":\"leader_elected\""));
  EXPECT_THAT(swarmbox::testing::ReadWholeFile((fs::path(run->trial_dir) / "truth.csv").string()), HasSubstr("t_s,"));
  EXPECT_THAT(run->result.problems, IsEmpty());
  const std::string result = swarmbox::testing::ReadWholeFile((fs::path(run->trial_dir) / "result.json").string());
  EXPECT_THAT(result, HasSubstr("\"oom_killed\":[]"));
  fs::remove_all(out);
}

TEST_F(PrivilegeE2e, ADroneOverItsMemoryLimitIsReportedAsOomKilled) {
  dsl::TrialSpec spec = Flight("oom-e2e");
  // The SAR mission (its agents hold 9-10 MiB anonymous memory; a plan flight lives in 6 MiB).
  spec.mission = dsl::MissionSpec{};
  spec.drones[0].limits = {kOomDroneMemoryMib, 0};  // scout_1 cannot live in this
  const fs::path out = fs::temp_directory_path() / "swarmbox-oom-e2e";
  fs::remove_all(out);
  options_.out_dir = out.string();
  SteadyClock clock;
  auto run = RunTrialSpec(spec, *api_, clock, options_);
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kFailure) << run->result.verdict.ToString();
  // The cause first; when the physics server reported the start before the kill, the drones that
  // did not join follow it ("; drones that did not join: ..."), which depends on timing.
  EXPECT_THAT(run->result.verdict.reason,
              ::testing::MatchesRegex("scout_1 was killed for lack of memory"
                                      "(; drones that did not join: [a-z0-9_,]+ \\((lost at the start, )?joined [0-9]+/2\\))?"));
  auto doc = yaml::ParseFile((fs::path(run->trial_dir) / "result.json").string());
  ASSERT_TRUE(doc) << doc.error().ToString();
  const yaml::Node* oom = doc->Find("oom_killed");
  ASSERT_NE(oom, nullptr);
  ASSERT_EQ(oom->items().size(), 1u);
  EXPECT_EQ(oom->items()[0].scalar(), "scout_1");
  for (const yaml::Node& c : doc->Find("components")->items()) {
    if (c.Find("name")->scalar() == "scout_1") {
      EXPECT_EQ(c.Find("exit_code")->scalar(), "137");
    }
  }
  fs::remove_all(out);
}

}  // namespace
}  // namespace swarmbox::runner
