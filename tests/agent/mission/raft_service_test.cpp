// RaftRadio and RaftService over real DDS on loopback, in one process (integration):
// addressing on the shared radio topic, a two-node cluster agreeing, events with the caller's
// sim clock, and the loud stop when the storage fails.
#include "swarmbox/mission/raft_service.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/flaky_file_system.hpp"
#include "support/wait_until.hpp"
#include "swarmbox/mission/raft_radio.hpp"

namespace swarmbox::mission {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::FlakyFileSystem;
using swarmbox::testing::WaitUntil;

std::unique_ptr<bus::Participant> Mesh(int domain) {
  auto p = bus::Participant::Create({.backend = "cyclonedds", .domain_id = domain,
                                     .interface = "lo"});
  EXPECT_TRUE(p) << p.error().ToString();
  return p ? std::move(*p) : nullptr;
}

// A fresh directory under /tmp, removed with everything in it at the end of the test.
struct TempDir {
  explicit TempDir(const std::string& prefix) : path(swarmbox::testing::MakeTempDir(prefix)) {}
  ~TempDir() {
    if (!path.empty()) std::filesystem::remove_all(path);
  }
  std::string path;
};

class FixedClock final : public raft::Clock {
 public:
  double NowS() const override { return 12.5; }
};

// Thread-safe collection of the lines a service prints.
class Lines {
 public:
  LineSink Sink() {
    return [this](const std::string& l) {
      std::lock_guard<std::mutex> lk(mu_);
      lines_.push_back(l);
    };
  }
  bool Contains(const std::string& part) const {
    std::lock_guard<std::mutex> lk(mu_);
    for (const std::string& l : lines_) {
      if (l.find(part) != std::string::npos) return true;
    }
    return false;
  }
  std::string All() const {
    std::lock_guard<std::mutex> lk(mu_);
    std::string s;
    for (const std::string& l : lines_) s += l + "\n";
    return s;
  }

