// LogFollower and LogFollowers on the fake Docker engine: lines go to the log file and the hub
// with the follower's generation, a stream's end says how it ended, a restart's follower skips
// what was delivered and makes the earlier follower's items stale. Built with ThreadSanitizer in
// the tsan stage.
#include "swarmbox/runner/log_follower.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "support/fake_clock.hpp"
#include "support/fake_docker_api.hpp"
#include "support/files.hpp"

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

class LogFollowerTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = swarmbox::testing::MakeTempDir("swarmbox-log-follower-"); }
  void TearDown() override { fs::remove_all(dir_); }

  // A started container of component `component` whose script is `script`; returns its id.
  std::string Started(const std::string& component, swarmbox::testing::ContainerScript script) {
    api_.scripts[component] = std::move(script);
    docker::ContainerSpec spec;
    spec.name = "t-" + component;
    spec.labels[std::string(docker::kLabelComponent)] = component;
    auto id = api_.CreateContainer(spec);
    EXPECT_TRUE(id) << id.error().ToString();
    EXPECT_TRUE(api_.StartContainer(*id));
    return *id;
  }

  LogFollower::Options Options(const std::string& component, const std::string& id) {
    LogFollower::Options o;
    o.component = component;
    o.container_id = id;
    o.log_path = (dir_ / (component + ".log")).string();
    o.start_wall_s = 1000;
    o.generation = 7;
    return o;
  }

  // Hub items until the first kStreamEnd (included), or what came within ~10 s.
  std::vector<HubItem> UntilStreamEnd() {
    std::vector<HubItem> items;
    for (int i = 0; i < 100; ++i) {
      for (HubItem& item : hub_.Drain(100ms)) items.push_back(std::move(item));
      if (!items.empty() && items.back().kind == HubItem::Kind::kStreamEnd) break;
    }
    return items;
  }

  static swarmbox::testing::ContainerScript Script(std::vector<std::string> lines,
                                                  std::optional<std::int64_t> exit_code) {
    swarmbox::testing::ContainerScript script;
    script.lines = std::move(lines);
    script.exit_code = exit_code;
    return script;
  }

  swarmbox::testing::FakeDockerApi api_;
  swarmbox::testing::FakeClock clock_{1000, 0.5};
  LogHub hub_;
  fs::path dir_;
};

TEST_F(LogFollowerTest, WritesEveryLineToItsFileAndTheHubThenEndsByItself) {
  const std::string id = Started("scout", Script({"one", "two", "three"}, 0));
  std::atomic<int> ends{0};
  LogFollower::Options o = Options("scout", id);
  o.on_end = [&] { ends.fetch_add(1); };
  LogFollower follower(api_, hub_, clock_, o);

  const std::vector<HubItem> items = UntilStreamEnd();
  ASSERT_EQ(items.size(), 4u);
  for (std::size_t i = 0; i < 3; ++i) {
    EXPECT_EQ(items[i].kind, HubItem::Kind::kLine);
    EXPECT_EQ(items[i].component, "scout");
    EXPECT_EQ(items[i].generation, 7u);
  }
  EXPECT_EQ(items[0].text, "one");
  EXPECT_EQ(items[2].text, "three");
  EXPECT_DOUBLE_EQ(items[0].wall_s, 0.5);  // Clock seconds since start_wall_s
  EXPECT_DOUBLE_EQ(items[1].wall_s, 1.0);
  EXPECT_EQ(items[3].kind, HubItem::Kind::kStreamEnd);
  EXPECT_EQ(items[3].text, "");  // ended by itself: no error
  EXPECT_EQ(follower.Finish(5s), 3u);
  EXPECT_TRUE(follower.ended());
  EXPECT_TRUE(follower.ended_by_itself());
  EXPECT_EQ(ends.load(), 1);
  EXPECT_EQ(swarmbox::testing::ReadWholeFile((dir_ / "scout.log").string()), "one\ntwo\nthree\n");
}

TEST_F(LogFollowerTest, SkipsTheLinesAnEarlierFollowerDelivered) {
  const std::string id = Started("scout", Script({"one", "two", "three"}, 0));
  LogFollower::Options o = Options("scout", id);
  o.skip_lines = 2;
  LogFollower follower(api_, hub_, clock_, o);
  const std::vector<HubItem> items = UntilStreamEnd();
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[0].text, "three");
  EXPECT_EQ(follower.Finish(5s), 1u);
  EXPECT_EQ(swarmbox::testing::ReadWholeFile((dir_ / "scout.log").string()), "three\n");
}

