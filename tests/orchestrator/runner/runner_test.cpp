// The runner end to end against FakeDockerApi and a fake clock: how trials end (log pattern, sim
// timeout, crash, wall-clock guard, readiness, Ctrl-C), that logs and artifacts are collected and
// that teardown leaves nothing behind on every path.
#include "swarmbox/runner/runner.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <condition_variable>
#include <filesystem>
#include <functional>
#include <fstream>
#include <mutex>
#include <sstream>
#include <thread>

#include "support/fake_clock.hpp"
#include "support/fake_docker_api.hpp"
#include "support/files.hpp"
#include "swarmbox/common/version.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/docker/tar_archive.hpp"
#include "swarmbox/runner/docker_engine.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

std::string ReadFile(const fs::path& p) { return swarmbox::testing::ReadWholeFile(p.string()); }

class RunnerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("swarmbox-runner-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(out_);
    spec_ = dsl::TrialSpec::Named("mini")
                .Seed(5)
                .World("worlds/open_field.yaml")
                .Drone("scout_1", "x500", {0, 0, 0})
                .EndOn("event=mission_complete", dsl::Outcome::kSuccess)
                .EndOn("event=collision", dsl::Outcome::kFailure, "collision")
                .Timeout(dsl::Duration::Seconds(60), dsl::Outcome::kTimeout, dsl::Duration::Seconds(600));
    spec_.trials_dir = std::string(SWARMBOX_SOURCE_DIR) + "/trials";
    // The netem model's tree (mesh network, sidecars), as these tests were written for; the
    // channel's runs are in channel_runner_test.cpp.
    spec_.radio.model = dsl::RadioModel::kNetem;
    options_.out_dir = out_.string();
    options_.run_id = "20261121-120000-abcd";
    options_.images = {"swarmbox/physics:test", "swarmbox/agent:test"};
    options_.poll = std::chrono::milliseconds(5);
    api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready",
                                     "t=1.000 node=physics event=tick"};
    api_.scripts["physics"].files["/swarmbox/out/truth.csv"] =
        "t_s,drone,x_m,y_m,z_m\n0.0,scout_1,0,0,0\n1.0,scout_1,1,2,3\n";
  }
  void TearDown() override { fs::remove_all(out_); }

  RunOutcome Run(double clock_step = 0.001) {
    testing::FakeClock clock(1000, clock_step);
    auto run = RunTrialSpec(spec_, api_, clock, options_);
    EXPECT_TRUE(run) << run.error().ToString();
    if (!run) return {};
    return *run;
  }

  // Nothing labelled with the run is left, and every container was removed.
  void ExpectNothingLeft() {
    EXPECT_TRUE(api_.Containers().empty());
    EXPECT_TRUE(api_.Networks().empty());
  }

  fs::path out_;
  dsl::TrialSpec spec_;
  RunOptions options_;
  testing::FakeDockerApi api_;
};

