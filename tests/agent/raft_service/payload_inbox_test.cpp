// PayloadInbox (unit): arrival order, the bound (oldest dropped and counted), and hand-over from
// several producer threads with nothing lost or duplicated.
#include "swarmbox/raft_service/payload_inbox.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cstdint>
#include <set>
#include <thread>
#include <vector>

namespace swarmbox::raft_service {
namespace {

using namespace std::chrono_literals;

raft::Bytes B(std::uint8_t a, std::uint8_t b = 0) { return {a, b}; }

TEST(PayloadInbox, DrainsInArrivalOrderAndAppends) {
  PayloadInbox inbox;
  inbox.Push(B(1));
  inbox.Push(B(2));
  inbox.Push(B(3));
  EXPECT_EQ(inbox.size(), 3u);
  std::vector<raft::Bytes> out = {B(9)};
  EXPECT_EQ(inbox.Drain(&out), 3u);
  EXPECT_EQ(out, (std::vector<raft::Bytes>{B(9), B(1), B(2), B(3)}));
  EXPECT_EQ(inbox.size(), 0u);
  EXPECT_EQ(inbox.Drain(&out), 0u);
  EXPECT_EQ(out.size(), 4u);
}

TEST(PayloadInbox, DropsTheOldestBeyondItsCapacity) {
  PayloadInbox inbox(2);
  inbox.Push(B(1));
  inbox.Push(B(2));
  inbox.Push(B(3));
  EXPECT_EQ(inbox.drops(), 1u);
  std::vector<raft::Bytes> out;
  inbox.Drain(&out);
  EXPECT_EQ(out, (std::vector<raft::Bytes>{B(2), B(3)}));
}

TEST(PayloadInbox, WaitUntilReturnsOnArrivalOrDeadline) {
  PayloadInbox inbox;
  EXPECT_FALSE(inbox.WaitUntil(std::chrono::steady_clock::now() + 10ms));
  std::thread producer([&] {
    std::this_thread::sleep_for(20ms);
    inbox.Push(B(7));
  });
  // The deadline is a hang guard: the arrival wakes the wait.
  EXPECT_TRUE(inbox.WaitUntil(std::chrono::steady_clock::now() + 30s));
  producer.join();
  EXPECT_EQ(inbox.size(), 1u);
}

TEST(PayloadInbox, ManyProducersOneConsumerLoseNothing) {
  constexpr int kThreads = 4;
  constexpr int kEach = 2000;
  constexpr std::size_t kTotal = std::size_t{kThreads} * kEach;
  PayloadInbox inbox(kTotal);
  std::vector<std::thread> producers;
  producers.reserve(kThreads);
  for (int t = 0; t < kThreads; ++t) {
    producers.emplace_back([&inbox, t] {
      for (int i = 0; i < kEach; ++i) {
        inbox.Push(B(static_cast<std::uint8_t>(t), static_cast<std::uint8_t>(i % 256)));
      }
    });
  }
  std::vector<raft::Bytes> got;
  while (got.size() < kTotal) {
    inbox.WaitUntil(std::chrono::steady_clock::now() + 100ms);
    inbox.Drain(&got);
  }
  for (std::thread& p : producers) p.join();
  inbox.Drain(&got);
  EXPECT_EQ(got.size(), kTotal);
  EXPECT_EQ(inbox.drops(), 0u);
  // Each producer's payloads arrive in its own order (i % 256 counts up per thread).
  std::vector<int> next(kThreads, 0);
  for (const raft::Bytes& b : got) {
    ASSERT_LT(b[0], kThreads);
    int& n = next[b[0]];
    ASSERT_EQ(b[1], static_cast<std::uint8_t>(n % 256));
    ++n;
  }
  for (int n : next) EXPECT_EQ(n, kEach);
}

}  // namespace
}  // namespace swarmbox::raft_service