TEST_F(LogFollowerTest, ABrokenStreamEndsWithItsReasonAndNotByItself) {
  swarmbox::testing::ContainerScript script = Script({"one", "two"}, std::nullopt);
  script.broken_streams = 1;  // the first stream breaks after one line
  script.broken_stream_lines = 1;
  const std::string id = Started("scout", script);
  LogFollower follower(api_, hub_, clock_, Options("scout", id));
  const std::vector<HubItem> items = UntilStreamEnd();
  ASSERT_EQ(items.size(), 2u);
  EXPECT_EQ(items[1].kind, HubItem::Kind::kStreamEnd);
  EXPECT_NE(items[1].text.find("connection reset by peer"), std::string::npos) << items[1].text;
  EXPECT_EQ(follower.Finish(0ms), 1u);
  EXPECT_TRUE(follower.ended());
  EXPECT_FALSE(follower.ended_by_itself());
}

TEST_F(LogFollowerTest, FinishWithoutGraceCancelsARunningStream) {
  const std::string id = Started("scout", Script({"one", "two"}, std::nullopt));  // runs until stopped
  LogFollower follower(api_, hub_, clock_, Options("scout", id));
  std::vector<HubItem> items;
  for (int i = 0; i < 100 && items.size() < 2; ++i) {
    for (HubItem& item : hub_.Drain(100ms)) items.push_back(std::move(item));
  }
  ASSERT_EQ(items.size(), 2u);
  EXPECT_FALSE(follower.ended());
  EXPECT_EQ(follower.Finish(0ms), 2u);
  EXPECT_TRUE(follower.ended());
  EXPECT_FALSE(follower.ended_by_itself());
  const std::vector<HubItem> end = UntilStreamEnd();
  ASSERT_EQ(end.size(), 1u);
  EXPECT_EQ(end[0].kind, HubItem::Kind::kStreamEnd);
  EXPECT_EQ(end[0].text, "");  // cancelled is no error
}

TEST_F(LogFollowerTest, AnUnwritableLogFileEndsTheStreamWithTheReason) {
  const std::string id = Started("scout", Script({"one"}, 0));
  LogFollower::Options o = Options("scout", id);
  o.log_path = (dir_ / "no-such-folder" / "scout.log").string();
  LogFollower follower(api_, hub_, clock_, o);
  const std::vector<HubItem> items = UntilStreamEnd();
  ASSERT_EQ(items.size(), 2u);  // the line still reaches the hub
  EXPECT_EQ(items[1].text, "cannot write " + o.log_path);
  follower.Finish(5s);
}

TEST_F(LogFollowerTest, ARestartedFollowerSkipsWhatWasDeliveredAndTheOldItemsAreStale) {
  swarmbox::testing::ContainerScript script = Script({"one", "two"}, std::nullopt);
  script.restart_lines = {"three"};
  const std::string id = Started("scout", script);
  LogFollowers followers(api_, hub_, clock_, {dir_.string(), 1000, {}});
  EXPECT_EQ(followers.Start("scout", id), 0u);
  std::vector<HubItem> first;
  for (int i = 0; i < 100 && first.size() < 2; ++i) {
    for (HubItem& item : hub_.Drain(100ms)) first.push_back(std::move(item));
  }
  ASSERT_EQ(first.size(), 2u);
  EXPECT_TRUE(followers.IsCurrent(first[0]));

  ASSERT_TRUE(api_.RestartContainer(id, 1));  // Docker keeps one, two; the new run logs three
  const std::uint64_t delivered = followers.Start("scout", id, 2);
  EXPECT_EQ(delivered, 2u);
  std::vector<HubItem> second;  // lines only (the earlier follower's stream end may come too)
  for (int i = 0; i < 100 && second.empty(); ++i) {
    for (HubItem& item : hub_.Drain(100ms)) {
      if (item.kind == HubItem::Kind::kLine) second.push_back(std::move(item));
    }
  }
  ASSERT_EQ(second.size(), 1u);
  EXPECT_EQ(second[0].text, "three");
  EXPECT_FALSE(followers.IsCurrent(first[0]));  // the earlier follower's
  EXPECT_TRUE(followers.IsCurrent(second[0]));
  EXPECT_NE(second[0].generation, first[0].generation);
  EXPECT_FALSE(followers.EndedByItself("scout"));

  EXPECT_EQ(followers.Finish("scout", 0ms), 1u);
  EXPECT_TRUE(followers.IsCurrent(second[0]));  // the last follower's items stay current
  EXPECT_EQ(followers.Finish("scout", 0ms), 0u);  // none left
  EXPECT_EQ(swarmbox::testing::ReadWholeFile((dir_ / "scout.log").string()), "one\ntwo\nthree\n");
}

}  // namespace
}  // namespace swarmbox::runner
