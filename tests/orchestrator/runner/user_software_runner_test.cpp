// The runner with the user's software, on FakeDockerApi: components start by priority and wait for
// their readiness line, their files come back into <trial>/components/<name>/ on success and on
// failure, an external brain's container may go without ending the trial (the agent's failsafe
// answers), a crashing component fails it, and nothing is left afterwards.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <sstream>

#include "support/fake_clock.hpp"
#include "support/fake_docker_api.hpp"
#include "support/files.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string ReadFile(const fs::path& p) { return swarmbox::testing::ReadWholeFile(p.string()); }

class UserSoftwareRunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("swarmbox-user-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(out_);
    spec_ = dsl::TrialSpec::Named("byo")
                .Seed(1)
                .World("worlds/open_field.yaml")
                .Drone("scout_1", "x500", {0, 0, 0})
                .Drone("scout_2", "x500", {3, 0, 0})
                .EndOn("event=rendezvous_complete", dsl::Outcome::kSuccess, "", "scout_1")
                .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout, dsl::Duration::Seconds(600));
    spec_.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
    spec_.Brain("scout_2", dsl::BrainSpec::Program("/b/swarmbox_c_brain"));
    dsl::UserComponentSpec ground = dsl::UserComponentSpec::Program("ground", "/b/ground");
    ground.networks = {"sim"};
    ground.priority = 5;
    ground.ready = "event=ground_ready";
    ground.collect = {"/tmp/ground.csv"};
    spec_.Component(ground);
    options_.out_dir = out_.string();
    options_.run_id = "20261126-060000-beef";
    options_.images = {"swarmbox/physics:t", "swarmbox/agent:t"};
    options_.images.brains["scout_2"] = "swarmbox/brain:t";
    options_.images.components["ground"] = "swarmbox/component:t";
    options_.poll = std::chrono::milliseconds(5);
    api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=1.000 node=physics event=tick"};
    api_.scripts["ground"].lines = {"t=0 node=ground event=ground_ready"};
    api_.scripts["ground"].files["/tmp/ground.csv"] = "t,x\n0,1\n";
  }
  void TearDown() override { fs::remove_all(out_); }

  RunOutcome Run() {
    testing::FakeClock clock(100, 0.001);
    auto run = RunTrialSpec(spec_, api_, clock, options_);
    EXPECT_TRUE(run) << run.error().ToString();
    return run ? *run : RunOutcome{};
  }

  // The "start <container>" calls, in order, by component.
  std::vector<std::string> Starts() const {
    const std::string prefix = "start byo-20261126-060000-beef-";
    std::vector<std::string> out;
    for (const std::string& c : api_.Calls()) {
      if (c.rfind(prefix, 0) == 0) out.push_back(c.substr(prefix.size()));
    }
    return out;
  }

  fs::path out_;
  dsl::TrialSpec spec_;
  RunOptions options_;
  testing::FakeDockerApi api_;
};