TEST_F(RunnerTest, EndsOnALogPatternWithItsOutcome) {
  api_.scripts["scout_1"].lines = {"t=0.5 node=scout_1 event=takeoff",
                                   "t=20.0 node=scout_1 event=mission_complete victims=2"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.reason, "matched 'event=mission_complete'");
  EXPECT_EQ(run.result.verdict.source, "scout_1");
  EXPECT_EQ(run.result.ending_line, "t=20.0 node=scout_1 event=mission_complete victims=2");
  EXPECT_EQ(run.trial_dir, (out_ / "mini-20261121-120000-abcd").string());
  ExpectNothingLeft();

  const fs::path dir = run.trial_dir;
  EXPECT_THAT(ReadFile(dir / "logs" / "scout_1.log"), HasSubstr("event=mission_complete victims=2\n"));
  EXPECT_THAT(ReadFile(dir / "logs" / "physics.log"), HasSubstr("event=ready"));
  EXPECT_THAT(ReadFile(dir / "trial.yaml"), HasSubstr("name: \"mini\""));
  EXPECT_TRUE(fs::exists(dir / "truth.csv"));
  EXPECT_TRUE(fs::exists(dir / "trajectories.png"));
  // plots.html from the same logs and truth.csv, titled by the trial and its run.
  EXPECT_THAT(ReadFile(dir / "plots.html"), HasSubstr("<title>mini (run 20261121-120000-abcd)</title>"));
  EXPECT_THAT(ReadFile(dir / "plots.html"), HasSubstr("src='trajectories.png'"));

  auto result = yaml::Parse(ReadFile(dir / "result.json"), "result.json");
  ASSERT_TRUE(result) << result.error().ToString();
  EXPECT_EQ(result->Find("outcome")->scalar(), "success");
  EXPECT_EQ(result->Find("trial")->scalar(), "mini");
  EXPECT_EQ(result->Find("seed")->scalar(), "5");
  ASSERT_NE(result->Find("metrics"), nullptr);
  EXPECT_EQ(result->Find("metrics")->Find("mission_time_s")->scalar(), "20");
  // What produced it: this build, the engine's GET /version, the tree's images, no fault.
  const yaml::Node* p = result->Find("provenance");
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(p->Find("swarmbox_version")->scalar(), std::string(swarmbox::Build().version));
  EXPECT_EQ(p->Find("swarmbox_commit")->scalar(), std::string(swarmbox::Build().commit));
  EXPECT_EQ(p->Find("docker_version")->scalar(), "20.10.24+dfsg1");
  EXPECT_EQ(p->Find("docker_api_version")->scalar(), "1.41");
  EXPECT_EQ(p->Find("kernel")->scalar(), "6.1.0-fake-amd64");
  EXPECT_EQ(p->Find("fault_mechanism")->scalar(), "none");
  EXPECT_FALSE(p->Find("images")->items().empty());
  EXPECT_FALSE(p->Find("host_name")->scalar().empty());

  const std::string events = ReadFile(dir / "events.jsonl");
  EXPECT_THAT(events, HasSubstr("\"component\":\"scout_1\",\"t\":20.0,\"node\":\"scout_1\",\"event\":\"mission_complete\""));
  EXPECT_THAT(events, HasSubstr("\"event\":\"run\",\"target\":\"physics\",\"outcome\":\"success\""));
  EXPECT_THAT(events, HasSubstr("\"event\":\"shutdown\""));
}

TEST_F(RunnerTest, StartsInPriorityOrderAndStopsInReverse) {
  api_.scripts["scout_1"].lines = {"t=2 node=scout_1 event=mission_complete"};
  Run();
  // The two networks form one level (made and removed at once, in any order); the containers
  // are created ahead, in any order (a creation starts nothing), each before its start; starts
  // keep the priority order; containers are removed while the next level stops (in any order),
  // all before the networks.
  const std::string p = "mini-20261121-120000-abcd-";
  std::vector<std::string> order;
  std::vector<std::string> created;
  std::vector<std::string> removed;
  for (const std::string& c : api_.Calls()) {
    if (c.rfind("create-network", 0) == 0) {
      order.push_back("create-network");
    } else if (c.rfind("remove-network", 0) == 0) {
      order.push_back("remove-network");
    } else if (c.rfind("create", 0) == 0) {
      EXPECT_EQ(std::count(order.begin(), order.end(), "create-network"), 2) << c;
      EXPECT_EQ(std::count(order.begin(), order.end(), "start " + c.substr(7)), 0) << c;
      created.push_back(c);
    } else if (c.rfind("start", 0) == 0 || c.rfind("stop", 0) == 0) {
      order.push_back(c);
    } else if (c.rfind("remove", 0) == 0) {
      EXPECT_EQ(std::count(order.begin(), order.end(), "remove-network"), 0) << c;
      removed.push_back(c);
    }
  }
  EXPECT_THAT(order, ::testing::ElementsAre(
                         "create-network", "create-network", "start " + p + "physics",
                         "start " + p + "scout_1", "stop " + p + "scout_1", "stop " + p + "physics",
                         "remove-network", "remove-network"));
  EXPECT_THAT(created, ::testing::UnorderedElementsAre("create " + p + "scout_1", "create " + p + "physics"));
  EXPECT_THAT(removed, ::testing::UnorderedElementsAre("remove " + p + "scout_1", "remove " + p + "physics"));
}

