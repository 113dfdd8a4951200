// The runner against the real Docker engine: trials built with the C++ DSL whose containers run
// swarmbox-e2e-node (packed into a registry-free image with swarmbox_images). Each run must end
// as scripted and leave nothing labelled with its run id behind.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "e2e_node_image.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/runner/naming.hpp"
#include "swarmbox/runner/runner.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;

using swarmbox::testing::kE2eNodeInImage;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class RunnerE2eTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    auto client = docker::DockerClient::Connect(docker::DockerClientOptions{});
    ASSERT_TRUE(client) << "these tests need a Docker engine: " << client.error().ToString();
    api_ = std::move(*client).release();
    auto image = swarmbox::testing::EnsureE2eNodeImage(*api_, SWARMBOX_E2E_NODE);
    ASSERT_TRUE(image) << image.error().ToString();
    image_ = new std::string(*image);
  }
  static void TearDownTestSuite() {
    delete api_;
    delete image_;
  }

  void SetUp() override {
    out_ = fs::temp_directory_path() /
           ("swarmbox-e2e-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    fs::remove_all(out_);
    options_.out_dir = out_.string();
    options_.run_id = NewRunId();
    options_.poll = std::chrono::milliseconds(50);
  }
  void TearDown() override {
    // Nothing labelled with this run is left: containers, networks.
    docker::LabelSelector mine;
    mine.equals[std::string(docker::kLabelRun)] = options_.run_id;
    auto containers = api_->ListContainers(mine, /*all=*/true);
    ASSERT_TRUE(containers);
    EXPECT_TRUE(containers->empty()) << containers->size() << " containers left";
    auto networks = api_->ListNetworks(mine);
    ASSERT_TRUE(networks);
    EXPECT_TRUE(networks->empty()) << networks->size() << " networks left";
    fs::remove_all(out_);
  }

  // sim + mesh networks, a "physics" node (priority 1, ready on event=ready, the clock, writes
  // truth.csv) and a "scout_1" node (priority 2) with the given arguments.
  Planner MakePlanner(std::vector<std::string> scout_args, dsl::Duration sim_timeout) {
    return [scout_args, sim_timeout](const std::string& run_id, const TrialSubnets& nets) {
      auto trial = std::make_unique<dsl::Trial>("e2e", run_id);
      auto name = [&](const char* c) { return ResourceName("e2e", run_id, c); };
      auto net = [&](const char* id, const Ipv4Net& subnet) {
        auto spec = dsl::NetworkSpec::Subnet(name(id), subnet.ToString(), subnet.Host(kGatewayHost));
        spec.labels = RunLabels(run_id, "e2e", id);
        return spec;
      };
      auto& sim = trial->Add<dsl::Network>("sim", net("sim", nets.sim));
      auto& mesh = trial->Add<dsl::Network>("mesh", net("mesh", nets.mesh));
      auto physics = dsl::ContainerSpec::Image(
          *image_, {kE2eNodeInImage, "--name", "physics", "--ready", "--truth", "/out/truth.csv"});
      physics.name = name("physics");
      physics.labels = RunLabels(run_id, "e2e", "physics");
      physics.scratch_dirs = {"/out"};
      physics.stop_timeout_s = 3;
      trial->Add<dsl::Plugin>("physics", physics, 1)
          .On(sim, nets.sim.Host(kPhysicsHost))
          .ReadyOn("event=ready", dsl::Duration::Seconds(30))
          .Collect("/out/truth.csv");
      std::vector<std::string> argv = {kE2eNodeInImage, "--name", "scout_1", "--quiet-ticks"};
      argv.insert(argv.end(), scout_args.begin(), scout_args.end());
      auto scout = dsl::ContainerSpec::Image(*image_, argv);
      scout.name = name("scout_1");
      scout.labels = RunLabels(run_id, "e2e", "scout_1");
      scout.stop_timeout_s = 3;
      trial->Add<dsl::Plugin>("scout_1", scout, 2)
          .On(sim, nets.sim.Host(kFirstDroneHost))
          .On(mesh, nets.mesh.Host(kFirstDroneHost));
      trial->EndOn("event=mission_complete", dsl::Outcome::kSuccess);
      trial->EndOn("event=collision", dsl::Outcome::kFailure, "collision");
      trial->SetTimeout(dsl::TimeoutPolicy::Sim(sim_timeout, dsl::Duration::Seconds(120), "physics"));
      return Result<std::unique_ptr<dsl::Trial>>(std::move(trial));
    };
  }

  RunOutcome Run(const Planner& planner) {
    SteadyClock clock;
    TrialInfo info;
    info.name = "e2e";
    info.resolved_yaml = "name: e2e\n";
    info.rtf = 1.0;
    auto run = RunTrial(info, planner, *api_, clock, options_);
    EXPECT_TRUE(run) << run.error().ToString();
    return run ? *run : RunOutcome{};
  }

  static docker::DockerApi* api_;
  static std::string* image_;
  fs::path out_;
  RunOptions options_;
};

