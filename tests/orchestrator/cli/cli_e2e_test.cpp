// `swarmbox run` and `swarmbox gc` as a user runs them: the built `swarmbox` program as a child
// process against the real Docker engine, running trials/smoke.yaml (the real physics server and
// one real agent, packed from this build tree by swarmbox itself) at rtf 1 with a long simulated
// timeout, so the trial is still running when the test interrupts or kills swarmbox.
//
//   SIGINT  -> exit 130, result.json outcome "error" ("interrupted (Ctrl-C)"), every log collected,
//              nothing labelled with the run id left (ARCHITECTURE.md "CLI", "Labels").
//   SIGTERM -> the same clean-up, exit 143 (`--json`: the summary on stdout says so too).
//   SIGKILL -> the containers and networks stay; `swarmbox gc --run ID` removes exactly that run's,
//              `swarmbox gc` every dead run's, and leaves a live run's alone.
//
// Plain `swarmbox gc` removes whatever any run left on this engine, so these tests hold the
// ctest resource lock "docker" like every other end-to-end test.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <csignal>
#include <deque>
#include <filesystem>
#include <iostream>
#include <thread>

#include "run_lock.hpp"
#include "support/child_process.hpp"
#include "support/files.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using ::testing::StartsWith;
using swarmbox::testing::ChildProcess;
using swarmbox::testing::ReadWholeFile;
using swarmbox::testing::RunToEnd;

constexpr char kSwarmbox[] = SWARMBOX_CLI_EXE;
const std::string kSmokeTrial = std::string(SWARMBOX_SOURCE_DIR) + "/trials/smoke.yaml";
constexpr char kTrialName[] = "smoke";

struct Leftovers {
  std::size_t containers = 0;
  std::size_t networks = 0;
};