TEST_F(RunnerTest, EndsWhenSimulatedTimeRunsOut) {
  api_.scripts["physics"].lines = {"t=0 node=physics event=ready", "t=30 node=physics event=tick",
                                   "t=60.001 node=physics event=tick"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kTimeout);
  EXPECT_EQ(run.result.verdict.reason, "simulated time ran out (1m)");
  EXPECT_DOUBLE_EQ(run.result.sim_s, 60.001);
  ExpectNothingLeft();
}

TEST_F(RunnerTest, ACrashedContainerFailsTheTrialAndItsLogsAreKept) {
  api_.scripts["scout_1"].lines = {"t=1 node=scout_1 event=takeoff", "panic: estimator diverged"};
  api_.scripts["scout_1"].exit_code = 134;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure);
  EXPECT_EQ(run.result.verdict.reason, "scout_1 exited with code 134 before the trial ended");
  EXPECT_THAT(ReadFile(fs::path(run.trial_dir) / "logs" / "scout_1.log"),
              HasSubstr("panic: estimator diverged\n"));
  bool reported = false;
  for (const ComponentReport& c : run.result.components) {
    if (c.name == "scout_1") {
      reported = true;
      EXPECT_EQ(c.exit_code, 134);
      EXPECT_EQ(c.log_lines, 2u);
    }
  }
  EXPECT_TRUE(reported);
  ExpectNothingLeft();
}

TEST_F(RunnerTest, WallClockGuardEndsAStalledTrialAsAnError) {
  spec_.timeout.wall = dsl::Duration::Seconds(30);
  RunOutcome run = Run(/*clock_step=*/0.5);
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason,
              HasSubstr("wall-clock guard: 30s passed with simulated time at 1.0s of 1m"));
  ExpectNothingLeft();
}

TEST_F(RunnerTest, AComponentThatNeverGetsReadyFailsAndIsTornDown) {
  api_.scripts["physics"].lines = {"t=0 node=physics event=loading"};
  api_.scripts["physics"].exit_code = 2;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure);
  EXPECT_EQ(run.result.verdict.reason, "physics exited with code 2 before it was ready");
  // The agent was created (Build) but never started.
  for (const std::string& c : api_.Calls()) EXPECT_NE(c, "start mini-20261121-120000-abcd-scout_1");
  ExpectNothingLeft();
}

TEST_F(RunnerTest, AFailedStartIsAnInfrastructureError) {
  api_.scripts["scout_1"].fail_start = true;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("starting mini-20261121-120000-abcd-scout_1"));
  EXPECT_EQ(ExitCodeFor(run.result.verdict), 3);
  ExpectNothingLeft();
}

TEST_F(RunnerTest, InterruptTearsDownCleanly) {
  std::atomic<bool> interrupted{false};
  options_.interrupted = &interrupted;
  std::thread ctrl_c([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
    interrupted = true;
  });
  RunOutcome run = Run();
  ctrl_c.join();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_EQ(run.result.verdict.reason, "interrupted (Ctrl-C)");
  ExpectNothingLeft();
}

