// The agent's Raft host, pure parts: the --members list, the default WAL directory, the clocks,
// the transport onto a MeshRadio, the event restamp; three hosts over ChannelRadios and a
// scripted channel elect one leader at the same simulated time on every run.
#include "raft_host.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <vector>

#include "support/files.hpp"
#include "swarmbox/mission/raft_envelope.hpp"
#include "swarmbox/radio/channel_radio.hpp"

namespace swarmbox::agent {
namespace {

TEST(RaftHostMembers, ParsesTheTrialsDronesInOrder) {
  auto m = ParseMembers("drone_1,drone_2,lifter", "drone_2");
  ASSERT_TRUE(m.ok()) << m.error().ToString();
  EXPECT_EQ(*m, (std::vector<std::string>{"drone_1", "drone_2", "lifter"}));
}

TEST(RaftHostMembers, RejectsAListWithoutThisDrone) {
  auto m = ParseMembers("drone_1,drone_2", "drone_3");
  ASSERT_FALSE(m.ok());
  EXPECT_EQ(m.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(m.error().ToString().find("does not include this drone ('drone_3')"), std::string::npos)
      << m.error().ToString();
}

TEST(RaftHostMembers, RejectsEmptyDuplicateAndBadNames) {
  auto empty = ParseMembers("drone_1,,drone_2", "drone_1");
  ASSERT_FALSE(empty.ok());
  EXPECT_NE(empty.error().ToString().find("empty name"), std::string::npos) << empty.error().ToString();
  auto twice = ParseMembers("drone_1,drone_2,drone_1", "drone_1");
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().ToString().find("'drone_1' listed twice"), std::string::npos) << twice.error().ToString();
  auto bad = ParseMembers("drone_1,drone-2", "drone_1");
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bad.error().ToString().find("--members"), std::string::npos) << bad.error().ToString();
}

TEST(RaftHostMembers, DefaultWalDirectoryIsPerDrone) {
  EXPECT_EQ(DefaultRaftDir("drone_3"), "/tmp/swarmbox-raft/drone_3");
  EXPECT_NE(DefaultRaftDir("drone_1"), DefaultRaftDir("drone_2"));
}

TEST(RaftHostClock, ReturnsTheLastSimulatedTime) {
  SimClock c;
  EXPECT_EQ(c.NowS(), 0.0);
  c.Set(12.5);
  EXPECT_EQ(c.NowS(), 12.5);
}

TEST(RaftHostClock, RadioClockIsTheRadiosNowSinceItsOrigin) {
  radio::ChannelRadio radio("drone_1");
  RadioClock from_zero(radio, 0), from_one(radio, 1'000'000'000);
  bus::SensorSample s;
  s.sim_time_ns = 2'500'000'000;
  std::vector<bus::RadioFrame> frames;
  radio.TakeReceived(s, &frames);
  EXPECT_DOUBLE_EQ(from_zero.NowS(), 2.5);
  EXPECT_DOUBLE_EQ(from_one.NowS(), 1.5);
}

TEST(RaftHostTransport, SendsOneRaftEnvelopePerMessage) {
  radio::ChannelRadio radio("drone_1");
  RadioTransport t(radio, "drone_1");
  const std::vector<std::uint8_t> bytes = {1, 2, 3};
  t.Send("drone_2", bytes);
  bus::ActuatorCommand cmd;
  radio.Flush(&cmd);
  ASSERT_EQ(cmd.radio_out.size(), 1u);
  const bus::RadioFrame& f = cmd.radio_out[0];
  EXPECT_EQ(f.from, "drone_1");
  EXPECT_EQ(f.to, "drone_2");
  ASSERT_EQ(f.raft_msg.size(), 1u);
  EXPECT_EQ(f.raft_msg[0].from, "drone_1");
  EXPECT_EQ(f.raft_msg[0].to, "drone_2");
  EXPECT_EQ(f.raft_msg[0].payload, bytes);
  EXPECT_TRUE(f.state_msg.empty() && f.ping_msg.empty() && f.detection_msg.empty());
}

TEST(RaftHostEvents, RestampReplacesOnlyTheLeadingTime) {
  EXPECT_EQ(RestampLine("t=123.456789 node=a event=leader_elected term=2", 4.25),
            "t=4.250 node=a event=leader_elected term=2");
  EXPECT_EQ(RestampLine("t=1", 2.0), "t=2.000");
  EXPECT_EQ(RestampLine("node=a t=1", 2.0), "node=a t=1");
}

// Three drones on a lossless channel with a 10 ms delay, stepped every 4 ms of simulated time.
// Returns each drone's log.
std::map<std::string, std::string> RunThree(std::uint64_t seed, double seconds) {
  const std::vector<std::string> members = {"drone_1", "drone_2", "drone_3"};
  const std::string dir = swarmbox::testing::MakeTempDir("swarmbox_agent_raft_three_");
  struct Drone {
    std::unique_ptr<radio::ChannelRadio> radio;
    std::unique_ptr<RadioClock> clock;
    std::FILE* log = nullptr;
    std::unique_ptr<RaftHost> host;
  };
  std::vector<Drone> drones(members.size());
  for (std::size_t i = 0; i < members.size(); ++i) {
    Drone& d = drones[i];
    d.radio = std::make_unique<radio::ChannelRadio>(members[i]);
    d.clock = std::make_unique<RadioClock>(*d.radio, 0);
    d.log = std::tmpfile();
    RaftHostOptions o;
    o.self = members[i];
    o.members = members;
    o.raft_dir = dir + "/" + members[i];
    o.seed = seed;
    auto h = RaftHost::Start(o, *d.radio, *d.clock, d.log);
    EXPECT_TRUE(h) << h.error().ToString();
    if (!h) return {};
    d.host = std::move(*h);
  }
  std::multimap<std::int64_t, bus::RadioFrame> air;
  for (std::int64_t t = 4'000'000; t <= static_cast<std::int64_t>(seconds * 1e9); t += 4'000'000) {
    for (std::size_t i = 0; i < drones.size(); ++i) {
      Drone& d = drones[i];
      bus::SensorSample s;
      s.sim_time_ns = t;
      for (auto it = air.begin(); it != air.end() && it->first <= t;) {
        if (it->second.to == members[i]) {
          s.radio_in.push_back(it->second);
          it = air.erase(it);
        } else {
          ++it;
        }
      }
      std::vector<bus::RadioFrame> frames;
      d.radio->TakeReceived(s, &frames);
      for (const bus::RadioFrame& f : frames) {
        if (mission::ClassifyRaftMessage(f.raft_msg[0], members[i]) == mission::RaftDelivery::kDeliver) {
          d.host->OnPayload(f.raft_msg[0].payload);
        }
      }
      EXPECT_TRUE(d.host->Step());
      bus::ActuatorCommand cmd;
      d.radio->Flush(&cmd);
      for (bus::RadioFrame& f : cmd.radio_out) {
        f.delivered_ns = f.sent_ns + 10'000'000;
        air.emplace(f.delivered_ns, f);
      }
    }
  }
  std::map<std::string, std::string> logs;
  for (std::size_t i = 0; i < drones.size(); ++i) {
    drones[i].host.reset();
    std::FILE* log = drones[i].log;
    std::fflush(log);
    std::rewind(log);
    char buf[512];
    while (std::fgets(buf, sizeof buf, log) != nullptr) logs[members[i]] += buf;
    std::fclose(log);
  }
  std::filesystem::remove_all(dir);
  return logs;
}

TEST(RaftHostOnTheChannel, ElectsOneLeaderAtTheSameSimulatedTimeOnEveryRun) {
  const auto a = RunThree(7, 3.0);
  const auto b = RunThree(7, 3.0);
  ASSERT_EQ(a.size(), 3u);
  EXPECT_EQ(a, b);  // same seed, same deliveries: the same lines, byte for byte
  std::set<std::string> leaders;
  for (const auto& [name, log] : a) {
    const std::size_t at = log.find("event=leader_elected");
    ASSERT_NE(at, std::string::npos) << name << ": " << log;
    const std::size_t l = log.find("leader=", at);
    ASSERT_NE(l, std::string::npos) << log;
    leaders.insert(log.substr(l + 7, log.find_first_of(" \n", l) - l - 7));
  }
  EXPECT_EQ(leaders.size(), 1u) << "every drone agrees on one leader";
}

}  // namespace
}  // namespace swarmbox::agent
