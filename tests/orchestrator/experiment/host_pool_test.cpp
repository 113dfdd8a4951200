// The host pool of `swarmbox experiment` (host_pool.hpp) on fake engines (the runner's
// FakeDockerApi behind PoolEngine): the hosts that connect and get their images make the pool in
// the order given, with their slots, their own engine and images; a host that does not connect, or
// whose trial images or fault sidecar image fail, is left out with the reason; every host is
// prepared at once; the build lines carry the host's name; Disconnect closes every connection.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <condition_variable>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "support/fake_docker_api.hpp"
#include "swarmbox/experiment/host_pool.hpp"

namespace swarmbox::experiment {
namespace {

using ::testing::ElementsAre;
using ::testing::Pair;
using ::testing::UnorderedElementsAre;

// A connected fake engine; counts how many are alive (closed = destroyed). The fakes are made
// before the pool (the hosts' threads only look them up).
class FakeEngine final : public PoolEngine {
 public:
  FakeEngine(testing::FakeDockerApi& api, bool answers, std::atomic<int>& alive) : api_(api), answers_(answers), alive_(alive) {
    ++alive_;
  }
  ~FakeEngine() override { --alive_; }
  docker::DockerApi& api() override { return api_; }
  Status Check() override {
    if (!answers_) return Error(ErrorCode::kUnavailable, "the tunnel to the engine is gone");
    if (auto version = api_.Ping(); !version) return version.error();
    return Ok{};
  }

 private:
  testing::FakeDockerApi& api_;
  bool answers_;
  std::atomic<int>& alive_;
};

hosts::HostSpec Spec(const std::string& text) {
  auto spec = hosts::ParseHostSpec(text);
  EXPECT_TRUE(spec) << spec.error().ToString();
  return *spec;
}

class HostPoolTest : public ::testing::Test {
 protected:
  // One fake engine per host name; `refuse` hosts do not connect.
  HostPoolSetup FakeSetup() {
    HostPoolSetup s;
    s.connect = [this](const hosts::HostSpec& spec) -> Result<std::unique_ptr<PoolEngine>> {
      if (refuse.count(spec.name()) > 0) {
        return Error(ErrorCode::kUnavailable, "ssh: connect to host " + spec.host + " port 22: No route to host");
      }
      return std::unique_ptr<PoolEngine>(std::make_unique<FakeEngine>(apis.at(spec.name()), down.count(spec.name()) == 0, alive));
    };
    s.trial_images = [this](docker::DockerApi& api, const ImageProgressFn& progress) -> Result<runner::Images> {
      const std::string host = HostOf(api);
      progress("image swarmbox/physics built");
      if (no_images.count(host) > 0) return Error(ErrorCode::kIo, "the engine refused the build context");
      return runner::Images{"swarmbox/physics:" + host, "swarmbox/agent:" + host};
    };
    s.on_left_out = [this](const std::string& host, const std::string& why) { left_out[host] = why; };
    s.on_progress = [this](const std::string& host, std::string_view line) {
      progress_lines.push_back("[" + host + "] " + std::string(line));
    };
    return s;
  }

  // Which host's fake engine `api` is.
  std::string HostOf(docker::DockerApi& api) {
    for (auto& [name, fake] : apis) {
      if (&fake == &api) return name;
    }
    ADD_FAILURE() << "an engine that no host connected";
    return "";
  }