TEST_F(RunnerTest, SubnetConflictRetriesWithAnotherPair) {
  api_.network_conflicts = 1;
  api_.scripts["scout_1"].lines = {"t=2 node=scout_1 event=mission_complete"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const auto tried = api_.SubnetsTried();
  ASSERT_GE(tried.size(), 3u);  // sim (refused), then sim + mesh of another pair
  EXPECT_NE(tried[0], tried[1]);
  ExpectNothingLeft();
}

TEST_F(RunnerTest, AStaleEndpointIsWaitedOutAndOneThatStaysIsNamed) {
  // Docker 20.10 refuses twice, then lets the network go: nothing is left.
  api_.stale_endpoints = 2;
  api_.scripts["scout_1"].lines = {"t=2 node=scout_1 event=mission_complete"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  ExpectNothingLeft();

  // A stale endpoint that stays: the trial's outcome stands, the problem says what to do.
  fs::remove_all(out_);
  options_.run_id = "20261121-120000-abce";
  api_.stale_endpoints = 1000;
  RunOutcome stuck = Run();
  EXPECT_EQ(stuck.result.verdict.outcome, dsl::Outcome::kSuccess) << stuck.result.verdict.ToString();
  std::string problems;
  for (const std::string& p : stuck.result.problems) problems += p + "\n";
  EXPECT_THAT(problems, HasSubstr("moby#43286")) << problems;
  EXPECT_THAT(problems, HasSubstr("swarmbox gc")) << problems;
  EXPECT_TRUE(api_.Containers().empty());
}

TEST(RemoveLabelled, GcRidesOutAStaleEndpointAndReportsOneThatStays) {
  // `swarmbox gc` removes networks with the same patience as a run's teardown.
  testing::FakeDockerApi api;
  docker::NetworkSpec net;
  net.name = "gc-net";
  net.subnet = "10.79.0.0/24";
  net.labels = {{"swarmbox.run", "gc-test"}};
  ASSERT_TRUE(api.CreateNetwork(net));
  docker::LabelSelector run;
  run.equals = {{"swarmbox.run", "gc-test"}};
  api.stale_endpoints = 2;  // released after two refusals
  auto report = docker::RemoveLabelled(api, run, /*include_images=*/false);
  ASSERT_TRUE(report) << report.error().ToString();
  EXPECT_EQ(report->networks.size(), 1u);
  EXPECT_TRUE(report->failures.empty());
  EXPECT_TRUE(api.Networks().empty());

  net.name = "gc-net-2";
  ASSERT_TRUE(api.CreateNetwork(net));
  api.stale_endpoints = 1000;  // never released
  report = docker::RemoveLabelled(api, run, /*include_images=*/false);
  ASSERT_TRUE(report) << report.error().ToString();
  ASSERT_EQ(report->failures.size(), 1u);
  EXPECT_TRUE(docker::IsStaleEndpointRefusal(Status(report->failures[0])));
  EXPECT_EQ(api.Networks().size(), 1u);
}

TEST_F(RunnerTest, ABrokenLogStreamRestartsTheTrial) {
  // The first log stream of the scout breaks after one line; the restarted trial completes.
  api_.scripts["scout_1"].lines = {"t=1 node=scout_1 event=takeoff",
                                   "t=3 node=scout_1 event=mission_complete"};
  api_.scripts["scout_1"].broken_streams = 1;
  api_.scripts["scout_1"].broken_stream_lines = 1;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.restarts, 1);
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_THAT(ReadFile(fs::path(run.trial_dir) / "events.jsonl"),
              HasSubstr("\"event\":\"restart\",\"target\":\"mini\""));
  ExpectNothingLeft();
}

TEST_F(RunnerTest, MissingTruthIsAProblemNotAnOutcome) {
  api_.scripts["physics"].files.clear();
  api_.scripts["scout_1"].lines = {"t=2 node=scout_1 event=mission_complete"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess);
  ASSERT_FALSE(run.result.problems.empty());
  EXPECT_THAT(run.result.problems[0], HasSubstr("artifact /swarmbox/out/truth.csv not collected"));
  EXPECT_FALSE(fs::exists(fs::path(run.trial_dir) / "trajectories.png"));
}

TEST_F(RunnerTest, InputFilesAreCopiedIntoTheContainers) {
  api_.scripts["scout_1"].lines = {"t=2 node=scout_1 event=mission_complete"};
  Run();
  const auto archives = api_.PutArchives();
  // The root filesystem is read-only: the files go into the container's volume at /swarmbox.
  EXPECT_EQ(api_.PutArchiveDirs().at("mini-20261121-120000-abcd-physics"), "/swarmbox");
  auto entries = docker::ReadTar(archives.at("mini-20261121-120000-abcd-physics"));
  ASSERT_TRUE(entries) << entries.error().ToString();
  std::map<std::string, std::uint32_t> modes;
  for (const auto& e : *entries) {
    std::string path = e.path;  // directories may come back as "out/"
    if (!path.empty() && path.back() == '/') path.pop_back();
    modes[path] = e.mode;
  }
  EXPECT_EQ(modes.count("trials/worlds/open_field.yaml"), 1u);
  EXPECT_EQ(modes.count("trials/airframes/x500.yaml"), 1u);
  ASSERT_EQ(modes.count("out"), 1u);
  EXPECT_EQ(modes["out"] & 07777u, 01777u);  // writable by the container's user
  auto agent = docker::ReadTar(archives.at("mini-20261121-120000-abcd-scout_1"));
  ASSERT_TRUE(agent);
  bool airframe = false;
  for (const auto& e : *agent) {
    if (e.path == "trials/airframes/x500.yaml") {
      airframe = true;
      EXPECT_THAT(e.content, HasSubstr("name: x500"));
    }
  }
  EXPECT_TRUE(airframe);
}

TEST_F(RunnerTest, TheAgentsOfALevelStartAndStopAtOnceAfterThePhysicsServerIsReady) {
  spec_.drones.clear();
  spec_.Drone("scout_1", "x500", {0, 0, 0})
      .Drone("scout_2", "x500", {3, 0, 0})
      .Drone("scout_3", "x500", {6, 0, 0});
  api_.scripts["scout_3"].lines = {"t=2 node=scout_3 event=mission_complete"};
  // Each scout's start (stop) waits inside the engine until the other two are there as well: a
  // runner going one by one would fail these calls instead.
  api_.start_together = {"scout_1", "scout_2", "scout_3"};
  api_.stop_together = {"scout_1", "scout_2", "scout_3"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  for (const std::string& problem : run.result.problems) {
    EXPECT_THAT(problem, ::testing::Not(HasSubstr("alone")));
  }
  // Levels keep their order: the physics server starts (and is ready) before any scout starts,
  // and is stopped only after every scout was removed; networks go last.
  std::vector<std::string> calls;
  for (const std::string& c : api_.Calls()) {
    if (c.rfind("start", 0) == 0 || c.rfind("stop", 0) == 0 || c.rfind("remove", 0) == 0) {
      calls.push_back(c);
    }
  }
  const std::string p = "mini-20261121-120000-abcd-";
  auto at = [&](const std::string& call) {
    return std::find(calls.begin(), calls.end(), call) - calls.begin();
  };
  ASSERT_EQ(calls.size(), 14u) << ::testing::PrintToString(calls);
  EXPECT_EQ(calls[0], "start " + p + "physics");
  for (const char* s : {"scout_1", "scout_2", "scout_3"}) {
    EXPECT_LT(at("start " + p + s), at("stop " + p + s));
    EXPECT_LT(at("stop " + p + s), at("stop " + p + "physics"));
    EXPECT_LT(at("remove " + p + s), at("remove-network " + p + "net2-mesh"));
  }
  EXPECT_LT(at("stop " + p + "physics"), at("remove " + p + "physics"));
  EXPECT_THAT(std::vector<std::string>(calls.end() - 2, calls.end()),
              ::testing::UnorderedElementsAre("remove-network " + p + "net2-mesh",
                                              "remove-network " + p + "net1-sim"));
  EXPECT_EQ(run.result.components.size(), 4u);
  for (const ComponentReport& c : run.result.components) EXPECT_EQ(c.exit_code, 0) << c.name;
  ExpectNothingLeft();
}

TEST_F(RunnerTest, LaterLevelsAreCreatedWhileTheFirstStartsButStartOnlyOnceItIsReady) {
  spec_.drones.clear();
  spec_.Drone("scout_1", "x500", {0, 0, 0}).Drone("scout_2", "x500", {3, 0, 0});
  // The scouts' creation waits inside the engine until the physics server has started: a runner
  // creating every container before the first start (or one level after another) fails these.
  api_.scripts["scout_1"].create_after_started = {"physics"};
  api_.scripts["scout_2"].create_after_started = {"physics"};
  api_.scripts["scout_2"].lines = {"t=2 node=scout_2 event=mission_complete"};
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  const std::string p = "mini-20261121-120000-abcd-";
  const std::vector<std::string> calls = api_.Calls();
  auto at = [&](const std::string& call) {
    return std::find(calls.begin(), calls.end(), call) - calls.begin();
  };
  for (const char* s : {"scout_1", "scout_2"}) {
    EXPECT_LT(at("start " + p + "physics"), at("start " + p + s)) << s;
    EXPECT_LT(at("create " + p + s), at("start " + p + s)) << s;
  }
  // Each build is traced once, when its creation has finished.
  const std::string events = ReadFile(fs::path(run.trial_dir) / "events.jsonl");
  for (const char* s : {"physics", "scout_1", "scout_2"}) {
    const std::string build = std::string("\"event\":\"build\",\"target\":\"") + s + "\",\"outcome\":\"success\"";
    const auto first = events.find(build);
    ASSERT_NE(first, std::string::npos) << s;
    EXPECT_EQ(events.find(build, first + 1), std::string::npos) << s;
  }
  ExpectNothingLeft();
}

TEST_F(RunnerTest, ContainersCreatedAheadAreRemovedWhenAnEarlierLevelFails) {
  // The scouts are created while the physics server starts; it exits before it is ready: they
  // are never started, and removed.
  spec_.drones.clear();
  spec_.Drone("scout_1", "x500", {0, 0, 0}).Drone("scout_2", "x500", {3, 0, 0});
  api_.scripts["physics"].log_after_created = {"scout_1", "scout_2"};
  api_.scripts["physics"].lines = {"t=0 node=physics event=loading"};
  api_.scripts["physics"].exit_code = 2;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure);
  EXPECT_EQ(run.result.verdict.reason, "physics exited with code 2 before it was ready");
  const std::string p = "mini-20261121-120000-abcd-";
  const std::vector<std::string> calls = api_.Calls();
  for (const char* s : {"scout_1", "scout_2"}) {
    EXPECT_EQ(std::count(calls.begin(), calls.end(), "create " + p + s), 1) << s;
    EXPECT_EQ(std::count(calls.begin(), calls.end(), "start " + p + s), 0) << s;
    EXPECT_EQ(std::count(calls.begin(), calls.end(), "remove " + p + s), 1) << s;
  }
  ExpectNothingLeft();
}

TEST_F(RunnerTest, ContainersCreatedAheadAreRemovedAfterCtrlCDuringAReadinessWait) {
  spec_.drones.clear();
  spec_.Drone("scout_1", "x500", {0, 0, 0}).Drone("scout_2", "x500", {3, 0, 0});
  api_.scripts["physics"].lines = {"t=0 node=physics event=loading"};  // never ready
  std::atomic<bool> interrupted{false};
  options_.interrupted = &interrupted;
  std::thread ctrl_c([&] {
    // Once both scouts exist (created ahead), while the runner waits for the physics server.
    for (int i = 0; i < 1000; ++i) {
      const auto created = api_.Created();
      if (created.size() == 3u) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    interrupted = true;
  });
  RunOutcome run = Run();
  ctrl_c.join();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("interrupted"));
  EXPECT_EQ(api_.Created().size(), 3u);
  const std::string p = "mini-20261121-120000-abcd-";
  const std::vector<std::string> calls = api_.Calls();
  for (const char* s : {"scout_1", "scout_2"}) {
    EXPECT_EQ(std::count(calls.begin(), calls.end(), "start " + p + s), 0) << s;
  }
  ExpectNothingLeft();
}

TEST_F(RunnerTest, AFailedCreationOfALaterLevelEndsTheRunBeforeThatLevelStarts) {
  spec_.drones.clear();
  spec_.Drone("scout_1", "x500", {0, 0, 0}).Drone("scout_2", "x500", {3, 0, 0});
  api_.scripts["scout_2"].fail_create = true;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kError);
  EXPECT_THAT(run.result.verdict.reason, HasSubstr("creating container mini-20261121-120000-abcd-scout_2"));
  EXPECT_EQ(ExitCodeFor(run.result.verdict), 3);
  const std::string p = "mini-20261121-120000-abcd-";
  const std::vector<std::string> calls = api_.Calls();
  EXPECT_EQ(std::count(calls.begin(), calls.end(), "start " + p + "scout_2"), 0);
  // The failed build is in events.jsonl with Docker's message.
  const std::string events = ReadFile(fs::path(run.trial_dir) / "events.jsonl");
  EXPECT_THAT(events, HasSubstr("\"event\":\"build\",\"target\":\"scout_2\",\"outcome\":\"error\""));
  ExpectNothingLeft();
}