 private:
  mutable std::mutex mu_;
  std::vector<std::string> lines_;
};

RaftServiceConfig SoloConfig(const std::string& dir) {
  RaftServiceConfig c;
  c.driver.self = "solo";
  c.driver.members = {"solo"};
  c.driver.seed = 3;
  c.data_dir = dir;
  return c;
}

TEST(RaftRadio, DeliversOnlyPayloadsAddressedToSelfByOthers) {
  auto mesh = Mesh(180);
  ASSERT_NE(mesh, nullptr);
  std::atomic<int> got_a{0}, got_b{0}, got_c{0};
  std::mutex mu;
  std::vector<std::uint8_t> last_b;
  auto a = RaftRadio::Create(*mesh, "a", [&](std::span<const std::uint8_t>) { ++got_a; });
  auto b = RaftRadio::Create(*mesh, "b", [&](std::span<const std::uint8_t> p) {
    std::lock_guard<std::mutex> lk(mu);
    last_b.assign(p.begin(), p.end());
    ++got_b;
  });
  auto c = RaftRadio::Create(*mesh, "c", [&](std::span<const std::uint8_t>) { ++got_c; });
  ASSERT_TRUE(a && b && c);
  ASSERT_TRUE(WaitUntil([&] { return (*a)->matched_subscribers() >= 3; }, 10s));
  const std::vector<std::uint8_t> payload = {1, 2, 3, 4};
  // Best effort: resend until one arrives (loopback rarely loses, but the radio may).
  ASSERT_TRUE(WaitUntil([&] {
    (*a)->Send("b", payload);
    std::this_thread::sleep_for(20ms);
    return got_b.load() > 0;
  }, 10s));
  {
    std::lock_guard<std::mutex> lk(mu);
    EXPECT_EQ(last_b, payload);
  }
  EXPECT_EQ(got_a.load(), 0);  // own messages are not delivered
  EXPECT_EQ(got_c.load(), 0);  // another drone's are not either
  EXPECT_GE((*a)->counters().sent, 1u);
  EXPECT_EQ((*a)->counters().send_errors, 0u);
  EXPECT_GE((*b)->counters().delivered, 1u);
  EXPECT_TRUE(WaitUntil([&] { return (*c)->counters().ignored >= 1; }, 5s));
}

TEST(RaftRadio, RefusesNamesThatCannotBeAddressed) {
  auto mesh = Mesh(180);
  ASSERT_NE(mesh, nullptr);
  auto r = RaftRadio::Create(*mesh, "bad name", [](std::span<const std::uint8_t>) {});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(r.error().message().find("raft radio"), std::string::npos);
}

TEST(RaftService, TwoNodesOverTheRadioElectAndCommit) {
  auto mesh_a = Mesh(181);
  auto mesh_b = Mesh(181);
  ASSERT_TRUE(mesh_a && mesh_b);
  const TempDir tmp("swarmbox_raft_service_");
  const std::string& dir = tmp.path;
  FixedClock clock;
  Lines lines_a, lines_b;
  RaftServiceConfig ca;
  ca.driver.self = "alpha";
  ca.driver.members = {"alpha", "bravo"};
  ca.driver.seed = 11;
  ca.data_dir = dir + "/alpha";
  RaftServiceConfig cb = ca;
  cb.driver.self = "bravo";
  cb.data_dir = dir + "/bravo";
  auto a = RaftService::Start(ca, *mesh_a, clock, lines_a.Sink());
  auto b = RaftService::Start(cb, *mesh_b, clock, lines_b.Sink());
  ASSERT_TRUE(a) << a.error().ToString();
  ASSERT_TRUE(b) << b.error().ToString();
  ASSERT_TRUE(WaitUntil([&] {
    return !(*a)->leader().empty() && (*a)->leader() == (*b)->leader();
  }, 30s)) << lines_a.All() << lines_b.All();
  RaftService& leader = (*a)->is_leader() ? **a : **b;
  ASSERT_TRUE(WaitUntil([&] { return leader.Propose(raft::StartSearch{}).ok(); }, 10s));
  ASSERT_TRUE(WaitUntil([&] {
    return (*a)->mission().phase() == raft::MissionPhase::kSearch &&
           (*b)->mission().phase() == raft::MissionPhase::kSearch;
  }, 20s)) << lines_a.All() << lines_b.All();
  EXPECT_EQ((*a)->mission(), (*b)->mission());
  EXPECT_TRUE(lines_a.Contains("t=12.500 node=alpha event=leader_elected")) << lines_a.All();
  EXPECT_TRUE(lines_b.Contains("node=bravo event=mission_state state=SEARCH")) << lines_b.All();
  EXPECT_TRUE((*a)->health().ok());
  EXPECT_GE((*a)->radio_counters().delivered, 1u);
  EXPECT_EQ((*a)->protocol_errors(), 0u);
}

TEST(RaftService, StorageFailureStopsTheNodeLoudly) {
  auto mesh = Mesh(184);
  ASSERT_NE(mesh, nullptr);
  FlakyFileSystem fs;
  const TempDir tmp("swarmbox_raft_flaky_");
  RaftServiceConfig cfg = SoloConfig(tmp.path);
  cfg.file_system = &fs;
  FixedClock clock;
  Lines lines;
  auto s = RaftService::Start(cfg, *mesh, clock, lines.Sink());
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_TRUE(WaitUntil([&] { return (*s)->is_leader(); }, 10s)) << lines.All();
  EXPECT_FALSE((*s)->WaitStopped(0ms));
  fs.fail_sync = true;
  (void)(*s)->Propose(raft::StartSearch{});  // the WAL's fsync fails on this or the next Ready
  ASSERT_TRUE((*s)->WaitStopped(10s)) << lines.All();
  ASSERT_FALSE((*s)->health());
  EXPECT_NE((*s)->health().error().ToString().find("injected"), std::string::npos);
  EXPECT_TRUE(lines.Contains("event=raft_stopped")) << lines.All();
  auto again = (*s)->Propose(raft::StartSearch{});
  ASSERT_FALSE(again);
  EXPECT_NE(again.error().ToString().find("injected"), std::string::npos);
}

TEST(RaftService, UndecodablePayloadsAreCountedNotFatal) {
  auto mesh = Mesh(186);
  ASSERT_NE(mesh, nullptr);
  const TempDir tmp("swarmbox_raft_junk_");
  FixedClock clock;
  Lines lines;
  auto s = RaftService::Start(SoloConfig(tmp.path), *mesh, clock, lines.Sink());
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_TRUE(WaitUntil([&] { return (*s)->is_leader(); }, 10s)) << lines.All();
  // Another "drone" (e.g. of another cluster, or a damaged datagram) talks to us.
  auto intruder = RaftRadio::Create(*mesh, "intruder", [](std::span<const std::uint8_t>) {});
  ASSERT_TRUE(intruder);
  const std::vector<std::uint8_t> junk = {1, 0xde, 0xad, 0xbe, 0xef, 11, 1, 1, 1};
  ASSERT_TRUE(WaitUntil([&] {
    (*intruder)->Send("solo", junk);
    std::this_thread::sleep_for(20ms);
    return (*s)->protocol_errors() >= 1;
  }, 10s));
  EXPECT_TRUE((*s)->health().ok());
  EXPECT_TRUE((*s)->is_leader());
  EXPECT_TRUE((*s)->Propose(raft::StartSearch{}));
  EXPECT_TRUE(WaitUntil([&] { return (*s)->mission().phase() == raft::MissionPhase::kSearch; },
                        10s));
}

TEST(RaftService, RestartReappliesTheDurableLog) {
  auto mesh = Mesh(185);
  ASSERT_NE(mesh, nullptr);
  const TempDir tmp("swarmbox_raft_restart_");
  const RaftServiceConfig cfg = SoloConfig(tmp.path);
  FixedClock clock;
  raft::MissionState before;
  {
    Lines lines;
    auto s = RaftService::Start(cfg, *mesh, clock, lines.Sink());
    ASSERT_TRUE(s) << s.error().ToString();
    ASSERT_TRUE(WaitUntil([&] { return (*s)->is_leader(); }, 10s));
    ASSERT_TRUE((*s)->Propose(raft::StartSearch{}));
    ASSERT_TRUE((*s)->Propose(raft::ConfirmVictim{"op", 10.0, 20.0}));
    ASSERT_TRUE(WaitUntil([&] { return (*s)->mission().victims().size() == 1; }, 10s));
    before = (*s)->mission();
  }
  Lines lines;
  auto s = RaftService::Start(cfg, *mesh, clock, lines.Sink());
  ASSERT_TRUE(s) << s.error().ToString();
  ASSERT_TRUE(WaitUntil([&] {
    return (*s)->mission().applied_index() >= before.applied_index();
  }, 10s)) << lines.All();
  EXPECT_EQ((*s)->mission().victims(), before.victims());
  EXPECT_EQ((*s)->mission().phase(), raft::MissionPhase::kSearch);
  EXPECT_TRUE(lines.Contains("event=victim_confirmed id=1")) << lines.All();
}

}  // namespace
}  // namespace swarmbox::mission