class CliE2eTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    ASSERT_TRUE(client) << "these tests need a Docker engine: " << client.error().ToString();
    api_ = std::move(*client).release();
  }
  static void TearDownTestSuite() { delete api_; }

  void SetUp() override {
    ASSERT_NE(api_, nullptr);
    dir_ = fs::temp_directory_path() /
           ("swarmbox-cli-e2e-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
            "-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }

  // Whatever the test did, nothing of its runs stays behind (the checks are in the tests).
  void TearDown() override {
    children_.clear();  // SIGKILLs and reaps a swarmbox still running
    for (const std::string& id : run_ids_) {
      docker::LabelSelector run;
      run.equals[std::string(docker::kLabelRun)] = id;
      auto removed = docker::RemoveLabelled(*api_, run, /*include_images=*/false);
      EXPECT_TRUE(removed) << removed.error().ToString();
    }
    fs::remove_all(dir_);
  }

  std::string NewRun() {
    run_ids_.push_back(runner::NewRunId());
    return run_ids_.back();
  }
  fs::path TrialDir(const std::string& run_id) const {
    return dir_ / runner::TrialDirName(kTrialName, run_id);
  }
  std::string Out(const std::string& run_id) const { return (dir_ / (run_id + ".out")).string(); }
  std::string Err(const std::string& run_id) const { return (dir_ / (run_id + ".err")).string(); }

  // `swarmbox run trials/smoke.yaml` paced at real time, far from its end (a plan that hovers
  // for 10 minutes, whatever the smoke trial itself flies).
  ChildProcess& StartRun(const std::string& run_id, std::vector<std::string> extra = {}) {
    std::vector<std::string> argv = {
        kSwarmbox, "run", kSmokeTrial, "--out", dir_.string(), "--run-id", run_id,
        "--set", "physics.rtf=1", "--set", "timeout.sim=600s", "--set", "timeout.wall=20m",
        "--set", "mission={kind: plan, plan: \"takeoff:2,hover:600,land\"}", "--set", "radio.model=netem"};
    argv.insert(argv.end(), extra.begin(), extra.end());
    auto child = ChildProcess::Spawn(argv, Out(run_id), Err(run_id));
    EXPECT_TRUE(child) << child.error().ToString();
    if (!child) std::abort();
    children_.push_back(std::move(*child));
    return children_.back();
  }

  // Until the runner has streamed the agent's `event=ready` into logs/scout_1.log: every
  // container of the trial was created and started, and the logs flow.
  ::testing::AssertionResult WaitRunning(ChildProcess& child, const std::string& run_id) {
    const fs::path log = TrialDir(run_id) / "logs" / "scout_1.log";
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::minutes(3);
    while (std::chrono::steady_clock::now() < deadline) {
      if (ReadWholeFile(log.string()).find("event=ready") != std::string::npos) {
        return ::testing::AssertionSuccess();
      }
      if (auto code = child.Wait(std::chrono::milliseconds(100))) {
        return ::testing::AssertionFailure()
               << "swarmbox run exited with " << *code << " before the trial ran:\n"
               << ReadWholeFile(Err(run_id));
      }
    }
    return ::testing::AssertionFailure() << "no event=ready from scout_1 within 3 minutes:\n"
                                         << ReadWholeFile(Err(run_id));
  }

  static Leftovers Left(const std::string& run_id) {
    docker::LabelSelector run;
    run.equals[std::string(docker::kLabelRun)] = run_id;
    Leftovers left;
    auto containers = api_->ListContainers(run, /*all=*/true);
    EXPECT_TRUE(containers) << containers.error().ToString();
    if (containers) left.containers = containers->size();
    auto networks = api_->ListNetworks(run);
    EXPECT_TRUE(networks) << networks.error().ToString();
    if (networks) left.networks = networks->size();
    return left;
  }

  testing::Finished Swarmbox(std::vector<std::string> args) {
    args.insert(args.begin(), kSwarmbox);
    auto done = RunToEnd(args, std::chrono::minutes(2), dir_.string());
    EXPECT_TRUE(done) << done.error().ToString();
    return done ? *done : testing::Finished{-1, "", ""};
  }

  static docker::DockerApi* api_;
  fs::path dir_;
  std::vector<std::string> run_ids_;
  std::deque<ChildProcess> children_;  // references stay valid as runs are added
};

docker::DockerApi* CliE2eTest::api_ = nullptr;

TEST_F(CliE2eTest, SigintEndsTheRunCleanlyWithItsLogs) {
  const std::string id = NewRun();
  ChildProcess& run = StartRun(id);
  ASSERT_TRUE(WaitRunning(run, id));
  ASSERT_EQ(Left(id).containers, 2u);  // physics and scout_1, running

  // When the user presses Ctrl-C,
  const auto sent = std::chrono::steady_clock::now();
  ASSERT_TRUE(run.Signal(SIGINT));
  const std::optional<int> code = run.Wait(std::chrono::minutes(2));  // a hang guard, not a target
  ASSERT_TRUE(code) << "swarmbox run still runs 2 minutes after SIGINT:\n" << ReadWholeFile(Err(id));
  const double exit_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - sent).count();
  std::cout << "suite=cli_e2e scenario=sigint sigint_to_exit_s=" << exit_s << "\n";
  RecordProperty("sigint_to_exit_ms", static_cast<int>(exit_s * 1000));

  // then swarmbox exits 130 (128 + SIGINT, as a shell reports Ctrl-C: not a trial's outcome),
  // having written the outcome the runner gives an interrupted trial,
  const std::string err = ReadWholeFile(Err(id));
  EXPECT_EQ(*code, 130) << err;
  const fs::path dir = TrialDir(id);
  // (scout_1's event=ready comes before the physics server counts it joined: a Ctrl-C between the
  // two adds "; drones that did not join: scout_1 (joined 0/1)" to the reason, which is right.)
  EXPECT_THAT(ReadWholeFile(Out(id)), HasSubstr(dir.string() + ": error (interrupted (Ctrl-C)"));
  auto result = yaml::Parse(ReadWholeFile((dir / "result.json").string()), "result.json");
  ASSERT_TRUE(result) << result.error().ToString();
  ASSERT_NE(result->Find("outcome"), nullptr);
  EXPECT_EQ(result->Find("outcome")->scalar(), "error");
  ASSERT_NE(result->Find("reason"), nullptr);
  EXPECT_THAT(result->Find("reason")->scalar(), StartsWith("interrupted (Ctrl-C)"));
  ASSERT_NE(result->Find("trial"), nullptr);
  EXPECT_EQ(result->Find("trial")->scalar(), kTrialName);
  // collected every log to its end (the physics server's last line is printed on SIGTERM), the
  // ground truth and the event record,
  const std::string physics_log = ReadWholeFile((dir / "logs" / "physics.log").string());
  EXPECT_THAT(physics_log, HasSubstr("event=ready"));
  EXPECT_THAT(physics_log, HasSubstr("event=stopped reason=signal"));
  EXPECT_THAT(ReadWholeFile((dir / "logs" / "scout_1.log").string()), HasSubstr("event=ready"));
  EXPECT_THAT(ReadWholeFile((dir / "truth.csv").string()), HasSubstr("t_s,drone,"));
  EXPECT_THAT(ReadWholeFile((dir / "events.jsonl").string()), HasSubstr("\"shutdown\""));
  EXPECT_TRUE(fs::exists(dir / "trial.yaml"));
  // and left nothing labelled with its run id.
  const Leftovers left = Left(id);
  EXPECT_EQ(left.containers, 0u);
  EXPECT_EQ(left.networks, 0u);
}

