#include "swarmbox/depth/device_latency.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace swarmbox::depth {
namespace {

constexpr std::int64_t kMs = 1'000'000;

TEST(DeviceLatency, EachFrameLeavesThirtyToFiftyMsAfterItsExposure) {
  DeviceLatency<int> device(30, 50, 7);
  std::int64_t lo = 1'000 * kMs, hi = 0;
  for (int i = 0; i < 200; ++i) {
    const std::int64_t capture = i * 200 * kMs;  // 5 Hz
    const std::int64_t release = device.Push(capture, i);
    lo = std::min(lo, release - capture);
    hi = std::max(hi, release - capture);
    EXPECT_FALSE(device.Pop(capture + 30 * kMs - 1).has_value()) << i;  // never before 30 ms
    auto out = device.Pop(capture + 50 * kMs);                            // always by 50 ms
    ASSERT_TRUE(out.has_value()) << i;
    EXPECT_EQ(*out, i);
  }
  EXPECT_GE(lo, 30 * kMs);
  EXPECT_LE(hi, 50 * kMs);
  EXPECT_LT(lo, 33 * kMs);  // the draws span the range
  EXPECT_GT(hi, 47 * kMs);
}

TEST(DeviceLatency, FramesLeaveInCaptureOrderAndTheSeedRepeats) {
  DeviceLatency<int> a(30, 50, 3), b(30, 50, 3);
  std::vector<std::int64_t> ra, rb;
  for (int i = 0; i < 20; ++i) {  // 200 Hz: frames overlap in the pipeline
    ra.push_back(a.Push(i * 5 * kMs, i));
    rb.push_back(b.Push(i * 5 * kMs, i));
  }
  EXPECT_EQ(ra, rb);
  EXPECT_TRUE(std::is_sorted(ra.begin(), ra.end()));
  std::vector<int> order;
  for (std::int64_t t = 0; t <= 200 * kMs; t += kMs) {
    while (auto v = a.Pop(t)) order.push_back(*v);
  }
  ASSERT_EQ(order.size(), 20u);
  for (int i = 0; i < 20; ++i) EXPECT_EQ(order[static_cast<std::size_t>(i)], i);
  EXPECT_EQ(a.pending(), 0u);
}

}  // namespace
}  // namespace swarmbox::depth