TEST(RunConcurrently, RunsTheStepsAtOnceAndKeepsTheWorstVerdict) {
  // Four steps that each wait for all four: only a run with four at once gets through.
  std::mutex mu;
  std::condition_variable cv;
  int arrived = 0;
  auto step = [&](dsl::Verdict v) {
    return [&, v] {
      std::unique_lock lock(mu);
      ++arrived;
      cv.notify_all();
      const bool all = cv.wait_for(lock, std::chrono::seconds(10), [&] { return arrived == 4; });
      return all ? v : dsl::Verdict::Err("ran alone");
    };
  };
  std::vector<std::function<dsl::Verdict()>> steps = {
      step(dsl::Verdict::Success()), step(dsl::Verdict::Fail("first failure")),
      step(dsl::Verdict::Fail("second failure")), step(dsl::Verdict::Success())};
  dsl::Verdict v = RunConcurrently(steps, 4);
  EXPECT_EQ(v.ToString(), "failure: first failure");
  EXPECT_EQ(arrived, 4);
}

TEST(RunConcurrently, NeverRunsMoreThanTheLimitAndRunsEveryStep) {
  std::mutex mu;
  int running = 0;
  int peak = 0;
  std::vector<int> ran(10, 0);
  std::vector<std::function<dsl::Verdict()>> steps;
  for (int i = 0; i < 10; ++i) {
    steps.emplace_back([&, i] {
      {
        std::lock_guard lock(mu);
        peak = std::max(peak, ++running);
        ++ran[static_cast<std::size_t>(i)];
      }
      std::lock_guard lock(mu);
      --running;
      return dsl::Verdict::Success();
    });
  }
  EXPECT_TRUE(RunConcurrently(steps, 3).ok());
  EXPECT_LE(peak, 3);
  EXPECT_THAT(ran, ::testing::Each(1));
  // One thread: in order, on the calling thread.
  std::vector<std::string> order;
  std::vector<std::function<dsl::Verdict()>> in_order;
  for (const char* name : {"a", "b", "c"}) {
    in_order.emplace_back([&order, name, caller = std::this_thread::get_id()] {
      order.push_back(std::this_thread::get_id() == caller ? name : "elsewhere");
      return dsl::Verdict::Success();
    });
  }
  EXPECT_TRUE(RunConcurrently(in_order, 1).ok());
  EXPECT_THAT(order, ::testing::ElementsAre("a", "b", "c"));
}

}  // namespace
}  // namespace swarmbox::runner

