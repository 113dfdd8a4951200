// LiveServer against real clients on loopback: Foxglove's own client library (tests/js/ws_client.mjs
// on @foxglove/ws-protocol, run by Node) gets the history and the live stream; a raw socket gets the
// page at GET /; a client that never reads does not hold Write() up.
#include "swarmbox/record/live_server.hpp"

#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "support/child_process.hpp"
#include "support/files.hpp"
#include "support/wait_until.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::record {
namespace {

namespace fs = std::filesystem;
using namespace std::chrono_literals;

const std::string kJsDir = SWARMBOX_TESTS_JS_DIR;
const std::string kNode = SWARMBOX_NODE_EXE;

// The Node packages the test runs, or a failure that says how to get them.
::testing::AssertionResult NodeReady() {
  if (kNode.empty() || !fs::exists(kNode)) {
    return ::testing::AssertionFailure()
           << "node was not found at configure time: run `sudo bash scripts/setup.sh` (installs "
              "nodejs), then reconfigure";
  }
  if (!fs::exists(kJsDir + "/node_modules/@foxglove/ws-protocol")) {
    return ::testing::AssertionFailure() << "the JS test packages are missing: run `(cd " << kJsDir
                                         << " && npm ci)` (scripts/setup.sh does)";
  }
  return ::testing::AssertionSuccess();
}

std::string Pose(int i) {
  return R"({"timestamp":{"sec":)" + std::to_string(i) + R"(,"nsec":0},"transforms":[{"parent_frame_id":"world","child_frame_id":"scout_1","translation":{"x":)" +
         std::to_string(i) + R"(,"y":0,"z":10},"rotation":{"x":0,"y":0,"z":0,"w":1}}]})";
}

// A TCP connection to 127.0.0.1:port; -1 when it cannot connect.
int Connect(int port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<std::uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof(addr)) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

bool SendAll(int fd, const std::string& s) {
  return ::send(fd, s.data(), s.size(), MSG_NOSIGNAL) == static_cast<ssize_t>(s.size());
}

std::string ReadUntilClosed(int fd) {
  std::string all;
  char buf[8192];
  timeval tv{5, 0};
  ::setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &tv, sizeof(tv));
  for (ssize_t n; (n = ::recv(fd, buf, sizeof(buf), 0)) > 0;) all.append(buf, static_cast<std::size_t>(n));
  return all;
}

const ChannelSpec kTf{"/tf", "foxglove.FrameTransforms", R"({"type":"object"})"};
const ChannelSpec kWorld{"/world", "foxglove.SceneUpdate", R"({"type":"object"})"};
const ChannelSpec kCamera{"/drones/scout_1/camera", "foxglove.CompressedImage", R"({"type":"object"})"};

class LiveServerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = swarmbox::testing::MakeTempDir("live_server_test_");
    ASSERT_FALSE(dir_.empty());
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::unique_ptr<LiveServer> Start(LiveOptions options = {}) {
    options.port = 0;  // a free one
    auto server = LiveServer::Start(options);
    EXPECT_TRUE(server) << server.error().ToString();
    return server ? std::move(*server) : nullptr;
  }

  std::string dir_;
};

