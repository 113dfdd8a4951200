// Behaviour of the bus API: clear errors for bad configuration (unknown backend, missing
// interface, domain id out of range, bad topic names), callbacks, timeouts, and the keep-last-per-
// drone semantics of Qos::kState. Domains 190..199 (see bus_test_util.hpp).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <atomic>
#include <map>
#include <mutex>
#include <thread>
#include <vector>

#include "bus_test_util.hpp"
#include "message_samples.hpp"
#include "swarmbox/bus/cyclone_config.hpp"

namespace swarmbox::bus {
namespace {

using ::testing::HasSubstr;
using ::testing::Not;
using testing::MakeParticipant;

TEST(BusParticipant, UnknownBackendNamesTheAcceptedOnes) {
  auto p = Participant::Create({.backend = "opendds", .domain_id = 190, .interface = "lo"});
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_EQ(p.error().message(),
            "unknown bus backend 'opendds': accepted backends are 'cyclonedds' (default) and "
            "'fastdds'");
}

TEST(BusParticipant, MissingInterfaceNamesTheExistingOnes) {
  for (const auto& backend : AvailableBackends()) {
    auto p = Participant::Create({.backend = backend, .domain_id = 190, .interface = "nosuch0"});
    ASSERT_FALSE(p) << backend;
    EXPECT_EQ(p.error().code(), ErrorCode::kNotFound);
    EXPECT_THAT(p.error().message(),
                HasSubstr("network interface 'nosuch0' does not exist; interfaces with an IPv4 "
                          "address here: "));
    EXPECT_THAT(p.error().message(), HasSubstr("lo"));
  }
}

TEST(BusParticipant, EmptyInterfaceIsRejected) {
  auto p = Participant::Create({.backend = "fastdds", .domain_id = 190, .interface = ""});
  ASSERT_FALSE(p);
  EXPECT_EQ(p.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_THAT(p.error().message(), HasSubstr("no network interface given"));
}

TEST(BusParticipant, DomainIdOutOfRangeNamesTheRange) {
  for (int bad : {-1, 233, 1000}) {
    for (const auto& backend : AvailableBackends()) {
      auto p = Participant::Create({.backend = backend, .domain_id = bad, .interface = "lo"});
      ASSERT_FALSE(p) << backend << " " << bad;
      EXPECT_EQ(p.error().code(), ErrorCode::kInvalidArgument);
      EXPECT_EQ(p.error().message(), "DDS domain id " + std::to_string(bad) +
                                         " is out of range: accepted domain ids are 0 to 232 "
                                         "(RTPS ports overflow above)");
    }
  }
}

TEST(BusParticipant, BindsToTheInterfaceAddress) {
  auto p = MakeParticipant("cyclonedds", 190);
  ASSERT_TRUE(p);
  EXPECT_EQ(p->address(), "127.0.0.1");
  EXPECT_EQ(p->config().backend, "cyclonedds");
}

TEST(BusParticipant, BadTopicNameIsRejectedWithTheRule) {
  for (const auto& backend : AvailableBackends()) {
    auto p = MakeParticipant(backend, 190);
    ASSERT_TRUE(p);
    auto pub = p->CreatePublisher<SensorSample>("sim/drone-1/sensor", Qos::kLockstep);
    ASSERT_FALSE(pub);
    EXPECT_EQ(pub.error().code(), ErrorCode::kInvalidArgument);
    EXPECT_EQ(pub.error().message(),
              "topic name 'sim/drone-1/sensor' contains '-': topic names hold only ASCII letters, "
              "digits, '_' and '/', and start with a letter");
    auto sub = p->CreateSubscriber<SensorSample>("1sim", Qos::kLockstep);
    ASSERT_FALSE(sub);
    EXPECT_THAT(sub.error().message(), HasSubstr("starts with '1'"));
  }
}

TEST(BusTopics, PerDroneNamesAndDroneNameRule) {
  EXPECT_EQ(SensorTopic("scout_1"), "sim/scout_1/sensor");
  EXPECT_EQ(kActuatorTopic, "sim/actuator");  // one keyed topic for every drone's answers
  EXPECT_EQ(CameraTopic("scout_1"), "sim/scout_1/camera");
  EXPECT_EQ(StereoTopic("scout_1"), "sim/scout_1/stereo");
  EXPECT_EQ(DepthImageTopic("scout_1"), "sim/scout_1/depth");
  EXPECT_TRUE(ValidateDroneName("scout_1"));
  auto bad = ValidateDroneName("scout 1");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().message(),
            "drone name 'scout 1' contains byte 32: drone names are non-empty [A-Za-z0-9_]+");
  EXPECT_EQ(QosName(Qos::kLockstep), "lockstep");
  EXPECT_EQ(MessageTypeName(MessageType::kSensorSample), "swarmbox::msg::SensorSample");
}

class BusApi : public ::testing::TestWithParam<std::string> {
 protected:
  int Domain(int slot) const { return (GetParam() == "cyclonedds" ? 191 : 195) + slot; }
};

TEST_P(BusApi, TopicReusedWithAnotherTypeFails) {
  auto p = MakeParticipant(GetParam(), Domain(0));
  ASSERT_TRUE(p);
  auto a = p->CreatePublisher<ClockTick>("shared_name", Qos::kLockstep);
  ASSERT_TRUE(a) << a.error().ToString();
  auto b = p->CreatePublisher<Event>("shared_name", Qos::kLockstep);
  ASSERT_FALSE(b);
  EXPECT_THAT(b.error().message(), HasSubstr("shared_name"));
  EXPECT_THAT(b.error().message(), HasSubstr("swarmbox::msg::Event"));
}

TEST_P(BusApi, WaitForSubscribersTimesOutWithACount) {
  auto p = MakeParticipant(GetParam(), Domain(0));
  ASSERT_TRUE(p);
  auto pub = p->CreatePublisher<ClockTick>("lonely", Qos::kLockstep);
  ASSERT_TRUE(pub);
  EXPECT_EQ((*pub)->MatchedSubscribers(), 0);
  auto s = (*pub)->WaitForSubscribers(1, std::chrono::milliseconds(50));
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kTimeout);
  EXPECT_EQ(s.error().message(), "only 0 of 1 subscribers matched on topic 'lonely' after 50 ms");
}

// TakeFor on a silent topic returns false no earlier than the timeout. Upper bound: 50 ms timeout
// plus 1 s of scheduling slack on a shared 2-core machine.
TEST_P(BusApi, TakeForTimesOutOnASilentTopic) {
  auto p = MakeParticipant(GetParam(), Domain(1));
  ASSERT_TRUE(p);
  auto sub = p->CreateSubscriber<ClockTick>("silent", Qos::kLockstep);
  ASSERT_TRUE(sub);
  ClockTick tick;
  EXPECT_FALSE((*sub)->Take(tick));
  const auto start = std::chrono::steady_clock::now();
  EXPECT_FALSE((*sub)->TakeFor(tick, std::chrono::milliseconds(50)));
  const auto waited = std::chrono::steady_clock::now() - start;
  EXPECT_GE(waited, std::chrono::milliseconds(50));
  EXPECT_LT(waited, std::chrono::milliseconds(1050));
}

// With a callback, every sample of a reliable topic reaches the callback, in order, and Take()
// stays empty.
TEST_P(BusApi, CallbackReceivesEverySampleInOrder) {
  auto pub_p = MakeParticipant(GetParam(), Domain(2));
  auto sub_p = MakeParticipant(GetParam(), Domain(2));
  ASSERT_TRUE(pub_p && sub_p);
  std::mutex mu;
  std::vector<std::uint64_t> steps;
  auto sub = sub_p->CreateSubscriber<ClockTick>(
      std::string(kClockTopic), Qos::kLockstep, [&](const ClockTick& t) {
        std::lock_guard lock(mu);
        steps.push_back(t.step);
      });
  ASSERT_TRUE(sub);
  auto pub = pub_p->CreatePublisher<ClockTick>(std::string(kClockTopic), Qos::kLockstep);
  ASSERT_TRUE(pub);
  ASSERT_TRUE((*pub)->WaitForSubscribers(1, testing::kMatchTimeout));
  ASSERT_TRUE((*sub)->WaitForPublishers(1, testing::kMatchTimeout));
  constexpr std::uint64_t kCount = 10;  // below the keep-last depth 16: nothing may be dropped
  for (std::uint64_t i = 0; i < kCount; ++i) {
    ClockTick t;
    t.step = i;
    ASSERT_TRUE((*pub)->Publish(t));
  }
  const auto deadline = std::chrono::steady_clock::now() + testing::kMatchTimeout;
  while (std::chrono::steady_clock::now() < deadline) {
    {
      std::lock_guard lock(mu);
      if (steps.size() >= kCount) break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  std::lock_guard lock(mu);
  std::vector<std::uint64_t> expected;
  for (std::uint64_t i = 0; i < kCount; ++i) expected.push_back(i);
  EXPECT_EQ(steps, expected);
  ClockTick unused;
  EXPECT_FALSE((*sub)->Take(unused));
}

// Qos::kState keeps the latest sample per drone (DroneState is keyed by drone): after two updates
// of each of 30 drones (more than Fast DDS's default instance limit of 10), an idle subscriber
// holds exactly the latest of each.
TEST_P(BusApi, StateKeepsTheLatestSamplePerDrone) {
  auto pub_p = MakeParticipant(GetParam(), Domain(3));
  auto sub_p = MakeParticipant(GetParam(), Domain(3));
  ASSERT_TRUE(pub_p && sub_p);
  auto sub = sub_p->CreateSubscriber<DroneState>(std::string(kDroneStateTopic), Qos::kState);
  auto pub = pub_p->CreatePublisher<DroneState>(std::string(kDroneStateTopic), Qos::kState);
  ASSERT_TRUE(sub && pub);
  ASSERT_TRUE((*pub)->WaitForSubscribers(1, testing::kMatchTimeout));
  ASSERT_TRUE((*sub)->WaitForPublishers(1, testing::kMatchTimeout));
  constexpr int kDrones = 30;
  for (std::uint64_t seq : {1u, 2u}) {
    for (int i = 0; i < kDrones; ++i) {
      DroneState s = testing::FullDroneState(seq);
      s.drone = "scout_" + std::to_string(i);
      s.seq = seq;
      auto st = (*pub)->Publish(s);
      ASSERT_TRUE(st) << s.drone << " seq " << seq << ": " << st.error().ToString();
    }
  }
  // Reliable delivery in one process completes in milliseconds; 1 s leaves ample slack.
  std::this_thread::sleep_for(std::chrono::seconds(1));
  std::map<std::string, std::vector<std::uint64_t>> seen;
  DroneState s;
  while ((*sub)->Take(s)) seen[s.drone].push_back(s.seq);
  std::map<std::string, std::vector<std::uint64_t>> expected;
  for (int i = 0; i < kDrones; ++i) expected["scout_" + std::to_string(i)] = {2};
  EXPECT_EQ(seen, expected);
}

INSTANTIATE_TEST_SUITE_P(Backends, BusApi, ::testing::Values("cyclonedds", "fastdds"),
                         [](const auto& param_info) { return param_info.param; });

// The configuration every process (and, through the runner's CYCLONEDDS_URI, every external brain
// and component) gives Cyclone: the tuned settings are in it, and Cyclone accepts it (every
// cyclonedds participant of these tests is created with it).
TEST(BusCycloneConfig, CarriesTheSettingsTheReadmeExplains) {
  const std::string xml = CycloneXml({.interface = "eth0"});
  EXPECT_THAT(xml, HasSubstr("<NetworkInterface name=\"eth0\" multicast=\"true\"/>"));
  EXPECT_THAT(xml, HasSubstr("<AllowMulticast>true</AllowMulticast>"));
  EXPECT_THAT(xml, HasSubstr("<MaxMessageSize>65000B</MaxMessageSize><FragmentSize>62000B</FragmentSize>"));
  EXPECT_THAT(xml, HasSubstr("<ParticipantIndex>none</ParticipantIndex>"));
  EXPECT_THAT(xml, HasSubstr("<LeaseDuration>20 s</LeaseDuration>"));
  EXPECT_THAT(xml, HasSubstr("<SPDPInterval>10 s</SPDPInterval>"));
  EXPECT_THAT(xml, HasSubstr("<SocketReceiveBufferSize max=\"4MiB\"/>"));
  EXPECT_THAT(xml, Not(HasSubstr("WriterLingerDuration")));
  EXPECT_THAT(CycloneXml({.interface = "lo", .writer_linger_ms = 0}),
              HasSubstr("<WriterLingerDuration>0 ms</WriterLingerDuration>"));
}

// Discovery as a star (a trial's sim bus): the physics server at a well-known index, each agent
// naming it as its one peer, with multicast off so the agents do not discover one another.
TEST(BusCycloneConfig, StarDiscoveryNamesPeersAndTurnsMulticastOff) {
  EXPECT_EQ(CycloneDiscoveryPort(0, 0), 7410);  // DDSI: 7400 + 250 d + 10 + 2 i
  EXPECT_EQ(CycloneDiscoveryPort(3, 2), 7400 + 750 + 10 + 4);
  const std::string server = CycloneXml({.interface = "eth0", .participant_index = 0});
  EXPECT_THAT(server, HasSubstr("<ParticipantIndex>0</ParticipantIndex>"));
  EXPECT_THAT(server, HasSubstr("<AllowMulticast>true</AllowMulticast>"));  // brains, components find it
  EXPECT_THAT(server, Not(HasSubstr("<Peers>")));
  const std::string agent = CycloneXml({.interface = "eth0", .peers = {"physics:7410", "brain-scout-1:7410"}});
  EXPECT_THAT(agent, HasSubstr("<AllowMulticast>false</AllowMulticast>"));
  EXPECT_THAT(agent, HasSubstr("<NetworkInterface name=\"eth0\"/>"));
  EXPECT_THAT(agent, HasSubstr("<Peers><Peer Address=\"physics:7410\"/><Peer Address=\"brain-scout-1:7410\"/></Peers>"));
  EXPECT_THAT(agent, HasSubstr("<ParticipantIndex>none</ParticipantIndex>"));
}

}  // namespace
}  // namespace swarmbox::bus
