// RaftRadio and RaftService over real DDS on loopback, in one process (integration): addressing
// on the shared radio topic, and a two-node cluster agreeing over the radio, each passive service
// driven by the test's loop (PayloadInbox from the middleware threads, Tick on the test's clock),
// its events carrying that clock. The service's behaviour without DDS (storage failure, junk,
// restart, the tick grid, determinism) is in raft_service_sim_test.cpp.
#include "swarmbox/raft_service/raft_service.hpp"

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <functional>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "support/files.hpp"
#include "support/wait_until.hpp"
#include "swarmbox/common/logfmt.hpp"
#include "swarmbox/raft_service/payload_inbox.hpp"
#include "swarmbox/raft_service/raft_radio.hpp"

namespace swarmbox::raft_service {
namespace {

using namespace std::chrono_literals;
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

// The test loop's clock: starts at 12.5 s (events must carry the caller's clock, not the time
// since the start), advanced by the loop.
class LoopClock final : public raft::Clock {
 public:
  double NowS() const override { return static_cast<double>(t_us_) * 1e-6; }
  void Advance(std::chrono::microseconds dt) { t_us_ += dt.count(); }

 private:
  std::int64_t t_us_ = 12'500'000;
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
  std::string First(const std::string& part) const {
    std::lock_guard<std::mutex> lk(mu_);
    for (const std::string& l : lines_) {
      if (l.find(part) != std::string::npos) return l;
    }
    return "";
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

// One passive service on its radio, as a host drives it: the radio's middleware callback pushes
// into the inbox; the loop feeds the inbox to the service and ticks it.
struct RadioNode {
  PayloadInbox inbox;
  std::unique_ptr<RaftRadio> radio;      // after the inbox: destroyed before it
  std::unique_ptr<RaftService> service;  // after the radio: destroyed first
  std::vector<raft::Bytes> batch;

  void Step() {
    batch.clear();
    inbox.Drain(&batch);
    for (const raft::Bytes& b : batch) service->OnPayload(b);
    EXPECT_TRUE(service->Tick().ok());
  }
};

std::unique_ptr<RadioNode> StartNode(bus::Participant& mesh, const RaftServiceConfig& cfg,
                                     const raft::Clock& clock, LineSink sink) {
  auto n = std::make_unique<RadioNode>();
  RadioNode* raw = n.get();
  auto radio = RaftRadio::Create(mesh, cfg.driver.self, cfg.driver.members,
                                 [raw](std::span<const std::uint8_t> b) { raw->inbox.Push(b); });
  EXPECT_TRUE(radio) << radio.error().ToString();
  if (!radio) return nullptr;
  n->radio = std::move(*radio);
  auto service = RaftService::Start(cfg, *n->radio, clock, std::move(sink));
  EXPECT_TRUE(service) << service.error().ToString();
  if (!service) return nullptr;
  n->service = std::move(*service);
  return n;
}

TEST(RaftService, TwoNodesOverTheRadioElectAndCommit) {
  auto mesh_a = Mesh(181);
  auto mesh_b = Mesh(181);
  ASSERT_TRUE(mesh_a && mesh_b);
  const TempDir tmp("swarmbox_raft_service_");
  const std::string& dir = tmp.path;
  LoopClock clock;
  Lines lines_a, lines_b;
  RaftServiceConfig ca;
  ca.driver.self = "alpha";
  ca.driver.members = {"alpha", "bravo"};
  ca.driver.seed = 11;
  ca.data_dir = dir + "/alpha";
  RaftServiceConfig cb = ca;
  cb.driver.self = "bravo";
  cb.data_dir = dir + "/bravo";
  auto a = StartNode(*mesh_a, ca, clock, lines_a.Sink());
  auto b = StartNode(*mesh_b, cb, clock, lines_b.Sink());
  ASSERT_TRUE(a && b);
  // The loop: 5 ms of wall clock, 5 ms of the test's clock, one step of each node.
  auto step_until = [&](const std::function<bool()>& done, std::chrono::milliseconds timeout) {
    return WaitUntil([&] {
      clock.Advance(5ms);
      a->Step();
      b->Step();
      return done();
    }, timeout, 5ms);
  };
  ASSERT_TRUE(step_until([&] {
    return !a->service->leader().empty() && a->service->leader() == b->service->leader();
  }, 30s)) << lines_a.All() << lines_b.All();
  RaftService& leader = a->service->is_leader() ? *a->service : *b->service;
  ASSERT_TRUE(step_until([&] { return leader.Propose(raft::StartSearch{}).ok(); }, 10s));
  ASSERT_TRUE(step_until([&] {
    return a->service->mission().phase() == raft::MissionPhase::kSearch &&
           b->service->mission().phase() == raft::MissionPhase::kSearch;
  }, 20s)) << lines_a.All() << lines_b.All();
  EXPECT_EQ(a->service->mission(), b->service->mission());
  EXPECT_TRUE(lines_a.Contains("node=alpha event=leader_elected")) << lines_a.All();
  EXPECT_TRUE(lines_b.Contains("node=bravo event=mission_state state=SEARCH")) << lines_b.All();
  // `t` is the loop's clock: from 12.5 s on, never the time since the start.
  const std::string first = lines_a.First("event=leader_elected");
  const auto t = FindField(ParseLogfmt(first), "t");
  ASSERT_TRUE(t) << first;
  EXPECT_GE(std::stod(*t), 12.5) << first;
  EXPECT_LE(std::stod(*t), clock.NowS()) << first;
  EXPECT_TRUE(a->service->health().ok());
  EXPECT_GE(a->radio->counters().delivered, 1u);
  EXPECT_EQ(a->service->protocol_errors(), 0u);
  EXPECT_EQ(a->inbox.drops(), 0u);
}

}  // namespace
}  // namespace swarmbox::raft_service