TEST_F(CliE2eTest, SigtermEndsTheRunCleanlyWithExit143) {
  const std::string id = NewRun();
  ChildProcess& run = StartRun(id, {"--json", "-q"});
  ASSERT_TRUE(WaitRunning(run, id));
  ASSERT_EQ(Left(id).containers, 2u);

  // When a script (or systemd, or `timeout`) sends SIGTERM,
  ASSERT_TRUE(run.Signal(SIGTERM));
  const std::optional<int> code = run.Wait(std::chrono::minutes(2));  // a hang guard
  ASSERT_TRUE(code) << "swarmbox run still runs 2 minutes after SIGTERM:\n" << ReadWholeFile(Err(id));

  // swarmbox tears the trial down as for Ctrl-C and exits 143 (128 + SIGTERM),
  EXPECT_EQ(*code, 143) << ReadWholeFile(Err(id));
  // its --json summary is the only thing on stdout and says the same,
  auto summary = yaml::Parse(ReadWholeFile(Out(id)), "stdout");
  ASSERT_TRUE(summary) << summary.error().ToString() << "\n" << ReadWholeFile(Out(id));
  ASSERT_NE(summary->Find("exit_code"), nullptr);
  EXPECT_EQ(summary->Find("exit_code")->scalar(), "143");
  EXPECT_EQ(summary->Find("outcome")->scalar(), "error");
  EXPECT_EQ(summary->Find("run_id")->scalar(), id);
  const fs::path dir = TrialDir(id);
  EXPECT_EQ(summary->Find("trial_dir")->scalar(), dir.string());
  auto result = yaml::Parse(ReadWholeFile((dir / "result.json").string()), "result.json");
  ASSERT_TRUE(result) << result.error().ToString();
  EXPECT_EQ(result->Find("outcome")->scalar(), "error");
  EXPECT_THAT(result->Find("reason")->scalar(), StartsWith("interrupted (SIGTERM)"));
  EXPECT_THAT(ReadWholeFile((dir / "logs" / "physics.log").string()), HasSubstr("event=stopped"));
  // and nothing labelled with its run id is left.
  const Leftovers left = Left(id);
  EXPECT_EQ(left.containers, 0u);
  EXPECT_EQ(left.networks, 0u);
}

