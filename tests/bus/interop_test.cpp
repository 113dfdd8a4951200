// Cross-vendor interoperability on loopback: a Cyclone DDS publisher reaches a Fast DDS
// subscriber and a Fast DDS publisher reaches a Cyclone DDS subscriber, for every lockstep type
// (sim domain) and every radio/state type (mesh domain), with fully populated values. Both
// participants are bound to `lo` the way the agents bind theirs (Cyclone: per-domain XML config;
// Fast DDS: UDPv4 whitelist, builtin transports off), so this also shows the binding keeps
// discovery working across vendors.
#include <gtest/gtest.h>

#include "bus_test_util.hpp"
#include "message_samples.hpp"

namespace swarmbox::bus {
namespace {

using testing::Full;
using testing::MakeParticipant;
using testing::RoundTrip;

struct Direction {
  std::string from;
  std::string to;
  int domain_base;  // 170 for cyclone -> fastdds, 180 for fastdds -> cyclone
};

class BusInterop : public ::testing::TestWithParam<Direction> {
 protected:
  template <BusMessage T>
  void Check(int slot, const std::string& topic, Qos qos) {
    const int domain = GetParam().domain_base + slot;
    auto pub = MakeParticipant(GetParam().from, domain);
    auto sub = MakeParticipant(GetParam().to, domain);
    ASSERT_TRUE(pub && sub);
    EXPECT_TRUE(RoundTrip<T>(*pub, *sub, topic, qos, Full<T>(11)))
        << GetParam().from << " -> " << GetParam().to;
  }
};

// Lockstep types (sim domain, reliable).
TEST_P(BusInterop, ClockTickCrossesVendors) { Check<ClockTick>(0, std::string(kClockTopic), Qos::kLockstep); }
TEST_P(BusInterop, SensorSampleCrossesVendors) { Check<SensorSample>(1, SensorTopic("scout_1"), Qos::kLockstep); }
TEST_P(BusInterop, ActuatorCommandCrossesVendors) { Check<ActuatorCommand>(2, std::string(kActuatorTopic), Qos::kLockstep); }
TEST_P(BusInterop, CameraImageCrossesVendors) { Check<CameraImage>(3, CameraTopic("scout_1"), Qos::kLockstep); }
TEST_P(BusInterop, WorldCommandCrossesVendors) { Check<WorldCommand>(4, std::string(kWorldCommandTopic), Qos::kLockstep); }
// Radio and state types (mesh domain).
TEST_P(BusInterop, DroneStateCrossesVendors) { Check<DroneState>(5, std::string(kDroneStateTopic), Qos::kState); }
TEST_P(BusInterop, RaftMessageCrossesVendors) { Check<RaftMessage>(6, std::string(kRaftTopic), Qos::kRadio); }
TEST_P(BusInterop, DetectionCrossesVendors) { Check<Detection>(7, std::string(kDetectionTopic), Qos::kRadio); }
TEST_P(BusInterop, RadioPingCrossesVendors) { Check<RadioPing>(8, std::string(kRadioPingTopic), Qos::kRadio); }
TEST_P(BusInterop, EventCrossesVendors) { Check<Event>(9, std::string(kEventTopic), Qos::kRadio); }
// The brain's types share slots (domains) with others, on topics of their own.
TEST_P(BusInterop, BrainMessageCrossesVendors) { Check<BrainMessage>(8, std::string(kBrainMessageTopic), Qos::kRadio); }
TEST_P(BusInterop, BrainInputCrossesVendors) { Check<BrainInput>(1, OffboardInputTopic("scout_1"), Qos::kLockstep); }
TEST_P(BusInterop, BrainOutputCrossesVendors) { Check<BrainOutput>(2, OffboardOutputTopic("scout_1"), Qos::kLockstep); }
TEST_P(BusInterop, TelemetryCrossesVendors) { Check<Telemetry>(5, std::string(kTelemetryTopic), Qos::kState); }
TEST_P(BusInterop, DepthSummaryCrossesVendors) { Check<DepthSummary>(6, std::string(kDepthTopic), Qos::kState); }

// A camera-sized image is fragmented by one vendor and reassembled by the other.
TEST_P(BusInterop, CameraSizedImageCrossesVendors) {
  auto pub = MakeParticipant(GetParam().from, GetParam().domain_base + 3);
  auto sub = MakeParticipant(GetParam().to, GetParam().domain_base + 3);
  ASSERT_TRUE(pub && sub);
  EXPECT_TRUE(RoundTrip<CameraImage>(*pub, *sub, "sim/scout_1/camera_large", Qos::kLockstep,
                                     testing::FullCameraImage(5, 320, 240)));
}

INSTANTIATE_TEST_SUITE_P(Directions, BusInterop,
                         ::testing::Values(Direction{"cyclonedds", "fastdds", 170},
                                           Direction{"fastdds", "cyclonedds", 180}),
                         [](const auto& param_info) {
                           return param_info.param.from + "_to_" + param_info.param.to;
                         });

}  // namespace
}  // namespace swarmbox::bus
