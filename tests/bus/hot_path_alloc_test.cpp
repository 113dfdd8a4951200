// No per-message heap churn on the lockstep hot path once warm, counted as operator-new calls in
// the calling thread (middleware threads are not ours; C-level malloc is not counted):
//  * Cyclone DDS, end to end: Publish a SensorSample / ActuatorCommand / CameraImage and TakeFor it
//    into a reused value: zero.
//  * Fast DDS: DataWriter::write itself calls operator new (11 times per sample, measured with
//    backtraces: all inside libfastrtps), which the bus cannot avoid; what the bus adds, the
//    conversion into the writer's reused generated object and back into the caller's value, is
//    checked to be zero.
#include <gtest/gtest.h>

#include <cstdlib>
#include <new>

#include "bus_test_util.hpp"
#include "fastdds_convert.hpp"
#include "message_samples.hpp"

// The replacement operators below pair malloc with free; GCC 12 cannot see that through inlining
// (at -O1, the level of test sources, it reports -Wmismatched-new-delete).
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"

namespace {
thread_local bool g_counting = false;
thread_local long g_allocations = 0;

void* CountedAlloc(std::size_t n) {
  if (g_counting) ++g_allocations;
  void* p = std::malloc(n == 0 ? 1 : n);
  if (p == nullptr) throw std::bad_alloc();
  return p;
}
}  // namespace

void* operator new(std::size_t n) { return CountedAlloc(n); }
void* operator new[](std::size_t n) { return CountedAlloc(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }

namespace swarmbox::bus {
namespace {

class BusHotPath : public ::testing::TestWithParam<std::string> {
 protected:
  // Publishes `value` and takes it back `rounds` times; returns operator-new calls in this thread
  // during the last `rounds - kWarm` rounds.
  template <BusMessage T>
  long AllocationsPerSteadyState(int domain, const std::string& topic, T value) {
    auto pub_p = testing::MakeParticipant(GetParam(), domain);
    auto sub_p = testing::MakeParticipant(GetParam(), domain);
    if (!pub_p || !sub_p) return -1;
    auto sub = sub_p->CreateSubscriber<T>(topic, Qos::kLockstep);
    auto pub = pub_p->CreatePublisher<T>(topic, Qos::kLockstep);
    if (!sub || !pub) return -1;
    EXPECT_TRUE(testing::RoundTrip<T>(*pub_p, *sub_p, topic + "_warm", Qos::kLockstep, value));
    if (!(*pub)->WaitForSubscribers(1, testing::kMatchTimeout)) return -1;
    if (!(*sub)->WaitForPublishers(1, testing::kMatchTimeout)) return -1;
    T out;
    constexpr int kWarm = 20;
    constexpr int kRounds = 220;
    long allocations = 0;
    for (int i = 0; i < kRounds; ++i) {
      g_allocations = 0;
      g_counting = i >= kWarm;
      const bool published = static_cast<bool>((*pub)->Publish(value));
      const bool taken = (*sub)->TakeFor(out, std::chrono::seconds(2));
      g_counting = false;
      allocations += g_allocations;
      if (!published || !taken) {
        ADD_FAILURE() << "round " << i << ": published=" << published << " taken=" << taken;
        return -1;
      }
    }
    EXPECT_EQ(out, value);
    return allocations;
  }
  int Domain(int slot) const { return 144 + slot; }
};

TEST_P(BusHotPath, SensorSampleRoundTripDoesNotAllocateOnceWarm) {
  EXPECT_EQ(AllocationsPerSteadyState(Domain(0), SensorTopic("drone_1"), testing::FullSensorSample(3)), 0);
}

TEST_P(BusHotPath, ActuatorCommandRoundTripDoesNotAllocateOnceWarm) {
  EXPECT_EQ(AllocationsPerSteadyState(Domain(1), std::string(kActuatorTopic), testing::FullActuatorCommand(3)), 0);
}

TEST_P(BusHotPath, CameraImageRoundTripDoesNotAllocateOnceWarm) {
  EXPECT_EQ(AllocationsPerSteadyState(Domain(2), CameraTopic("drone_1"), testing::FullCameraImage(3, 320, 240)), 0);
}

template <typename Cpp, typename Gen>
long FastddsConversionAllocations(const Cpp& value) {
  Gen gen;
  Cpp back;
  fastdds_detail::Conv(value, gen);  // warm: buffers reach their size
  fastdds_detail::Conv(gen, back);
  g_allocations = 0;
  g_counting = true;
  for (int i = 0; i < 100; ++i) {
    fastdds_detail::Conv(value, gen);
    fastdds_detail::Conv(gen, back);
  }
  g_counting = false;
  EXPECT_EQ(back, value);
  return g_allocations;
}

TEST(BusHotPathFastdds, ConversionDoesNotAllocateOnceWarm) {
  EXPECT_EQ((FastddsConversionAllocations<SensorSample, ::swarmbox::msg::SensorSample>(
                testing::FullSensorSample(3))),
            0);
  EXPECT_EQ((FastddsConversionAllocations<ActuatorCommand, ::swarmbox::msg::ActuatorCommand>(
                testing::FullActuatorCommand(3))),
            0);
  EXPECT_EQ((FastddsConversionAllocations<CameraImage, ::swarmbox::msg::CameraImage>(
                testing::FullCameraImage(3, 320, 240))),
            0);
  EXPECT_EQ((FastddsConversionAllocations<Event, ::swarmbox::msg::Event>(testing::FullEvent(3))), 0);
}

INSTANTIATE_TEST_SUITE_P(Backends, BusHotPath, ::testing::Values("cyclonedds"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace swarmbox::bus
