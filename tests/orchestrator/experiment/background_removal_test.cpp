// Background removal of a trial's containers and networks (background_removal.hpp), on the
// runner's FakeDockerApi: the trial's result is written while its removal is still held up, the
// queue removes containers before their networks, a recreated name waits for its own removal,
// Docker 20.10's stale endpoints are retried, and RunExperiment waits for every removal before
// its leftover sweep (so the sweep finds nothing and nothing is left).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <optional>

#include "support/fake_clock.hpp"
#include "support/fake_docker_api.hpp"
#include "swarmbox/experiment/background_removal.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::experiment {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::size_t IndexOf(const std::vector<std::string>& calls, const std::string& call, std::size_t from = 0) {
  for (std::size_t i = from; i < calls.size(); ++i) {
    if (calls[i] == call) return i;
  }
  return calls.size();
}

// A fake engine whose container removals wait until the test opens the gate (10 s in vain: the
// removal fails, so a runner that waited for it fails the test instead of hanging it).
class GatedRemovalApi : public testing::FakeDockerApi {
 public:
  Status RemoveContainer(std::string_view id, bool force, bool remove_volumes) override {
    {
      std::unique_lock lock(gate_mu_);
      ++waiting_;
      gate_cv_.notify_all();
      if (!gate_cv_.wait_for(lock, std::chrono::seconds(10), [&] { return open_; })) {
        return Error(ErrorCode::kTimeout, "the removal gate was never opened");
      }
    }
    return FakeDockerApi::RemoveContainer(id, force, remove_volumes);
  }
  void Open() {
    std::lock_guard lock(gate_mu_);
    open_ = true;
    gate_cv_.notify_all();
  }
  // Blocks until a removal waits at the gate (false after 10 s).
  bool AwaitWaiting() {
    std::unique_lock lock(gate_mu_);
    return gate_cv_.wait_for(lock, std::chrono::seconds(10), [&] { return waiting_ > 0; });
  }

 private:
  std::mutex gate_mu_;
  std::condition_variable gate_cv_;
  bool open_ = false;
  int waiting_ = 0;
};

dsl::TrialSpec MiniTrial(const std::string& name) {
  dsl::TrialSpec spec = dsl::TrialSpec::Named(name)
                            .Seed(3)
                            .World("worlds/open_field.yaml")
                            .Drone("scout_1", "x500", {0, 0, 0})
                            .Drone("scout_2", "x500", {3, 0, 0})
                            .Mission({dsl::MissionKind::kPlan, "takeoff:5,hover:10,land", 40})
                            .EndOn("event=done", dsl::Outcome::kSuccess)
                            .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout,
                                     dsl::Duration::Seconds(600));
  spec.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
  spec.radio.model = dsl::RadioModel::kNetem;  // the two networks these removals are about
  return spec;
}

class BackgroundRemovalTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("swarmbox-bg-removal-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(out_);
  }
  void TearDown() override { fs::remove_all(out_); }
  fs::path out_;
};

TEST_F(BackgroundRemovalTest, TheTrialsResultIsWrittenWhileItsRemovalIsStillHeldUp) {
  GatedRemovalApi api;
  api.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=2.000 node=physics event=done"};
  BackgroundRemover remover(api, "fake");
  runner::RunOptions o;
  o.out_dir = out_.string();
  o.run_id = "20261121-220000-beef";
  o.images = {"swarmbox/physics:test", "swarmbox/agent:test"};
  o.poll = std::chrono::milliseconds(5);
  swarmbox::testing::FakeClock clock(100, 0.001);
  std::optional<Result<runner::RunOutcome>> ran;
  {
    DeferredRemovalApi deferred(api, remover);
    ran.emplace(runner::RunTrialSpec(MiniTrial("mini"), deferred, clock, o));
  }
  Result<runner::RunOutcome>& run = *ran;
  ASSERT_TRUE(run) << run.error().ToString();
  EXPECT_EQ(run->result.verdict.outcome, dsl::Outcome::kSuccess) << run->result.verdict.ToString();
  EXPECT_TRUE(fs::exists(fs::path(run->trial_dir) / "result.json"));
  EXPECT_TRUE(fs::exists(fs::path(run->trial_dir) / "logs" / "physics.log"));
  // Given: the first removal waits at the gate. Then: every container and both networks are
  // still on the engine, though the trial has ended and written its result.
  ASSERT_TRUE(api.AwaitWaiting());
  EXPECT_EQ(api.Containers().size(), 3u);
  EXPECT_EQ(api.Networks().size(), 2u);
  for (const std::string& p : run->result.problems) EXPECT_THAT(p, ::testing::Not(HasSubstr("remov")));
  // When the gate opens and the queue is drained: nothing is left, containers went first.
  api.Open();
  remover.Drain();
  EXPECT_TRUE(api.Containers().empty());
  EXPECT_TRUE(api.Networks().empty());
  EXPECT_TRUE(remover.TakeProblems().empty());
  const auto calls = api.Calls();
  std::size_t last_container = 0;
  std::size_t first_network = calls.size();
  for (std::size_t i = 0; i < calls.size(); ++i) {
    if (calls[i].rfind("remove ", 0) == 0) last_container = i;
    if (calls[i].rfind("remove-network ", 0) == 0) first_network = std::min(first_network, i);
  }
  EXPECT_LT(last_container, first_network) << ::testing::PrintToString(calls);
}

