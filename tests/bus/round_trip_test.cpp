// Round trip of a fully populated value of every message type, per backend: publisher and
// subscriber in two participants of one process (both backends serialize to CDR and back even
// in-process, so the converters and generated types are exercised both ways). A field a converter
// forgets stays at its default and the equality check fails.
#include <gtest/gtest.h>

#include "bus_test_util.hpp"
#include "message_samples.hpp"

namespace swarmbox::bus {
namespace {

using testing::Full;
using testing::MakeParticipant;
using testing::RoundTrip;

class BusRoundTrip : public ::testing::TestWithParam<std::string> {
 protected:
  // Domains 150..159 for cyclonedds, 160..169 for fastdds; `slot` is per message type.
  template <BusMessage T>
  void Check(int slot, const std::string& topic, Qos qos) {
    const int domain = (GetParam() == "cyclonedds" ? 150 : 160) + slot;
    auto pub = MakeParticipant(GetParam(), domain);
    auto sub = MakeParticipant(GetParam(), domain);
    ASSERT_TRUE(pub && sub);
    EXPECT_TRUE(RoundTrip<T>(*pub, *sub, topic, qos, Full<T>(7)));
  }
};

TEST_P(BusRoundTrip, ClockTickArrivesIntact) { Check<ClockTick>(0, std::string(kClockTopic), Qos::kLockstep); }
TEST_P(BusRoundTrip, SensorSampleArrivesIntact) { Check<SensorSample>(1, SensorTopic("drone_7"), Qos::kLockstep); }
TEST_P(BusRoundTrip, ActuatorCommandArrivesIntact) { Check<ActuatorCommand>(2, std::string(kActuatorTopic), Qos::kLockstep); }
TEST_P(BusRoundTrip, CameraImageArrivesIntact) { Check<CameraImage>(3, CameraTopic("drone_7"), Qos::kLockstep); }
TEST_P(BusRoundTrip, WorldCommandArrivesIntact) { Check<WorldCommand>(4, std::string(kWorldCommandTopic), Qos::kLockstep); }
TEST_P(BusRoundTrip, DroneStateArrivesIntact) { Check<DroneState>(5, std::string(kDroneStateTopic), Qos::kState); }
TEST_P(BusRoundTrip, RaftMessageArrivesIntact) { Check<RaftMessage>(6, std::string(kRaftTopic), Qos::kRadio); }
TEST_P(BusRoundTrip, DetectionArrivesIntact) { Check<Detection>(7, std::string(kDetectionTopic), Qos::kRadio); }
TEST_P(BusRoundTrip, RadioPingArrivesIntact) { Check<RadioPing>(8, std::string(kRadioPingTopic), Qos::kRadio); }
TEST_P(BusRoundTrip, EventArrivesIntact) { Check<Event>(9, std::string(kEventTopic), Qos::kRadio); }
// The brain's types share slots (domains) with others, on topics of their own.
TEST_P(BusRoundTrip, BrainMessageArrivesIntact) { Check<BrainMessage>(8, std::string(kBrainMessageTopic), Qos::kRadio); }
TEST_P(BusRoundTrip, BrainInputArrivesIntact) { Check<BrainInput>(1, OffboardInputTopic("drone_7"), Qos::kLockstep); }
TEST_P(BusRoundTrip, BrainOutputArrivesIntact) { Check<BrainOutput>(2, OffboardOutputTopic("drone_7"), Qos::kLockstep); }
TEST_P(BusRoundTrip, TelemetryArrivesIntact) { Check<Telemetry>(5, std::string(kTelemetryTopic), Qos::kState); }
TEST_P(BusRoundTrip, DepthSummaryArrivesIntact) { Check<DepthSummary>(6, std::string(kDepthTopic), Qos::kState); }

// A camera-sized image (320x240 mono8, 76,800 bytes of pixels) is fragmented on the wire by both
// backends and must still arrive byte for byte.
TEST_P(BusRoundTrip, CameraSizedImageArrivesIntact) {
  const int domain = (GetParam() == "cyclonedds" ? 150 : 160) + 3;
  auto pub = MakeParticipant(GetParam(), domain);
  auto sub = MakeParticipant(GetParam(), domain);
  ASSERT_TRUE(pub && sub);
  EXPECT_TRUE(RoundTrip<CameraImage>(*pub, *sub, "sim/drone_7/camera_large", Qos::kLockstep,
                                     testing::FullCameraImage(3, 320, 240)));
}

INSTANTIATE_TEST_SUITE_P(Backends, BusRoundTrip, ::testing::Values("cyclonedds", "fastdds"),
                         [](const auto& param_info) { return param_info.param; });

}  // namespace
}  // namespace swarmbox::bus