TEST_F(UserSoftwareRunnerTest, AComponentStartsFirstAndItsFileComesBack) {
  api_.scripts["scout_1"].lines = {"t=40 node=scout_1 event=rendezvous_complete members=2"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  // Level by level; the two agents form one level (started at once, in any order).
  const std::vector<std::string> starts = Starts();
  ASSERT_EQ(starts.size(), 5u);
  EXPECT_THAT(std::vector<std::string>(starts.begin(), starts.begin() + 3),
              ::testing::ElementsAre("ground", "physics", "scout_2-brain"));
  EXPECT_THAT(std::vector<std::string>(starts.begin() + 3, starts.end()),
              ::testing::UnorderedElementsAre("scout_1", "scout_2"));
  const fs::path dir = run.trial_dir;
  EXPECT_EQ(ReadFile(dir / "components" / "ground" / "ground.csv"), "t,x\n0,1\n");
  EXPECT_THAT(ReadFile(dir / "logs" / "ground.log"), HasSubstr("event=ground_ready"));
  // Labels: the brain's and the component's roles; every container was created with its own.
  int roles = 0;
  for (const docker::ContainerSpec& c : api_.Created()) {
    const auto role = c.labels.find("swarmbox.role");
    if (c.name.ends_with("-scout_2-brain")) {
      ASSERT_NE(role, c.labels.end());
      EXPECT_EQ(role->second, "brain");
      ++roles;
    }
    if (c.name.ends_with("-ground")) {
      ASSERT_NE(role, c.labels.end());
      EXPECT_EQ(role->second, "component");
      ++roles;
    }
    EXPECT_EQ(c.labels.at("swarmbox.run"), "20261126-060000-beef");
  }
  EXPECT_EQ(roles, 2);
  EXPECT_TRUE(api_.Containers().empty());
  EXPECT_TRUE(api_.Networks().empty());
}

TEST_F(UserSoftwareRunnerTest, AnExternalBrainThatGoesDoesNotEndTheTrial) {
  // The brain is killed (137) while the drones fly on; scout_1 completes later.
  api_.scripts["scout_2-brain"].lines = {"brain: up"};
  api_.scripts["scout_2-brain"].exit_code = 137;
  api_.scripts["scout_2"].lines = {"t=5 node=scout_2 event=offboard_lost silent_s=1.0 action=hold"};
  api_.scripts["scout_1"].log_after_exit_seen = {"scout_2-brain"};  // the runner saw the exit first
  api_.scripts["scout_1"].lines = {"t=9 node=scout_1 event=tick", "t=40 node=scout_1 event=rendezvous_complete members=2"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.reason, "matched 'event=rendezvous_complete'");
  const std::string events = ReadFile(fs::path(run.trial_dir) / "events.jsonl");
  EXPECT_THAT(events, HasSubstr("\"component\":\"scout_2-brain\",\"event\":\"exited\",\"exit_code\":137"));
  EXPECT_THAT(events, HasSubstr("\"event\":\"offboard_lost\""));
  EXPECT_TRUE(api_.Containers().empty());
}

TEST_F(UserSoftwareRunnerTest, ACrashingComponentFailsTheTrialAndItsFileStillComesBack) {
  api_.scripts["ground"].lines = {"t=0 node=ground event=ground_ready", "fatal: lost the link"};
  api_.scripts["ground"].exit_code = 3;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure);
  EXPECT_EQ(run.result.verdict.reason, "ground exited with code 3 before the trial ended");
  EXPECT_EQ(ReadFile(fs::path(run.trial_dir) / "components" / "ground" / "ground.csv"), "t,x\n0,1\n");
  EXPECT_TRUE(api_.Containers().empty());
  EXPECT_TRUE(api_.Networks().empty());
}

TEST_F(UserSoftwareRunnerTest, AComponentThatFinishesItsJobDoesNotEndTheTrial) {
  api_.scripts["ground"].exit_code = 0;
  api_.scripts["scout_1"].log_after_exit_seen = {"ground"};
  api_.scripts["scout_1"].lines = {"t=3 node=scout_1 event=tick", "t=40 node=scout_1 event=rendezvous_complete members=2"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.reason, "matched 'event=rendezvous_complete'");
  EXPECT_THAT(ReadFile(fs::path(run.trial_dir) / "events.jsonl"),
              HasSubstr("\"component\":\"ground\",\"event\":\"exited\",\"exit_code\":0"));
  EXPECT_EQ(ReadFile(fs::path(run.trial_dir) / "components" / "ground" / "ground.csv"), "t,x\n0,1\n");
}

TEST_F(UserSoftwareRunnerTest, AComponentThatNeverGetsReadyStopsTheStartBeforeThePhysicsServer) {
  api_.scripts["ground"].lines = {"starting", "cannot open port"};
  api_.scripts["ground"].exit_code = 1;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("ground exited with code 1 before it was ready"));
  EXPECT_THAT(Starts(), ::testing::ElementsAre("ground"));  // nothing later started
  EXPECT_TRUE(api_.Containers().empty());
  EXPECT_TRUE(api_.Networks().empty());
}

}  // namespace
}  // namespace swarmbox::runner
