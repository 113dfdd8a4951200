// Reproducible trials (issue #17, "Done when"): the same trial and seed give the same truth.csv and
// the same events.jsonl (apart from wall-clock fields) across two runs at `rtf: 0`, a run at
// `rtf: 1` and a run at `rtf: 0` with every core kept busy by other processes; a different seed
// gives a different run. Checked with `swarmbox diff` (exit 0 between every pair of same-seed
// runs, 1 against the other seed) on `trials/sar_search.yaml` and on
// `trials/faults/leader_kill.yaml` with its kill of the Raft leader (brought forward to 15 s).
//
// The trials run as a user runs them: the built `swarmbox run` as a child process against the real
// engine, with the trial's default radio model (`radio.model: channel`; the real-stack `netem`
// radio is on the wall clock and is not expected to pass). Each run is cut short by a simulated
// timeout (`timeout.sim`: 30 s for the SAR search, 25 s for the leader kill, 10 s past the kill) to
// keep the suite short; the durations are in the test's output.
#include <gtest/gtest.h>

#include <unistd.h>

#include <algorithm>
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
using swarmbox::testing::ChildProcess;
using swarmbox::testing::Finished;
using swarmbox::testing::ReadWholeFile;
using swarmbox::testing::RunToEnd;

constexpr char kSwarmbox[] = SWARMBOX_CLI_EXE;
const std::string kTrials = std::string(SWARMBOX_SOURCE_DIR) + "/trials";

// One busy loop per core (`sha256sum /dev/zero`, which never ends), killed when this goes.
class BusyCores {
 public:
  BusyCores() {
    const unsigned n = std::max(2u, std::thread::hardware_concurrency());
    for (unsigned i = 0; i < n; ++i) {
      auto child = ChildProcess::Spawn({SHA256SUM_EXE, "/dev/zero"}, "", "");
      EXPECT_TRUE(child) << child.error().ToString();
      if (child) children_.push_back(std::move(*child));
    }
  }
  ~BusyCores() {
    for (ChildProcess& c : children_) c.Stop(std::chrono::milliseconds(500));
  }
  BusyCores(const BusyCores&) = delete;
  BusyCores& operator=(const BusyCores&) = delete;
  // All still burning (none died early).
  bool all_running() {
    return std::all_of(children_.begin(), children_.end(), [](ChildProcess& c) { return c.running(); });
  }

 private:
  std::vector<ChildProcess> children_;
};

class ReproducibleE2e : public ::testing::Test {
 protected:
  void SetUp() override {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
    api_ = std::move(*client);
    dir_ = fs::temp_directory_path() / ("swarmbox-reproducible-e2e-" + std::to_string(::getpid()));
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    if (api_ != nullptr) {
      for (const std::string& id : run_ids_) {
        docker::LabelSelector run;
        run.equals[std::string(docker::kLabelRun)] = id;
        (void)docker::RemoveLabelled(*api_, run, /*include_images=*/false);
      }
    }
    fs::remove_all(dir_);
  }

  // `swarmbox run TRIAL --set k=v ...` into its own folder with its own run id; the trial must
  // reach an outcome (exit 0 success or 1 timeout/failure: a run cut by the simulated timeout
  // ends `timeout`), never an infrastructure error. Returns the trial folder.
  fs::path Run(const std::string& trial, const std::string& trial_name, const std::vector<std::string>& sets) {
    const std::string id = runner::NewRunId();
    run_ids_.push_back(id);
    std::vector<std::string> argv = {kSwarmbox, "run", trial, "--out", dir_.string(), "--run-id", id, "--quiet"};
    for (const std::string& s : sets) {
      argv.push_back("--set");
      argv.push_back(s);
    }
    const auto t0 = std::chrono::steady_clock::now();
    auto done = RunToEnd(argv, std::chrono::minutes(10), dir_.string());
    const double wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const fs::path trial_dir = dir_ / runner::TrialDirName(trial_name, id);
    std::string described;
    for (const std::string& s : sets) described += " " + s;
    std::cout << "[reproducible] " << trial_name << described << ": " << wall_s << " s wall -> "
              << trial_dir.string() << std::endl;
    EXPECT_TRUE(done) << done.error().ToString();
    if (!done) return trial_dir;
    EXPECT_TRUE(done->code == 0 || done->code == 1) << "exit " << done->code << "\n" << done->err;
    auto result = yaml::Parse(ReadWholeFile((trial_dir / "result.json").string()), "result.json");
    EXPECT_TRUE(result && result->Find("outcome") != nullptr)
        << (result ? "no outcome" : result.error().ToString());
    if (result && result->Find("outcome") != nullptr) {
      EXPECT_NE(result->Find("outcome")->scalar(), "error") << ReadWholeFile((trial_dir / "result.json").string());
    }
    return trial_dir;
  }

