// Two hosts, end to end (label e2e): the local engine and a second "host" made here, a network
// namespace with its own sshd and dockerd (scripts/netns_host.sh), reached over ssh with a key
// generated for the test and a known_hosts the test writes. The experiment
// trials/experiments/hover_grid.yaml (2 factors x 2 levels x 2 repetitions, short plan-hover
// trials of the real physics server and agent) runs
//   1. over both hosts: 8 rows in results.csv, trials on both hosts, every trial's logs back,
//      nothing labelled with the run left on either engine;
//   2. again, killing the second host's dockerd (SIGKILL) while it runs a trial: its trial is
//      re-queued on the local host, the experiment still ends with 8 rows, nothing left locally.
// The namespace, its daemons and files are removed in TearDown, also when the test fails.
#include <gtest/gtest.h>
#include <signal.h>
#include <unistd.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <thread>

#include "program_images.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/experiment/experiment_runner.hpp"
#include "swarmbox/hosts/host.hpp"
#include "swarmbox/images/process_capture.hpp"
#include "swarmbox/report/trial_record.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::experiment {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

std::size_t Labelled(docker::DockerApi& api, const std::string& run_id) {
  docker::LabelSelector sel;
  sel.equals[std::string(docker::kLabelRun)] = run_id;
  auto containers = api.ListContainers(sel, /*all=*/true);
  auto networks = api.ListNetworks(sel);
  EXPECT_TRUE(containers) << containers.error().ToString();
  EXPECT_TRUE(networks) << networks.error().ToString();
  return (containers ? containers->size() : 1000) + (networks ? networks->size() : 1000);
}

class TwoHostExperiment : public ::testing::Test {
 protected:
  void SetUp() override {
    if (::geteuid() != 0) GTEST_FAIL() << "needs root: ip netns, a second dockerd";
    name_ = "sbxh" + std::to_string(::getpid() % 100000);
    state_ = "/run/" + name_;
    work_ = fs::temp_directory_path() / ("swarmbox-2host-" + std::to_string(::getpid()));
    fs::remove_all(work_);
    fs::create_directories(work_);
    auto up = images::RunCapture({std::string(SWARMBOX_SOURCE_DIR) + "/scripts/netns_host.sh", "up",
                                  name_, state_, "10.250.0"});
    ASSERT_TRUE(up) << up.error().ToString();
    up_ = true;
    ASSERT_EQ(up->exit_code, 0) << "the second host could not be made: " << up->err;
    std::istringstream lines(up->out);
    for (std::string line; std::getline(lines, line);) {
      if (auto eq = line.find('='); eq != std::string::npos) env_[line.substr(0, eq)] = line.substr(eq + 1);
    }
    for (const char* key : {"ADDR", "SSH_USER", "SSH_KEY", "KNOWN_HOSTS", "DOCKER_SOCK", "DOCKERD_PID"}) {
      ASSERT_TRUE(env_.count(key) > 0) << key << " missing in: " << up->out;
    }
  }

  void TearDown() override {
    if (up_) {
      auto down = images::RunCapture(
          {std::string(SWARMBOX_SOURCE_DIR) + "/scripts/netns_host.sh", "down", name_, state_});
      EXPECT_TRUE(down && down->exit_code == 0) << (down ? down->err : down.error().ToString());
    }
    fs::remove_all(work_);
  }

  std::string RemoteSpec() const {
    return "ssh://" + env_.at("SSH_USER") + "@" + env_.at("ADDR") + "?slots=1&socket=" +
           env_.at("DOCKER_SOCK") + "&identity=" + env_.at("SSH_KEY") +
           "&known_hosts=" + env_.at("KNOWN_HOSTS");
  }

  struct Pool {
    std::vector<std::unique_ptr<hosts::Host>> hosts;
    std::vector<PoolHost> pool;
  };

  // Connects both hosts and builds the images on each (through the tunnel for the second).
  void Connect(Pool* p) {
    auto specs = hosts::ParseHostSpecs({"local?slots=1", RemoteSpec()});
    ASSERT_TRUE(specs) << specs.error().ToString();
    for (const hosts::HostSpec& s : *specs) {
      auto h = hosts::ConnectHost(s, (work_ / "sock").string());
      ASSERT_TRUE(h) << h.error().ToString();
      cli::ProgramPaths programs{SWARMBOX_PHYSICS_BIN, SWARMBOX_AGENT_BIN};
      auto images = cli::EnsureTrialImages((*h)->api(), programs, [](std::string_view) {});
      ASSERT_TRUE(images) << s.name() << ": " << images.error().ToString();
      hosts::Host* raw = h->get();
      p->pool.push_back({raw->name(), raw->slots(), &raw->api(), [raw] { return raw->Check(); }, *images, ""});
      p->hosts.push_back(std::move(*h));
    }
  }