docker::DockerApi* RunnerE2eTest::api_ = nullptr;
std::string* RunnerE2eTest::image_ = nullptr;

TEST_F(RunnerE2eTest, EndsOnALogPattern) {
  RunOutcome run = Run(MakePlanner({"--say", "2:event=mission_complete victims=2"},
                                   dsl::Duration::Seconds(60)));
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kSuccess) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.source, "scout_1");
  EXPECT_GE(run.result.sim_s, 1.0);
  const fs::path dir = run.trial_dir;
  EXPECT_THAT(ReadFile(dir / "logs" / "scout_1.log"), HasSubstr("event=mission_complete victims=2"));
  EXPECT_THAT(ReadFile(dir / "logs" / "physics.log"), HasSubstr("event=ready"));
  EXPECT_THAT(ReadFile(dir / "truth.csv"), HasSubstr("t_s,drone,x_m,y_m"));
  EXPECT_TRUE(fs::exists(dir / "trajectories.png"));
  EXPECT_THAT(ReadFile(dir / "result.json"), HasSubstr("\"outcome\":\"success\""));
  EXPECT_THAT(ReadFile(dir / "events.jsonl"), HasSubstr("\"event\":\"mission_complete\""));

  // What produced it (issue #16): every provenance field present and non-empty, from this engine.
  auto result = yaml::Parse(ReadFile(dir / "result.json"), "result.json");
  ASSERT_TRUE(result) << result.error().ToString();
  const yaml::Node* p = result->Find("provenance");
  ASSERT_NE(p, nullptr);
  for (const char* key : {"swarmbox_version", "swarmbox_commit", "build_type", "docker_version",
                          "docker_api_version", "kernel", "fault_mechanism", "rtf_requested",
                          "rtf_achieved", "host_name"}) {
    const yaml::Node* v = p->Find(key);
    EXPECT_TRUE(v != nullptr && !v->is_null() && !v->scalar().empty()) << key << ": " << ReadFile(dir / "result.json");
  }
  auto engine = api_->Version();
  ASSERT_TRUE(engine) << engine.error().ToString();
  EXPECT_EQ(p->Find("docker_version")->scalar(), engine->version);
  EXPECT_EQ(p->Find("kernel")->scalar(), engine->kernel_version);
  EXPECT_EQ(p->Find("fault_mechanism")->scalar(), "none");
  ASSERT_EQ(p->Find("images")->items().size(), 1u);
  EXPECT_EQ(p->Find("images")->items()[0].scalar(), *image_);
  EXPECT_GT(*yaml::ScalarAsDouble(p->Find("rtf_achieved")->scalar()), 0.0);
}

TEST_F(RunnerE2eTest, EndsOnSimulatedTimeout) {
  RunOutcome run = Run(MakePlanner({}, dsl::Duration::Seconds(3)));
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kTimeout) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.reason, "simulated time ran out (3s)");
  EXPECT_GE(run.result.sim_s, 3.0);
}

TEST_F(RunnerE2eTest, ACrashedContainerKeepsItsLogs) {
  RunOutcome run = Run(MakePlanner({"--say", "0.5:event=takeoff", "--exit", "1:3"},
                                   dsl::Duration::Seconds(60)));
  EXPECT_EQ(run.result.verdict.outcome, dsl::Outcome::kFailure) << run.result.verdict.ToString();
  EXPECT_EQ(run.result.verdict.reason, "scout_1 exited with code 3 before the trial ended");
  const std::string log = ReadFile(fs::path(run.trial_dir) / "logs" / "scout_1.log");
  EXPECT_THAT(log, HasSubstr("event=takeoff"));
  EXPECT_THAT(log, HasSubstr("crash: exiting with code 3"));
  bool reported = false;
  for (const ComponentReport& c : run.result.components) {
    if (c.name == "scout_1") {
      reported = true;
      EXPECT_EQ(c.exit_code, 3);
    }
  }
  EXPECT_TRUE(reported);
}

}  // namespace
}  // namespace swarmbox::runner
