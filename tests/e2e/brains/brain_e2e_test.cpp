// Bring your own swarm software (issue #24, "Done when"): trials/brains/rendezvous.yaml through the
// built `swarmbox run` on the real engine, with this build's example brains: scout_1 flies the C++
// rendezvous library in its agent (`--brain library`, the .so packed into its agent image),
// scout_2 the plain C program swarmbox_c_brain in its own container on the sim bus (`--brain
// external`).
//   1. Both complete the rendezvous (each logs event=rendezvous_complete members=2). The trial is
//      run to its simulated end (end conditions replaced, timeout outcome success) so that neither
//      drone's last line is cut off by the other's.
//   2. The external brain's container is killed while scout_2 flies to its slot: scout_2 holds
//      (event=offboard_lost), then lands (event=offboard_failsafe, event=landed), the trial goes on
//      (the brain's exit is recorded, not a crash).
// Afterwards nothing labelled with the runs is left.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <iostream>
#include <thread>

#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::e2e {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using swarmbox::testing::ChildProcess;
using swarmbox::testing::ReadWholeFile;
using swarmbox::testing::RunToEnd;

constexpr char kSwarmbox[] = SWARMBOX_CLI_EXE;
const std::string kTrial = std::string(SWARMBOX_SOURCE_DIR) + "/trials/brains/rendezvous.yaml";

class BrainE2e : public ::testing::Test {
 protected:
  void SetUp() override {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
    api_ = std::move(*client);
    dir_ = fs::temp_directory_path() / ("swarmbox-brain-e2e-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    for (const std::string& run : runs_) {
      docker::LabelSelector mine;
      mine.equals[std::string(docker::kLabelRun)] = run;
      if (api_ != nullptr) {
        (void)docker::RemoveLabelled(*api_, mine, /*include_images=*/false);
        auto containers = api_->ListContainers(mine, /*all=*/true);
        EXPECT_TRUE(containers && containers->empty()) << "containers of run " << run << " left";
        auto networks = api_->ListNetworks(mine);
        EXPECT_TRUE(networks && networks->empty()) << "networks of run " << run << " left";
      }
    }
    fs::remove_all(dir_);
  }

  // `swarmbox run` argv for this build's brains, plus `extra` --set overrides.
  std::vector<std::string> RunArgv(const std::string& run_id, const std::vector<std::string>& extra) {
    std::vector<std::string> argv = {kSwarmbox, "run", kTrial, "--out", dir_.string(), "--run-id", run_id,
                                     "--set", std::string("drones.scout_1.brain.library=") + SWARMBOX_RENDEZVOUS_SO,
                                     "--set", std::string("drones.scout_2.brain.program=") + SWARMBOX_C_BRAIN_EXE};
    for (const std::string& s : extra) {
      argv.push_back("--set");
      argv.push_back(s);
    }
    return argv;
  }

  // Nothing labelled with the run is left right after swarmbox returned.
  void ExpectNothingLeft(const std::string& run_id) {
    docker::LabelSelector mine;
    mine.equals[std::string(docker::kLabelRun)] = run_id;
    auto containers = api_->ListContainers(mine, /*all=*/true);
    ASSERT_TRUE(containers) << containers.error().ToString();
    EXPECT_TRUE(containers->empty());
    auto networks = api_->ListNetworks(mine);
    ASSERT_TRUE(networks) << networks.error().ToString();
    EXPECT_TRUE(networks->empty());
  }

  std::unique_ptr<docker::DockerClient> api_;
  fs::path dir_;
  std::vector<std::string> runs_;
};