  ExperimentPlan plan;  // no trial impairs the mesh: no fault sidecar image is needed
  std::map<std::string, testing::FakeDockerApi> apis;
  std::set<std::string> refuse, down, no_images;
  std::atomic<int> alive{0};  // engines are made and closed on the hosts' threads
  std::map<std::string, std::string> left_out;
  std::vector<std::string> progress_lines;
};

TEST_F(HostPoolTest, EveryHostThatConnectsAndGetsItsImagesJoinsThePoolInTheOrderGiven) {
  const std::vector<hosts::HostSpec> specs = {Spec("local?slots=2"), Spec("ssh://lab@lab2?slots=4"),
                                              Spec("ssh://lab@lab3")};
  // Make the engines first: the threads only read the map.
  for (const auto& s : specs) apis[s.name()];
  down.insert("lab@lab3");

  HostPool pool = PrepareHostPool(plan, specs, FakeSetup());

  ASSERT_EQ(pool.hosts().size(), 3u);
  EXPECT_TRUE(left_out.empty());
  const PoolHost& local = pool.hosts()[0];
  EXPECT_EQ(local.name, "local");
  EXPECT_EQ(local.slots, 2);
  EXPECT_EQ(local.api, &apis["local"]);
  EXPECT_EQ(local.images.physics, "swarmbox/physics:local");
  EXPECT_EQ(local.images.agent, "swarmbox/agent:local");
  EXPECT_EQ(local.faults_image, "");
  const PoolHost& lab2 = pool.hosts()[1];
  EXPECT_EQ(lab2.name, "lab@lab2");
  EXPECT_EQ(lab2.slots, 4);
  EXPECT_EQ(lab2.api, &apis["lab@lab2"]);
  EXPECT_EQ(lab2.images.physics, "swarmbox/physics:lab@lab2");
  EXPECT_EQ(pool.hosts()[2].name, "lab@lab3");
  EXPECT_EQ(pool.hosts()[2].slots, 1);
  // check asks the host's own engine.
  EXPECT_TRUE(local.check());
  Status gone = pool.hosts()[2].check();
  ASSERT_FALSE(gone);
  EXPECT_EQ(gone.error().message(), "the tunnel to the engine is gone");
  EXPECT_THAT(progress_lines, UnorderedElementsAre("[local] image swarmbox/physics built",
                                                   "[lab@lab2] image swarmbox/physics built",
                                                   "[lab@lab3] image swarmbox/physics built"));
}

TEST_F(HostPoolTest, AHostThatDoesNotConnectOrWhoseImagesFailIsLeftOutWithTheReason) {
  const std::vector<hosts::HostSpec> specs = {Spec("ssh://lab@lab1"), Spec("ssh://lab@lab2"), Spec("ssh://lab@lab3"),
                                              Spec("local")};
  for (const auto& s : specs) apis[s.name()];
  refuse.insert("lab@lab1");
  no_images.insert("lab@lab2");
  HostPoolSetup setup = FakeSetup();
  setup.faults_image = [this](docker::DockerApi& api, const ImageProgressFn&) -> Result<std::string> {
    if (HostOf(api) == "lab@lab3") return Error(ErrorCode::kNotFound, "swarmbox-netemd not found");
    return std::string("swarmbox/faults:abc");
  };

  HostPool pool = PrepareHostPool(plan, specs, setup);

  ASSERT_EQ(pool.hosts().size(), 1u);
  EXPECT_EQ(pool.hosts()[0].name, "local");
  EXPECT_EQ(pool.hosts()[0].faults_image, "swarmbox/faults:abc");
  EXPECT_THAT(left_out,
              ElementsAre(Pair("lab@lab1", "ssh: connect to host lab1 port 22: No route to host"),
                          Pair("lab@lab2", "images: the engine refused the build context"),
                          Pair("lab@lab3", "images: swarmbox-netemd not found")));
  // The connections of the hosts left out are closed; the pool's one is open.
  EXPECT_EQ(alive, 1);
}

TEST_F(HostPoolTest, NoUsableHostMakesAnEmptyPool) {
  const std::vector<hosts::HostSpec> specs = {Spec("ssh://lab@lab1")};
  refuse.insert("lab@lab1");
  HostPool pool = PrepareHostPool(plan, specs, FakeSetup());
  EXPECT_TRUE(pool.hosts().empty());
  EXPECT_EQ(left_out.size(), 1u);
  EXPECT_EQ(alive, 0);
}

TEST_F(HostPoolTest, EveryHostIsPreparedAtOnce) {
  // Each connection waits until every host is connecting: hosts prepared one after another would
  // leave the first one out after 10 s.
  const std::vector<hosts::HostSpec> specs = {Spec("local"), Spec("ssh://lab@lab2"), Spec("ssh://lab@lab3")};
  for (const auto& s : specs) apis[s.name()];
  std::mutex mu;
  std::condition_variable cv;
  std::size_t connecting = 0;
  HostPoolSetup setup = FakeSetup();
  auto connect = setup.connect;
  setup.connect = [&](const hosts::HostSpec& spec) -> Result<std::unique_ptr<PoolEngine>> {
    {
      std::unique_lock lock(mu);
      ++connecting;
      cv.notify_all();
      if (!cv.wait_for(lock, std::chrono::seconds(10), [&] { return connecting == specs.size(); })) {
        return Error(ErrorCode::kTimeout, "connected alone");
      }
    }
    return connect(spec);
  };

  HostPool pool = PrepareHostPool(plan, specs, setup);

  EXPECT_EQ(pool.hosts().size(), 3u);
  EXPECT_TRUE(left_out.empty()) << left_out.begin()->second;
}

TEST_F(HostPoolTest, WithoutProgressTheBuildsAreQuietAndDisconnectClosesEveryConnection) {
  const std::vector<hosts::HostSpec> specs = {Spec("local"), Spec("ssh://lab@lab2")};
  for (const auto& s : specs) apis[s.name()];
  HostPoolSetup setup = FakeSetup();
  setup.on_progress = nullptr;
  HostPool pool = PrepareHostPool(plan, specs, setup);
  ASSERT_EQ(pool.hosts().size(), 2u);
  EXPECT_TRUE(progress_lines.empty());
  EXPECT_EQ(alive, 2);

  pool.Disconnect();

  EXPECT_TRUE(pool.hosts().empty());
  EXPECT_EQ(alive, 0);
}

}  // namespace
}  // namespace swarmbox::experiment