namespace swarmbox::runner {
namespace {

// A 100-drone trial on an engine that takes its time per call (create 30 ms, start 50 ms, stop
// and remove 20 ms: one by one that is 12 s for 101 containers): every container is created
// ahead, the agents start at once (bounded by max_parallel), the terminal gets counts rather than
// a line per container, a drone that never joins is named in the failure, and everything goes,
// concurrently, at the end.
TEST_F(RunnerTest, AHundredDroneTrialStartsAtOnceAndNamesTheDronesThatDidNotJoin) {
  spec_.drones.clear();
  for (int i = 1; i <= 100; ++i) {
    spec_.Drone("scout_" + std::to_string(i), "x500", {4.0 * ((i - 1) % 10), 4.0 * ((i - 1) / 10), 0});
  }
  // The server's start, as it prints it (physics_server/app/joining.hpp). Its joining line comes
  // before its ready line here, so that the runner has it before any agent starts (the real server
  // prints it a second into the start; the order of the streams is not the point of this test).
  api_.scripts["physics"].lines = {
      "t=0.000 node=physics event=joining joined=98 expected=100 missing=scout_16,scout_40",
      "t=0.000 node=physics event=ready"};
  // scout_16 gives up waiting for its first sample (the agent's exit 3).
  api_.scripts["scout_16"].lines = {
      "no sensor sample on sim/scout_16/sensor within 10.0 s and no sign of the physics server (sim/status)"};
  api_.scripts["scout_16"].exit_code = 3;
  api_.latency = {{"create", std::chrono::milliseconds(30)},
                  {"start", std::chrono::milliseconds(50)},
                  {"stop", std::chrono::milliseconds(20)},
                  {"remove", std::chrono::milliseconds(20)}};
  std::ostringstream progress;
  options_.progress = &progress;
  const auto began = std::chrono::steady_clock::now();
  RunOutcome run = Run();
  const double took_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - began).count();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure);
  EXPECT_EQ(run.result.verdict.reason,
            "scout_16 exited with code 3 before the trial ended; drones that did not join: scout_16,scout_40 "
            "(joined 98/100)");
  // Calls overlapped: creations and starts up to the default bound of 32 in flight; a level's
  // stops (and the removals behind them) all at once, as they mostly wait for programs to exit.
  const std::map<std::string, int> flight = api_.MaxInFlight();
  for (const char* kind : {"create", "start", "stop", "remove"}) EXPECT_GE(flight.at(kind), 8) << kind;
  EXPECT_LE(flight.at("create"), 32);
  EXPECT_LE(flight.at("start"), 32);
  // Counts, not 101 "started" lines.
  const std::string said = progress.str();
  EXPECT_THAT(said, HasSubstr("[mini] created 1/101\n"));
  EXPECT_THAT(said, HasSubstr("[mini] created 101/101 in "));
  EXPECT_THAT(said, HasSubstr("[mini] started 101/101 in "));
  EXPECT_THAT(said, HasSubstr("[mini] stopped and removed 101 containers in "));
  EXPECT_LT(std::count(said.begin(), said.end(), '\n'), 30) << said;
  EXPECT_EQ(run.result.timing.containers, 101u);
  ASSERT_TRUE(run.result.timing.created_s && run.result.timing.started_s && run.result.timing.teardown_s);
  EXPECT_LE(*run.result.timing.created_s, *run.result.timing.started_s);
  EXPECT_FALSE(run.result.timing.joined_s);  // the server never said its start was complete
  ExpectNothingLeft();
  // The figure for the record (one by one: 101 x 120 ms = 12.1 s of engine time).
  std::printf("100 drones on a 30/50/20/20 ms engine: whole run %.2f s wall\n", took_s);
  EXPECT_LT(took_s, 12.1);
}

}  // namespace
}  // namespace swarmbox::runner

namespace swarmbox::runner {
namespace {

TEST_F(RunnerTest, TheServersCompleteStartIsSaidAndTimed) {
  api_.scripts["physics"].lines = {"t=0.000 node=physics event=ready",
                                   "t=0.000 node=physics event=joined joined=1 expected=1 lost=0 "
                                   "wait_s=1.250",
                                   "t=1.000 node=physics event=tick"};
  api_.scripts["scout_1"].lines = {"t=2 node=scout_1 event=mission_complete"};
  std::ostringstream progress;
  options_.progress = &progress;
  RunOutcome run = Run();
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_THAT(progress.str(), HasSubstr("[mini] joined 1/1 in 1.2 s\n"));
  EXPECT_TRUE(run.result.timing.joined_s);
  const std::string json = ReadFile(fs::path(run.trial_dir) / "result.json");
  EXPECT_THAT(json, HasSubstr("\"timing\":{\"containers\":"));
  ExpectNothingLeft();
}

}  // namespace
}  // namespace swarmbox::runner