  ExperimentPlan Plan() {
    auto spec = LoadExperiment(std::string(SWARMBOX_SOURCE_DIR) + "/trials/experiments/hover_grid.yaml");
    EXPECT_TRUE(spec) << spec.error().ToString();
    auto plan = PlanExperiment(*spec);
    EXPECT_TRUE(plan) << plan.error().ToString();
    EXPECT_EQ(plan->trials.size(), 8u);
    return std::move(*plan);
  }

  // The rows of results.csv (header excluded), checked against the folders.
  std::vector<report::TrialRecord> CheckEightRows(const fs::path& out) {
    const std::string csv = ReadFile(out / "results.csv");
    std::size_t lines = 0;
    for (char c : csv) lines += c == '\n' ? 1 : 0;
    EXPECT_EQ(lines, 9u) << csv;  // header + 8 rows
    EXPECT_TRUE(fs::exists(out / "report.html"));
    std::vector<std::string> problems;
    auto records = report::ReadExperimentFolder(out.string(), &problems);
    EXPECT_EQ(records.size(), 8u);
    EXPECT_TRUE(problems.empty());
    for (const report::TrialRecord& r : records) {
      // Every trial's logs came back, from whichever host ran it.
      const fs::path logs = out / r.folder / "logs";
      EXPECT_GT(fs::file_size(logs / "physics.log"), 0u) << r.folder;
      EXPECT_GT(fs::file_size(logs / "scout_1.log"), 0u) << r.folder;
      EXPECT_FALSE(r.outcome.empty()) << r.folder;
    }
    return records;
  }

  std::string name_, state_;
  fs::path work_;
  bool up_ = false;
  std::map<std::string, std::string> env_;
};

TEST_F(TwoHostExperiment, EightTrialsOverTwoHostsThenSurviveLosingOne) {
  Pool p;
  ASSERT_NO_FATAL_FAILURE(Connect(&p));
  ASSERT_EQ(p.pool.size(), 2u);
  const ExperimentPlan plan = Plan();
  const std::string remote = p.pool[1].name;

  // 1. Both hosts, no failure.
  ExperimentOptions o;
  o.out_dir = (work_ / "clean").string();
  o.run_id = runner::NewRunId();
  auto summary = RunExperiment(plan, p.pool, o);
  ASSERT_TRUE(summary) << summary.error().ToString();
  EXPECT_EQ(summary->committed, 8u);
  auto records = CheckEightRows(o.out_dir);
  std::map<std::string, int> per_host;
  for (const auto& r : records) per_host[r.host] += 1;
  EXPECT_GT(per_host["local"], 0) << "no trial ran on the local host";
  EXPECT_GT(per_host[remote], 0) << "no trial ran on " << remote;
  EXPECT_EQ(Labelled(*p.pool[0].api, o.run_id), 0u);
  EXPECT_EQ(Labelled(*p.pool[1].api, o.run_id), 0u);
  for (const std::string& pr : summary->problems) ADD_FAILURE() << "problem: " << pr;

  // 2. Kill the second host's dockerd while it runs a trial of this run.
  ExperimentOptions k = o;
  k.out_dir = (work_ / "killed").string();
  k.run_id = runner::NewRunId();
  const pid_t dockerd = static_cast<pid_t>(std::stol(env_.at("DOCKERD_PID")));
  std::atomic<bool> done{false};
  std::atomic<bool> killed{false};
  auto remote_api = docker::DockerClient::Connect({.socket_path = env_.at("DOCKER_SOCK")});
  ASSERT_TRUE(remote_api) << remote_api.error().ToString();
  std::thread killer([&] {
    docker::LabelSelector sel;
    sel.equals[std::string(docker::kLabelRun)] = k.run_id;
    while (!done.load()) {
      auto running = (*remote_api)->ListContainers(sel, /*all=*/false);
      if (running && running->size() >= 2) {  // physics and the agent of a trial are up
        std::this_thread::sleep_for(std::chrono::milliseconds(500));
        ::kill(dockerd, SIGKILL);
        killed = true;
        return;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    }
  });
  auto after = RunExperiment(plan, p.pool, k);
  done = true;
  killer.join();
  ASSERT_TRUE(killed.load()) << "the second host never ran a trial of the second run";
  ASSERT_TRUE(after) << after.error().ToString();
  EXPECT_EQ(after->committed, 8u);
  auto records2 = CheckEightRows(k.out_dir);
  int requeued = 0;
  for (const auto& r : records2) {
    if (r.meta.hosts.size() >= 2 && r.meta.hosts.front() == remote) ++requeued;
    EXPECT_NE(r.outcome, "error") << r.folder << ": " << r.reason;
  }
  EXPECT_GE(requeued, 1) << "no trial was re-queued from the killed host";
  EXPECT_TRUE(fs::exists(fs::path(k.out_dir) / ".failed")) << "the lost attempt is kept";
  bool host_left = false;
  for (const std::string& pr : after->problems) {
    if (pr.find("host " + remote + " left the pool") != std::string::npos) host_left = true;
  }
  EXPECT_TRUE(host_left);
  EXPECT_EQ(Labelled(*p.pool[0].api, k.run_id), 0u);
}

}  // namespace
}  // namespace swarmbox::experiment
