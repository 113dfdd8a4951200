// $DOCKER_HOST=tcp://... against the real engine: this test puts its own TCP endpoint on
// 127.0.0.1 in front of the engine's unix socket (tcp_unix_forwarder.hpp; loopback only, dockerd
// is not touched) and runs the built `swarmbox` through it. The forwarder counts connections, so a
// command that silently used /var/run/docker.sock instead would fail here.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdlib>
#include <filesystem>

#include "support/child_process.hpp"
#include "swarmbox/common/yaml.hpp"
#include "swarmbox/docker/docker_client.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/runner/naming.hpp"
#include "tcp_unix_forwarder.hpp"

namespace swarmbox::cli {
namespace {

namespace fs = std::filesystem;
using ::testing::HasSubstr;
using swarmbox::testing::Finished;
using swarmbox::testing::RunToEnd;
using swarmbox::testing::TcpUnixForwarder;

class DockerHostE2eTest : public ::testing::Test {
 protected:
  void SetUp() override {
    socket_ = docker::DefaultSocketPath();
    auto client = docker::DockerClient::Connect({.socket_path = socket_});
    ASSERT_TRUE(client) << "this test needs a Docker engine: " << client.error().ToString();
    api_ = std::move(*client);
    auto fwd = TcpUnixForwarder::Start(socket_);
    ASSERT_TRUE(fwd) << fwd.error().ToString();
    forwarder_ = std::move(*fwd);
    scratch_ = fs::temp_directory_path() / ("swarmbox-docker-host-e2e-" + std::to_string(::getpid()));
    fs::create_directories(scratch_);
    run_id_ = runner::NewRunId();
  }
  void TearDown() override {
    ::unsetenv("DOCKER_HOST");
    if (api_) {
      docker::LabelSelector run;
      run.equals[std::string(docker::kLabelRun)] = run_id_;
      auto removed = docker::RemoveLabelled(*api_, run, /*include_images=*/false);
      EXPECT_TRUE(removed) << removed.error().ToString();
    }
    fs::remove_all(scratch_);
  }
  std::string TcpHost() const { return "tcp://127.0.0.1:" + std::to_string(forwarder_->port()); }
  Finished Swarmbox(const std::vector<std::string>& args) {
    std::vector<std::string> argv = {SWARMBOX_CLI_EXE};
    argv.insert(argv.end(), args.begin(), args.end());
    auto done = RunToEnd(argv, std::chrono::minutes(2), scratch_.string());
    EXPECT_TRUE(done) << done.error().ToString();
    return done ? *done : Finished{-1, "", ""};
  }
  std::size_t NetworksOfRun() {
    docker::LabelSelector run;
    run.equals[std::string(docker::kLabelRun)] = run_id_;
    auto networks = api_->ListNetworks(run);
    EXPECT_TRUE(networks) << networks.error().ToString();
    return networks ? networks->size() : 0;
  }

  std::string socket_;
  std::unique_ptr<docker::DockerClient> api_;
  std::unique_ptr<TcpUnixForwarder> forwarder_;
  fs::path scratch_;
  std::string run_id_;
};

TEST_F(DockerHostE2eTest, TheClientSpeaksTheEngineApiOverTcp) {
  docker::DockerClientOptions options;
  auto engine = docker::ParseEngineEndpoint({TcpHost(), "", "", "", ""});
  ASSERT_TRUE(engine) << engine.error().ToString();
  options.engine = *engine;
  auto tcp = docker::DockerClient::Connect(options);
  ASSERT_TRUE(tcp) << tcp.error().ToString();
  EXPECT_EQ((*tcp)->transport().endpoint(), TcpHost());
  auto over_tcp = (*tcp)->Version();
  auto over_unix = api_->Version();
  ASSERT_TRUE(over_tcp) << over_tcp.error().ToString();
  ASSERT_TRUE(over_unix);
  EXPECT_EQ(over_tcp->version, over_unix->version);
  EXPECT_EQ((*tcp)->api_version(), api_->api_version());
  EXPECT_GE(forwarder_->connections(), 2);  // /_ping and /version
}

TEST_F(DockerHostE2eTest, GcDryRunAndGcGoThroughDockerHostTcp) {
  // Given a network labelled with a run of this test (made over the unix socket),
  docker::NetworkSpec net;
  net.name = "swarmbox-docker-host-e2e-" + run_id_;
  net.labels[std::string(docker::kLabelRun)] = run_id_;
  ASSERT_TRUE(api_->CreateNetwork(net));
  ::setenv("DOCKER_HOST", TcpHost().c_str(), 1);

  // `swarmbox gc --run ID --dry-run --json` over tcp:// lists it and removes nothing,
  const int before = forwarder_->connections();
  const Finished dry = Swarmbox({"gc", "--run", run_id_, "--dry-run", "--json"});
  ASSERT_EQ(dry.code, 0) << dry.err;
  EXPECT_GT(forwarder_->connections(), before) << "swarmbox did not connect through " << TcpHost();
  auto listed = yaml::Parse(dry.out, "gc --dry-run --json");
  ASSERT_TRUE(listed) << listed.error().ToString() << "\n" << dry.out;
  EXPECT_EQ(listed->Find("dry_run")->scalar(), "true");
  ASSERT_EQ(listed->Find("runs")->items().size(), 1u);
  const yaml::Node& run = listed->Find("runs")->items()[0];
  EXPECT_EQ(run.Find("run")->scalar(), run_id_);
  ASSERT_EQ(run.Find("networks")->items().size(), 1u);
  EXPECT_EQ(run.Find("networks")->items()[0].scalar(), net.name);
  EXPECT_EQ(listed->Find("would_remove_networks")->scalar(), "1");
  EXPECT_EQ(NetworksOfRun(), 1u);

  // the same without --json prints it for a person,
  const Finished dry_text = Swarmbox({"gc", "--run", run_id_, "--dry-run"});
  EXPECT_EQ(dry_text.code, 0) << dry_text.err;
  EXPECT_THAT(dry_text.out, HasSubstr("would remove 0 containers and 1 networks of run " + run_id_));
  EXPECT_THAT(dry_text.out, HasSubstr("  network " + net.name + "  run " + run_id_));
  EXPECT_EQ(NetworksOfRun(), 1u);

  // and `swarmbox gc --run ID --json` removes it.
  const Finished gc = Swarmbox({"gc", "--run", run_id_, "--json"});
  ASSERT_EQ(gc.code, 0) << gc.err;
  auto removed = yaml::Parse(gc.out, "gc --json");
  ASSERT_TRUE(removed) << removed.error().ToString() << "\n" << gc.out;
  EXPECT_EQ(removed->Find("dry_run")->scalar(), "false");
  EXPECT_EQ(removed->Find("removed_networks")->scalar(), "1");
  EXPECT_EQ(removed->Find("exit_code")->scalar(), "0");
  EXPECT_EQ(NetworksOfRun(), 0u);
}

}  // namespace
}  // namespace swarmbox::cli