TEST_F(CliE2eTest, GcRemovesWhatKilledRunsLeft) {
  // Given two runs whose swarmbox is SIGKILLed mid-trial (nothing can clean up),
  const std::string a = NewRun();
  const std::string b = NewRun();
  ChildProcess& run_a = StartRun(a);
  ChildProcess& run_b = StartRun(b);
  ASSERT_TRUE(WaitRunning(run_a, a));
  ASSERT_TRUE(WaitRunning(run_b, b));
  ASSERT_TRUE(run_a.Signal(SIGKILL));
  ASSERT_TRUE(run_b.Signal(SIGKILL));
  EXPECT_EQ(run_a.Wait(std::chrono::seconds(30)), std::optional<int>(128 + SIGKILL));
  EXPECT_EQ(run_b.Wait(std::chrono::seconds(30)), std::optional<int>(128 + SIGKILL));
  // their containers (physics, scout_1) and networks (sim, mesh) stay behind.
  for (const std::string& id : {a, b}) {
    const Leftovers left = Left(id);
    EXPECT_EQ(left.containers, 2u) << id;
    EXPECT_EQ(left.networks, 2u) << id;
  }

  // `swarmbox gc --run` of an unknown run removes nothing,
  testing::Finished none = Swarmbox({"gc", "--run", "no-such-run"});
  EXPECT_EQ(none.code, 0) << none.err;
  EXPECT_EQ(none.out, "removed 0 containers and 0 networks of run no-such-run\n");
  EXPECT_EQ(Left(a).containers, 2u);

  // `swarmbox gc --run A` removes all of A and nothing of B,
  testing::Finished gc_a = Swarmbox({"gc", "--run", a});
  EXPECT_EQ(gc_a.code, 0) << gc_a.err;
  EXPECT_EQ(gc_a.out, "removed 2 containers and 2 networks of run " + a + "\n");
  EXPECT_EQ(Left(a).containers, 0u);
  EXPECT_EQ(Left(a).networks, 0u);
  EXPECT_EQ(Left(b).containers, 2u);
  EXPECT_EQ(Left(b).networks, 2u);

  // A run still alive on this machine (its swarmbox holds the run lock; here, this test holds it
  // for a network labelled with its id)
  const std::string live = NewRun();
  auto live_lock = RunLock::Acquire(live);
  ASSERT_TRUE(live_lock) << live_lock.error().ToString();
  docker::NetworkSpec live_net;
  live_net.name = "swarmbox-cli-e2e-live-" + live;
  live_net.labels[std::string(docker::kLabelRun)] = live;
  ASSERT_TRUE(api_->CreateNetwork(live_net));

  // and `swarmbox gc` removes every dead run's leftovers (B's, and any other dead run's on this
  // engine) but not the live run's.
  // (Exit 3 is right when the engine refuses to remove some other run's network: Docker 20.10 can
  // keep a stale endpoint on a network until it restarts, "has active endpoints". Nothing of A or
  // B may be among the failures.)
  testing::Finished gc_all = Swarmbox({"gc"});
  EXPECT_TRUE(gc_all.code == 0 || (gc_all.code == 3 && gc_all.err.find("has active endpoints") != std::string::npos))
      << gc_all.code << ": " << gc_all.err;
  EXPECT_EQ(gc_all.err.find(a), std::string::npos) << gc_all.err;
  EXPECT_EQ(gc_all.err.find(b), std::string::npos) << gc_all.err;
  EXPECT_THAT(gc_all.out, HasSubstr("removed "));
  EXPECT_EQ(Left(b).containers, 0u);
  EXPECT_EQ(Left(b).networks, 0u);
  EXPECT_THAT(gc_all.out, HasSubstr("left run " + live + ": it is still running here"));
  EXPECT_EQ(Left(live).networks, 1u);
  // Named, it goes anyway.
  testing::Finished gc_live = Swarmbox({"gc", "--run", live});
  EXPECT_EQ(gc_live.code, 0) << gc_live.err;
  EXPECT_EQ(Left(live).networks, 0u);
}

}  // namespace
}  // namespace swarmbox::cli
