#include "swarmbox/runner/gc.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "fake_docker_api.hpp"
#include "swarmbox/runner/naming.hpp"

namespace swarmbox::runner {
namespace {

using ::testing::UnorderedElementsAre;

TEST(CollectGarbage, RemovesEverythingLabelledWithARunAndNothingElse) {
  testing::FakeDockerApi api;
  auto net = [&](const std::string& name, const std::string& subnet, docker::Labels labels) {
    docker::NetworkSpec n;
    n.name = name;
    n.subnet = subnet;
    n.labels = std::move(labels);
    return *api.CreateNetwork(n);
  };
  const std::string sim = net("old-sim", "10.200.0.0/24", RunLabels("old", "t", "sim"));
  net("other-sim", "10.200.2.0/24", RunLabels("other", "t", "sim"));
  net("foreign", "192.168.7.0/24", {{"owner", "someone"}});
  docker::ContainerSpec c;
  c.name = "old-physics";
  c.labels = RunLabels("old", "t", "physics");
  c.networks = {{sim, "10.200.0.2", {}}};
  ASSERT_TRUE(api.StartContainer(*api.CreateContainer(c)));
  c.name = "mine";
  c.labels = {{"owner", "someone"}};
  c.networks = {};
  (void)api.CreateContainer(c);

  auto one = CollectGarbage(api, "other");
  ASSERT_TRUE(one);
  EXPECT_THAT(one->networks, UnorderedElementsAre("other-sim"));
  EXPECT_TRUE(one->containers.empty());

  auto all = CollectGarbage(api);
  ASSERT_TRUE(all);
  EXPECT_THAT(all->containers, UnorderedElementsAre("old-physics"));
  EXPECT_THAT(all->networks, UnorderedElementsAre("old-sim"));
  EXPECT_TRUE(all->failures.empty());
  EXPECT_EQ(api.Containers().size(), 1u);  // "mine" is not ours
  EXPECT_EQ(api.Networks().size(), 1u);    // "foreign" neither
}

}  // namespace
}  // namespace swarmbox::runner