  // `swarmbox diff A B`: its exit code, with what it printed shown when it is not `expected`.
  void ExpectDiff(const fs::path& a, const fs::path& b, int expected, const std::string& what) {
    auto done = RunToEnd({kSwarmbox, "diff", a.string(), b.string()}, std::chrono::minutes(2), dir_.string());
    ASSERT_TRUE(done) << done.error().ToString();
    EXPECT_EQ(done->code, expected) << what << ":\n" << done->out << done->err;
    // What it printed is in the failure above when the exit code is not the expected one.
    std::cout << "[reproducible] diff " << what << ": exit " << done->code << "\n"
              << (done->code == expected ? done->out : std::string());
  }

  // The four same-seed runs (rtf 0 twice, rtf 1, rtf 0 under load) agree pairwise; the other seed
  // differs from the first.
  void ExpectReproducible(const std::string& trial, const std::string& name, const std::string& sim_timeout,
                          const std::vector<std::string>& more_sets = {}) {
    std::vector<std::string> base = {"seed=7", "timeout.sim=" + sim_timeout};
    base.insert(base.end(), more_sets.begin(), more_sets.end());
    auto with = [&](std::vector<std::string> sets, const std::string& more) {
      sets.push_back(more);
      return sets;
    };
    std::vector<std::pair<std::string, fs::path>> runs;
    runs.emplace_back("rtf 0 (1)", Run(trial, name, with(base, "physics.rtf=0")));
    runs.emplace_back("rtf 0 (2)", Run(trial, name, with(base, "physics.rtf=0")));
    runs.emplace_back("rtf 1", Run(trial, name, with(base, "physics.rtf=1")));
    {
      BusyCores busy;
      runs.emplace_back("rtf 0, cores busy", Run(trial, name, with(base, "physics.rtf=0")));
      EXPECT_TRUE(busy.all_running()) << "a busy loop ended during the run";
    }
    for (std::size_t i = 0; i < runs.size(); ++i) {
      for (std::size_t j = i + 1; j < runs.size(); ++j) {
        ExpectDiff(runs[i].second, runs[j].second, 0, name + ": " + runs[i].first + " vs " + runs[j].first);
      }
    }
    std::vector<std::string> other_sets = base;
    other_sets[0] = "seed=8";
    other_sets.push_back("physics.rtf=0");
    const fs::path other = Run(trial, name, other_sets);
    ExpectDiff(runs[0].second, other, 1, name + ": seed 7 vs seed 8");
  }

  std::unique_ptr<docker::DockerClient> api_;
  fs::path dir_;
  std::vector<std::string> run_ids_;
};

TEST_F(ReproducibleE2e, SarSearchIsTheSameAtAnySpeedAndLoad) {
  // 30 simulated seconds: take-off, the Raft election, the search plan committed and the first lanes.
  ExpectReproducible(kTrials + "/sar_search.yaml", "sar-search", "30s");
}

TEST_F(ReproducibleE2e, LeaderKillIsTheSameAtAnySpeedAndLoad) {
  // The leader is killed at 15 s of simulated time (the trial's 30 s, brought forward to keep the
  // suite short: a leader has long been elected by then); 25 s covers the kill, the election after
  // it and the leader's notice of the lost member (6 s of silence).
  ExpectReproducible(kTrials + "/faults/leader_kill.yaml", "faults-leader-kill", "25s", {"faults.kill_leader.at=15s"});
}

}  // namespace
}  // namespace swarmbox::e2e