TEST_F(BrainE2e, ALibraryBrainAndAnExternalCBrainCompleteTheRendezvous) {
  const std::string run_id = runner::NewRunId();
  runs_.push_back(run_id);
  auto done = RunToEnd(RunArgv(run_id, {"end=[{on: \"event=collision\", outcome: failure, reason: collision}]",
                                        "timeout.sim=70s", "timeout.outcome=success"}),
                       std::chrono::minutes(12), dir_.string());
  ASSERT_TRUE(done) << done.error().ToString();
  std::cout << done->out << done->err;
  EXPECT_EQ(done->code, 0) << done->err;
  const fs::path trial_dir = dir_ / runner::TrialDirName("rendezvous", run_id);
  const std::string scout_1 = ReadWholeFile((trial_dir / "logs" / "scout_1.log").string());
  const std::string scout_2 = ReadWholeFile((trial_dir / "logs" / "scout_2.log").string());
  EXPECT_THAT(scout_1, HasSubstr("event=brain_loaded kind=library name=rendezvous"));
  EXPECT_THAT(scout_2, HasSubstr("event=brain_loaded kind=external"));
  EXPECT_THAT(scout_1, HasSubstr("event=rendezvous_complete members=2"));
  EXPECT_THAT(scout_2, HasSubstr("event=rendezvous_complete members=2"));
  EXPECT_TRUE(fs::exists(trial_dir / "logs" / "scout_2-brain.log"));  // kept like every container's
  const std::string events = ReadWholeFile((trial_dir / "events.jsonl").string());
  EXPECT_THAT(events, HasSubstr("\"event\":\"run\",\"target\":\"scout_2-brain\",\"outcome\":\"success\""));
  ExpectNothingLeft(run_id);
}

TEST_F(BrainE2e, KillingTheExternalBrainMakesItsDroneHoldAndLand) {
  const std::string run_id = runner::NewRunId();
  runs_.push_back(run_id);
  const fs::path out = dir_ / "kill.out";
  auto child = ChildProcess::Spawn(
      RunArgv(run_id, {"end=[{on: \"event=landed\", outcome: success, from: scout_2}, "
                       "{on: \"event=collision\", outcome: failure, reason: collision}]"}),
      out.string(), out.string());
  ASSERT_TRUE(child) << child.error().ToString();
  const fs::path trial_dir = dir_ / runner::TrialDirName("rendezvous", run_id);
  const fs::path scout_2_log = trial_dir / "logs" / "scout_2.log";
  // Once scout_2 flies to its slot (it logged the rendezvous point), its brain's container is
  // killed.
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(6);
  bool killed = false;
  while (!killed && child->running() && std::chrono::steady_clock::now() < deadline) {
    if (ReadWholeFile(scout_2_log.string()).find("event=rendezvous_point") != std::string::npos) {
      Status s = api_->KillContainer(runner::ResourceName("rendezvous", run_id, "scout_2-brain"), "SIGKILL");
      ASSERT_TRUE(s) << s.error().ToString();
      killed = true;
    } else {
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  }
  ASSERT_TRUE(killed) << ReadWholeFile(out.string());
  const std::optional<int> code = child->Wait(std::chrono::minutes(6));
  std::cout << ReadWholeFile(out.string());
  ASSERT_TRUE(code.has_value()) << "swarmbox run did not end";
  EXPECT_EQ(*code, 0);
  const std::string log = ReadWholeFile(scout_2_log.string());
  const auto lost = log.find("event=offboard_lost");
  const auto failsafe = log.find("event=offboard_failsafe");
  const auto landed = log.rfind("event=landed");
  ASSERT_NE(lost, std::string::npos) << log;
  ASSERT_NE(failsafe, std::string::npos) << log;
  ASSERT_NE(landed, std::string::npos) << log;
  EXPECT_LT(lost, failsafe);
  EXPECT_LT(failsafe, landed);
  EXPECT_THAT(log.substr(lost), HasSubstr("action=hold"));
  EXPECT_THAT(log.substr(failsafe), HasSubstr("action=land"));
  const std::string events = ReadWholeFile((trial_dir / "events.jsonl").string());
  EXPECT_THAT(events, HasSubstr("\"component\":\"scout_2-brain\",\"event\":\"exited\",\"exit_code\":137"));
  EXPECT_THAT(events, HasSubstr("\"event\":\"offboard_lost\""));
  EXPECT_THAT(events, HasSubstr("\"event\":\"offboard_failsafe\""));
  ExpectNothingLeft(run_id);
}

}  // namespace
}  // namespace swarmbox::e2e