TEST_F(BackgroundRemovalTest, ANameCreatedAgainWaitsForItsOwnRemoval) {
  testing::FakeDockerApi api;
  BackgroundRemover remover(api, "fake");
  DeferredRemovalApi deferred(api, remover);
  docker::NetworkSpec net;
  net.name = "t-net";
  net.subnet = "10.77.0.0/24";
  auto net_id = deferred.CreateNetwork(net);
  ASSERT_TRUE(net_id) << net_id.error().ToString();
  docker::ContainerSpec c;
  c.name = "t-box";
  c.image = "swarmbox/agent:test";
  auto id = deferred.CreateContainer(c);
  ASSERT_TRUE(id) << id.error().ToString();
  ASSERT_TRUE(deferred.RemoveContainer(*id, true, true));  // queued, answered at once
  ASSERT_TRUE(deferred.RemoveNetwork(*net_id));
  // A restart creates the same names: Docker would refuse them while the old ones exist.
  auto again = deferred.CreateContainer(c);
  ASSERT_TRUE(again) << again.error().ToString();
  auto net_again = deferred.CreateNetwork(net);
  ASSERT_TRUE(net_again) << net_again.error().ToString();
  const auto calls = api.Calls();
  const std::size_t removed = IndexOf(calls, "remove t-box");
  ASSERT_LT(removed, calls.size()) << ::testing::PrintToString(calls);
  EXPECT_LT(removed, IndexOf(calls, "create t-box", IndexOf(calls, "create t-box") + 1));
  EXPECT_LT(IndexOf(calls, "remove-network t-net"),
            IndexOf(calls, "create-network t-net", IndexOf(calls, "create-network t-net") + 1));
  remover.Drain();
  EXPECT_TRUE(remover.TakeProblems().empty());
}

TEST_F(BackgroundRemovalTest, StaleEndpointsAreRetriedAndALastingOneIsAProblemNamingTheFix) {
  testing::FakeDockerApi api;
  BackgroundRemover remover(api, "lab2");
  DeferredRemovalApi deferred(api, remover);
  docker::NetworkSpec net;
  net.name = "t-mesh";
  net.subnet = "10.78.0.0/24";
  auto first = deferred.CreateNetwork(net);
  ASSERT_TRUE(first);
  api.stale_endpoints = 2;  // released after two refusals
  ASSERT_TRUE(deferred.RemoveNetwork(*first));
  remover.Drain();
  EXPECT_TRUE(api.Networks().empty());
  EXPECT_TRUE(remover.TakeProblems().empty());

  auto second = deferred.CreateNetwork(net);
  ASSERT_TRUE(second);
  api.stale_endpoints = 1000;  // never released
  ASSERT_TRUE(deferred.RemoveNetwork(*second));
  remover.Drain();
  const auto problems = remover.TakeProblems();
  ASSERT_EQ(problems.size(), 1u);
  EXPECT_THAT(problems[0], HasSubstr("lab2: network " + *second + " left on the engine"));
  EXPECT_THAT(problems[0], HasSubstr("moby#43286"));
  EXPECT_THAT(problems[0], HasSubstr("swarmbox gc"));
}

TEST_F(BackgroundRemovalTest, AContainerAlreadyGoneIsNotAProblem) {
  testing::FakeDockerApi api;
  BackgroundRemover remover(api, "fake");
  DeferredRemovalApi deferred(api, remover);
  ASSERT_TRUE(deferred.RemoveContainer("no-such-container", true, true));
  remover.Drain();
  EXPECT_TRUE(remover.TakeProblems().empty());
}

// The experiment: two trials on one slot of a fake host, removal in the background. Once
// RunExperiment returns every removal has run: the leftover sweep found nothing (it would list
// what it removed among the problems) and the engine is empty.
TEST_F(BackgroundRemovalTest, TheExperimentWaitsForEveryBackgroundRemovalBeforeItsLeftoverSweep) {
  testing::FakeDockerApi api;
  api.scripts["physics"].lines = {"t=0.000 node=physics event=ready", "t=2.000 node=physics event=done"};
  ExperimentPlan plan;
  plan.spec.name = "mini";
  for (int rep = 1; rep <= 2; ++rep) {
    PlannedTrial t;
    t.id = TrialId("mini", "a", rep);
    t.code = "a";
    t.repetition = rep;
    t.seed = static_cast<std::uint64_t>(rep);
    plan.trials.push_back(t);
    plan.specs.emplace(t.id, MiniTrial(t.id));
  }
  std::vector<PoolHost> pool = {{"fake", 1, &api, [] { return Status(Ok{}); },
                                 runner::Images{"swarmbox/physics:test", "swarmbox/agent:test"}, ""}};
  ExperimentOptions o;
  o.out_dir = (out_ / "exp").string();
  o.run_id = "20261121-220001-beef";
  o.trial_options.poll = std::chrono::milliseconds(5);
  ASSERT_TRUE(o.remove_in_background);  // the default
  auto summary = RunExperiment(plan, pool, o);
  ASSERT_TRUE(summary) << summary.error().ToString();
  EXPECT_EQ(summary->committed, 2u);
  EXPECT_EQ(summary->outcomes["success"], 2u);
  for (const std::string& p : summary->problems) ADD_FAILURE() << "problem: " << p;
  EXPECT_TRUE(api.Containers().empty());
  EXPECT_TRUE(api.Networks().empty());
  // Each trial's containers went before its networks (the two trials' removals may interleave
  // with the next launch, not with each other).
  const auto calls = api.Calls();
  for (const std::string& trial : {plan.trials[0].id, plan.trials[1].id}) {
    std::size_t last_container = 0;
    std::size_t first_network = calls.size();
    for (std::size_t i = 0; i < calls.size(); ++i) {
      if (calls[i].find(trial) == std::string::npos) continue;
      if (calls[i].rfind("remove ", 0) == 0) last_container = i;
      if (calls[i].rfind("remove-network ", 0) == 0) first_network = std::min(first_network, i);
    }
    EXPECT_LT(last_container, first_network) << trial << ": " << ::testing::PrintToString(calls);
  }
}

}  // namespace
}  // namespace swarmbox::experiment
