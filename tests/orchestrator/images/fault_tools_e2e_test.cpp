// The fault sidecar image end to end: tc and iptables (nft backend, with the run-time plugins ldd
// does not list) packed FROM scratch, run in the network namespace of a running non-root container
// with CapDrop ALL + CapAdd NET_ADMIN only (as uid 0: see standard_images.hpp for why).
#include <gtest/gtest.h>

#include <iostream>

#include "e2e_support.hpp"
#include "swarmbox/docker/remove_labelled.hpp"
#include "swarmbox/images/ensure_image.hpp"
#include "swarmbox/images/standard_images.hpp"

namespace swarmbox {
namespace {

struct SidecarRun {
  std::int64_t exit_code = -1;
  std::string output;
};

class FaultToolsEndToEnd : public ::testing::Test {
 protected:
  void SetUp() override {
    api_ = testing::ConnectOrFail();
    ASSERT_NE(api_, nullptr);
    run_id_ = testing::UniqueRunId("e2e-faults");
    auto spec = images::FaultToolsImage();
    ASSERT_TRUE(spec) << spec.error().ToString();
    auto image = images::EnsureImage(*api_, *spec, nullptr, nullptr);
    ASSERT_TRUE(image) << image.error().ToString();
    image_ = *image;
    std::cout << "[figures] fault tools image " << image_.tag << ": " << image_.image_size_bytes
              << " bytes, context " << image_.context_bytes << " bytes, pack " << image_.pack_s * 1e3
              << " ms" << (image_.built ? ", build " + std::to_string(image_.build_s * 1e3) + " ms" : ", cached")
              << "\n";
  }
  void TearDown() override {
    if (api_ == nullptr) return;
    docker::LabelSelector run;
    run.equals = {{std::string(docker::kLabelRun), run_id_}};
    auto left = docker::RemoveLabelled(*api_, run, false);
    EXPECT_TRUE(left) << left.error().ToString();
  }

  // Runs one command of the fault image in `target`'s network namespace and collects its output.
  SidecarRun RunSidecar(const std::string& target, std::vector<std::string> cmd, bool net_admin) {
    docker::ContainerSpec spec;
    spec.image = image_.tag;
    spec.cmd = std::move(cmd);
    spec.network_mode = "container:" + target;
    spec.cap_drop = {"ALL"};
    if (net_admin) spec.cap_add = {"NET_ADMIN"};
    spec.labels = docker::SwarmboxLabels(run_id_, "t1", "faults");
    SidecarRun run;
    auto id = api_->CreateContainer(spec);
    EXPECT_TRUE(id) << id.error().ToString();
    if (!id) return run;
    EXPECT_TRUE(api_->StartContainer(*id));
    testing::LineLog log;
    EXPECT_TRUE(api_->FollowLogs(*id, {}, log.Collector(), nullptr));
    auto code = api_->WaitContainer(*id, docker::WaitCondition::kNotRunning, nullptr);
    EXPECT_TRUE(code) << code.error().ToString();
    run.exit_code = code ? *code : -1;
    run.output = log.Dump();
    EXPECT_TRUE(api_->RemoveContainer(*id, true, true));
    return run;
  }

  std::unique_ptr<docker::DockerClient> api_;
  std::string run_id_;
  images::EnsuredImage image_;
};

TEST_F(FaultToolsEndToEnd, SidecarShapesAndFiltersTheAgentsNamespaceWithNetAdminOnly) {
  // The "agent": any long-running container on a network; here the fault image's own `tc monitor`.
  docker::NetworkSpec net;
  net.name = "sbx-" + run_id_ + "-mesh";
  net.labels = docker::SwarmboxLabels(run_id_, "t1", "mesh");
  std::string prefix;
  ASSERT_TRUE(testing::CreateFreeNetwork(*api_, net, &prefix));
  docker::ContainerSpec agent;
  agent.name = "sbx-" + run_id_ + "-agent";
  agent.image = image_.tag;
  agent.cmd = {"/usr/sbin/tc", "monitor"};
  agent.user = "1000:1000";
  agent.cap_drop = {"ALL"};
  agent.labels = docker::SwarmboxLabels(run_id_, "t1", "drone_1");
  agent.networks = {docker::EndpointSpec{net.name, prefix + "30", {}}};
  auto agent_id = api_->CreateContainer(agent);
  ASSERT_TRUE(agent_id) << agent_id.error().ToString();
  ASSERT_TRUE(api_->StartContainer(*agent_id));

  // iptables with a plugin (libxt_statistic.so), NET_ADMIN the only capability.
  auto add = RunSidecar(*agent_id,
                        {"/usr/sbin/iptables", "-A", "OUTPUT", "-m", "statistic", "--mode", "random",
                         "--probability", "0.25", "-j", "DROP"},
                        true);
  EXPECT_EQ(add.exit_code, 0) << add.output;
  auto list = RunSidecar(*agent_id, {"/usr/sbin/iptables", "-S", "OUTPUT"}, true);
  EXPECT_EQ(list.exit_code, 0) << list.output;
  EXPECT_NE(list.output.find("-m statistic --mode random --probability 0.25"), std::string::npos)
      << list.output;

  // tc on the agent's interface.
  auto shape = RunSidecar(*agent_id,
                          {"/usr/sbin/tc", "qdisc", "add", "dev", "eth0", "root", "tbf", "rate",
                           "1mbit", "burst", "32kbit", "latency", "400ms"},
                          true);
  EXPECT_EQ(shape.exit_code, 0) << shape.output;
  auto show = RunSidecar(*agent_id, {"/usr/sbin/tc", "qdisc", "show", "dev", "eth0"}, true);
  EXPECT_NE(show.output.find("qdisc tbf"), std::string::npos) << show.output;

  // Without NET_ADMIN even uid 0 can change nothing.
  auto denied = RunSidecar(*agent_id, {"/usr/sbin/tc", "qdisc", "del", "dev", "eth0", "root"}, false);
  EXPECT_NE(denied.exit_code, 0) << denied.output;
  EXPECT_NE(denied.output.find("Operation not permitted"), std::string::npos) << denied.output;
}

}  // namespace
}  // namespace swarmbox
