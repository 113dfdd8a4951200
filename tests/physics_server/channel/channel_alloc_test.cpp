// STYLE.md 12: the channel runs inside the physics server's step, so a warm channel must not
// allocate. Counts C++ heap allocations (global operator new, replaced in this binary only) made by
// SetPositions/Send/TakeDeliveries under a steady 50-drone 10 Hz broadcast load once the
// in-flight heaps have reached their high-water mark.
#include <gtest/gtest.h>

#include <atomic>
#include <cstdlib>
#include <new>
#include <vector>

#include "channel_fixture.hpp"
#include "swarmbox/channel/channel.hpp"

namespace {
std::atomic<long> g_allocations{0};
}  // namespace

void* operator new(std::size_t n) {
  g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace swarmbox::channel {
namespace {

TEST(ChannelAllocation, AWarmChannelDoesNotAllocate) {
  auto profile = LoadRadioProfile(testing::TrialsDir() + "/radios/wifi_5ghz_mesh.yaml");
  ASSERT_TRUE(profile.ok());
  const std::size_t n = 50;
  Channel ch(*profile, n, 1, {Box{{-10, -10, 0}, {10, 10, 30}}});
  Impairment imp;
  imp.delay_ms = 50;
  imp.jitter_ms = 10;
  imp.loss = 0.05;
  imp.duplicate = 0.01;
  ch.SetImpairment(std::nullopt, imp);
  std::vector<Vec3d> pos(n);
  std::vector<Delivery> got;
  got.reserve(n * n * 4);
  long before = 0;
  for (std::int64_t k = 0; k < 5000; ++k) {  // 20 s; counting over the last 10 s
    if (k == 2500) before = g_allocations.load();
    const std::int64_t t = k * 4'000'000;
    for (std::size_t i = 0; i < n; ++i) {
      pos[i] = {static_cast<double>(i % 10) * 40.0 - 200.0 + 0.02 * static_cast<double>(k),
                static_cast<double>(i / 10) * 40.0 - 100.0, 30.0};
    }
    ch.SetPositions(pos);
    got.clear();
    ch.TakeDeliveries(t, &got);
    for (std::size_t i = 0; i < n; ++i) {
      if ((k + static_cast<std::int64_t>(i)) % 25 == 0) ch.Send(t, testing::Broadcast(i, static_cast<std::uint64_t>(k), t, 120));
    }
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
  EXPECT_GT(ch.stats().delivered, 100000u);
}

}  // namespace
}  // namespace swarmbox::channel