TEST_F(LiveServerTest, FoxgloveClientGetsTheHistoryThenTheLiveStreamAndOnlyTheNewestImage) {
  ASSERT_TRUE(NodeReady());
  auto server = Start({.name = "swarmbox-test"});
  ASSERT_NE(server, nullptr);
  const ChannelId world = *server->AddChannel(kWorld);
  const ChannelId tf = *server->AddChannel(kTf);
  const ChannelId camera = *server->AddChannel(kCamera);
  // Given a history written before anyone connected: the world, 100 poses, 5 camera frames.
  ASSERT_TRUE(server->Write(world, 0, R"({"timestamp":{"sec":0,"nsec":0},"deletions":[],"entities":[]})"));
  for (int i = 0; i < 100; ++i) {
    ASSERT_TRUE(server->Write(tf, static_cast<std::uint64_t>(i) * 1'000'000'000u, Pose(i)));
  }
  for (int i = 0; i < 5; ++i) {
    ASSERT_TRUE(server->Write(camera, static_cast<std::uint64_t>(i) * 1'000'000'000u,
                              R"({"timestamp":{"sec":0,"nsec":0},"frame_id":"scout_1","format":"jpeg","data":"AAA)" +
                                  std::to_string(i) + R"("})"));
  }
  // When Foxglove's client subscribes to everything...
  const std::string ready = dir_ + "/ready";
  auto child = swarmbox::testing::ChildProcess::Spawn(
      {kNode, kJsDir + "/ws_client.mjs", "ws://127.0.0.1:" + std::to_string(server->port()), "--want",
       "/tf=150", "--want", "/world=1", "--want", "/drones/scout_1/camera=3", "--ready", ready,
       "--timeout-ms", "30000"},
      dir_ + "/out.json", dir_ + "/err.txt");
  ASSERT_TRUE(child) << child.error().ToString();
  ASSERT_TRUE(swarmbox::testing::WaitUntil([&] { return fs::exists(ready) || !child->running(); }, 30s))
      << swarmbox::testing::ReadWholeFile(dir_ + "/err.txt");
  ASSERT_TRUE(fs::exists(ready)) << swarmbox::testing::ReadWholeFile(dir_ + "/err.txt");
  // ... and then 50 more poses and 2 camera frames are written live,
  for (int i = 100; i < 150; ++i) {
    ASSERT_TRUE(server->Write(tf, static_cast<std::uint64_t>(i) * 1'000'000'000u, Pose(i)));
    std::this_thread::sleep_for(2ms);
  }
  for (int i = 0; i < 2; ++i) {
    ASSERT_TRUE(server->Write(camera, 200'000'000'000u + static_cast<std::uint64_t>(i),
                              R"({"timestamp":{"sec":200,"nsec":0},"frame_id":"scout_1","format":"jpeg","data":"BBBB"})"));
  }
  const std::optional<int> code = child->Wait(40s);
  ASSERT_TRUE(code.has_value());
  const std::string err = swarmbox::testing::ReadWholeFile(dir_ + "/err.txt");
  ASSERT_EQ(*code, 0) << err;

  // Then it got the server's name, three channels as JSON with JSON Schema...
  auto doc = yaml::Parse(swarmbox::testing::ReadWholeFile(dir_ + "/out.json"), "out.json");
  ASSERT_TRUE(doc) << doc.error().ToString();
  EXPECT_EQ(*doc->Find("serverInfo")->Find("name")->AsString(), "swarmbox-test");
  const auto& channels = doc->Find("channels")->items();
  ASSERT_EQ(channels.size(), 3u);
  EXPECT_EQ(*channels[1].Find("topic")->AsString(), "/tf");
  EXPECT_EQ(*channels[1].Find("id")->AsInt(), static_cast<std::int64_t>(tf));
  EXPECT_EQ(*channels[1].Find("encoding")->AsString(), "json");
  EXPECT_EQ(*channels[1].Find("schemaName")->AsString(), "foxglove.FrameTransforms");
  EXPECT_EQ(*channels[1].Find("schemaEncoding")->AsString(), "jsonschema");
  // ... every pose in order with its log time (history first, then live),
  const yaml::Node* received = doc->Find("received");
  const auto& poses = received->Find("/tf")->items();
  ASSERT_EQ(poses.size(), 150u);
  for (std::size_t i = 0; i < poses.size(); ++i) {
    EXPECT_EQ(*poses[i].Find("log_time_ns")->AsString(), std::to_string(i * 1'000'000'000u));
    EXPECT_EQ(*poses[i].Find("data")->Find("transforms")->items()[0].Find("translation")->Find("x")->AsInt(),
              static_cast<std::int64_t>(i));
  }
  EXPECT_EQ(received->Find("/world")->items().size(), 1u);
  // ... and of the camera only the newest frame of the history, then the live ones.
  const auto& frames = received->Find("/drones/scout_1/camera")->items();
  ASSERT_EQ(frames.size(), 3u);
  EXPECT_EQ(*frames[0].Find("data")->Find("data")->AsString(), "AAA4");
  EXPECT_EQ(*frames[0].Find("log_time_ns")->AsString(), "4000000000");
  EXPECT_EQ(*frames[1].Find("data")->Find("data")->AsString(), "BBBB");
  EXPECT_EQ(server->dropped_messages(), 0u);
}

TEST_F(LiveServerTest, ChannelsAddedAfterTheClientConnectedAreAdvertisedToIt) {
  ASSERT_TRUE(NodeReady());
  auto server = Start();
  ASSERT_NE(server, nullptr);
  auto child = swarmbox::testing::ChildProcess::Spawn(
      {kNode, kJsDir + "/ws_client.mjs", "ws://127.0.0.1:" + std::to_string(server->port()), "--want",
       "/tf=3", "--timeout-ms", "30000"},
      dir_ + "/out.json", dir_ + "/err.txt");
  ASSERT_TRUE(child) << child.error().ToString();
  std::this_thread::sleep_for(500ms);  // connected with no channels (the history covers a late one)
  const ChannelId tf = *server->AddChannel(kTf);
  for (int i = 0; i < 3; ++i) ASSERT_TRUE(server->Write(tf, static_cast<std::uint64_t>(i), Pose(i)));
  const std::optional<int> code = child->Wait(40s);
  ASSERT_TRUE(code.has_value());
  EXPECT_EQ(*code, 0) << swarmbox::testing::ReadWholeFile(dir_ + "/err.txt");
}

TEST_F(LiveServerTest, ServesThePageAtTheRootAndNothingElse) {
  auto server = Start();
  ASSERT_NE(server, nullptr);
  int fd = Connect(server->port());
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(SendAll(fd, "GET / HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"));
  const std::string page = ReadUntilClosed(fd);
  ::close(fd);
  EXPECT_EQ(page.rfind("HTTP/1.1 200", 0), 0u) << page.substr(0, 300);
  EXPECT_NE(page.find("text/html"), std::string::npos);
  EXPECT_NE(page.find("foxglove.websocket.v1"), std::string::npos) << "the page speaks the protocol";
  EXPECT_NE(page.find("</html>"), std::string::npos) << "the whole page arrived";

  fd = Connect(server->port());
  ASSERT_GE(fd, 0);
  ASSERT_TRUE(SendAll(fd, "GET /etc/passwd HTTP/1.1\r\nHost: x\r\nConnection: close\r\n\r\n"));
  const std::string missing = ReadUntilClosed(fd);
  ::close(fd);
  EXPECT_EQ(missing.rfind("HTTP/1.1 404", 0), 0u) << missing.substr(0, 300);
  EXPECT_EQ(server->url(), "http://127.0.0.1:" + std::to_string(server->port()) + "/");
}

TEST_F(LiveServerTest, AClientThatNeverReadsDoesNotHoldUpWriteAndItsMessagesAreDropped) {
  auto server = Start({.history_bytes = 4u << 20, .client_queue_bytes = 1u << 20});
  ASSERT_NE(server, nullptr);
  const ChannelId tf = *server->AddChannel(kTf);
  // A WebSocket client that subscribes and then never reads a byte.
  const int fd = Connect(server->port());
  ASSERT_GE(fd, 0);
  const int small = 4096;
  ::setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &small, sizeof(small));
  ASSERT_TRUE(SendAll(fd,
                      "GET / HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                      "Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n"
                      "Sec-WebSocket-Protocol: foxglove.websocket.v1\r\n\r\n"));
  // A masked client text frame (RFC 6455 5.2): subscribe to channel tf as subscription 7.
  const std::string sub = R"({"op":"subscribe","subscriptions":[{"id":7,"channelId":)" + std::to_string(tf) + "}]}";
  std::string frame = {static_cast<char>(0x81), static_cast<char>(0x80 | sub.size())};
  const char mask[4] = {1, 2, 3, 4};
  frame.append(mask, 4);
  for (std::size_t i = 0; i < sub.size(); ++i) frame += static_cast<char>(sub[i] ^ mask[i % 4]);
  ASSERT_LT(sub.size(), 126u);
  ASSERT_TRUE(SendAll(fd, frame));
  std::this_thread::sleep_for(300ms);  // the subscription is in

  // When 64 MB of live messages are written...
  const std::string big(64u << 10, 'x');
  const std::string json = R"({"pad":")" + big + R"("})";
  const auto start = std::chrono::steady_clock::now();
  for (int i = 0; i < 1024; ++i) ASSERT_TRUE(server->Write(tf, static_cast<std::uint64_t>(i), json));
  const auto took = std::chrono::steady_clock::now() - start;
  // Then Write() never waited for the client, and what did not fit was dropped and counted.
  EXPECT_LT(took, 5s);
  EXPECT_GT(server->dropped_messages(), 900u);
  ::close(fd);
}

TEST_F(LiveServerTest, RefusesAPortInUseBadChannelsAndDuplicateTopics) {
  auto server = Start();
  ASSERT_NE(server, nullptr);
  auto second = LiveServer::Start({.address = "127.0.0.1", .port = server->port()});
  ASSERT_FALSE(second);
  EXPECT_EQ(second.error().code(), ErrorCode::kUnavailable);
  EXPECT_EQ(second.error().where(), "127.0.0.1:" + std::to_string(server->port()));

  ASSERT_TRUE(server->AddChannel(kTf));
  auto again = server->AddChannel(kTf);
  ASSERT_FALSE(again);
  EXPECT_EQ(again.error().code(), ErrorCode::kAlreadyExists);
  auto bad = server->Write(42, 0, "{}");
  ASSERT_FALSE(bad);
  EXPECT_NE(bad.error().message().find("no such channel"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::record
