// The agent's Raft host, pure parts: the --members list, the default WAL directory, the clocks,
// the transport onto a MeshRadio, the event restamp; three hosts over ChannelRadios and a
// scripted channel elect one leader at the same simulated time on every run, and replicate a
// brain's bytes through the entry log (ProposeBytes, TakeCommitted, leader()).
#include "raft_host.hpp"

#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <map>
#include <set>
#include <vector>

#include "support/files.hpp"
#include "swarmbox/raft_service/raft_envelope.hpp"
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

TEST(RaftHostMembers, ParsesTheVotingSetAmongTheMembers) {
  const std::vector<std::string> members = {"scout_1", "scout_2", "scout_3", "lifter"};
  auto v = ParseVoters("scout_1,scout_2", members);
  ASSERT_TRUE(v.ok()) << v.error().ToString();
  EXPECT_EQ(*v, (std::vector<std::string>{"scout_1", "scout_2"}));
  auto stranger = ParseVoters("scout_1,scout_9", members);
  ASSERT_FALSE(stranger.ok());
  EXPECT_NE(stranger.error().ToString().find("'scout_9' is not in --members"), std::string::npos)
      << stranger.error().ToString();
  auto twice = ParseVoters("scout_1,scout_1", members);
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.error().ToString().find("listed twice"), std::string::npos) << twice.error().ToString();
  EXPECT_FALSE(ParseVoters("scout_1,", members).ok());
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

struct ThreeRun {
  std::map<std::string, std::string> logs;                   // each drone's event lines
  std::map<std::string, std::vector<raft::Committed>> taps;  // each drone's TakeCommitted, joined
  std::map<std::string, std::string> leaders;                // each drone's leader() at the end
};

// Three drones on a lossless channel with a 10 ms delay, stepped every 4 ms of simulated time.
// With `entry_log` each runs an EntryLogMachine and, from t = 1 s, proposes "hello <name>" until
// a proposal is accepted.
// `members`/`voters`: another swarm (voters: the --raft-voters list, empty: every member votes).
ThreeRun RunThree(std::uint64_t seed, double seconds, bool entry_log = false,
                  const std::vector<std::string>& members = {"drone_1", "drone_2", "drone_3"},
                  const std::vector<std::string>& voters = {}) {
  const std::string dir = swarmbox::testing::MakeTempDir("swarmbox_agent_raft_three_");
  struct Drone {
    std::unique_ptr<radio::ChannelRadio> radio;
    std::unique_ptr<RadioClock> clock;
    std::FILE* log = nullptr;
    std::unique_ptr<RaftHost> host;
    bool proposed = false;
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
    o.voters = voters;
    o.raft_dir = dir + "/" + members[i];
    o.seed = seed;
    std::unique_ptr<raft::StateMachine> machine;
    if (entry_log) machine = std::make_unique<raft::EntryLogMachine>();
    auto h = RaftHost::Start(o, *d.radio, *d.clock, d.log, nullptr, std::move(machine));
    EXPECT_TRUE(h) << h.error().ToString();
    if (!h) return {};
    d.host = std::move(*h);
  }
  ThreeRun run;
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
        if (raft_service::ClassifyRaftMessage(f.raft_msg[0], members[i]) == raft_service::RaftDelivery::kDeliver) {
          d.host->OnPayload(f.raft_msg[0].payload);
        }
      }
      EXPECT_TRUE(d.host->Step());
      if (entry_log && t >= 1'000'000'000 && !d.proposed) {
        const std::string text = "hello " + members[i];
        d.proposed = d.host->ProposeBytes(raft::Bytes(text.begin(), text.end())).ok();
      }
      std::vector<raft::Committed> got;
      d.host->TakeCommitted(&got);
      auto& tap = run.taps[members[i]];
      tap.insert(tap.end(), got.begin(), got.end());
      bus::ActuatorCommand cmd;
      d.radio->Flush(&cmd);
      for (bus::RadioFrame& f : cmd.radio_out) {
        f.delivered_ns = f.sent_ns + 10'000'000;
        air.emplace(f.delivered_ns, f);
      }
    }
  }
  for (std::size_t i = 0; i < drones.size(); ++i) {
    run.leaders[members[i]] = drones[i].host->leader();
    drones[i].host.reset();
    std::FILE* log = drones[i].log;
    std::fflush(log);
    std::rewind(log);
    char buf[512];
    while (std::fgets(buf, sizeof buf, log) != nullptr) run.logs[members[i]] += buf;
    std::fclose(log);
  }
  std::filesystem::remove_all(dir);
  return run;
}

TEST(RaftHostOnTheChannel, ElectsOneLeaderAtTheSameSimulatedTimeOnEveryRun) {
  const auto a = RunThree(7, 3.0).logs;
  const auto b = RunThree(7, 3.0).logs;
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

// A brain's entries through the host: every drone's tap yields the same three entries, in the
// same index order, and every drone names the same leader.
TEST(RaftHostOnTheChannel, ReplicatesBytesThroughTheEntryLog) {
  const ThreeRun run = RunThree(7, 3.0, /*entry_log=*/true);
  ASSERT_EQ(run.taps.size(), 3u);
  const std::vector<raft::Committed>& first = run.taps.begin()->second;
  ASSERT_EQ(first.size(), 3u);
  std::set<std::string> texts;
  for (std::size_t k = 0; k < first.size(); ++k) {
    texts.insert(std::string(first[k].data.begin(), first[k].data.end()));
    if (k > 0) {
      EXPECT_LT(first[k - 1].index, first[k].index);
    }
  }
  EXPECT_EQ(texts, (std::set<std::string>{"hello drone_1", "hello drone_2", "hello drone_3"}));
  for (const auto& [name, tap] : run.taps) EXPECT_EQ(tap, first) << name;
  std::set<std::string> leaders;
  for (const auto& [name, leader] : run.leaders) leaders.insert(leader);
  ASSERT_EQ(leaders.size(), 1u);
  EXPECT_FALSE(leaders.begin()->empty());
  for (const auto& [name, log] : run.logs) {
    EXPECT_EQ(log.find("event=mission_state"), std::string::npos) << name << ": no mission here";
  }
}

// --raft-voters: with two voters among five drones the leader is a voter, and the three learners
// follow the log and get their own proposals committed (forwarded to the leader).
TEST(RaftHostOnTheChannel, LearnersFollowTheLogAndTheirProposalsCommit) {
  const std::vector<std::string> members = {"drone_1", "drone_2", "drone_3", "drone_4", "drone_5"};
  const ThreeRun run = RunThree(7, 6.0, /*entry_log=*/true, members, {"drone_1", "drone_2"});
  ASSERT_EQ(run.taps.size(), 5u);
  const std::vector<raft::Committed>& first = run.taps.begin()->second;
  std::set<std::string> texts;
  for (const raft::Committed& c : first) texts.insert(std::string(c.data.begin(), c.data.end()));
  EXPECT_EQ(texts, (std::set<std::string>{"hello drone_1", "hello drone_2", "hello drone_3", "hello drone_4",
                                          "hello drone_5"}));
  for (const auto& [name, tap] : run.taps) EXPECT_EQ(tap, first) << name;
  std::set<std::string> leaders;
  for (const auto& [name, leader] : run.leaders) leaders.insert(leader);
  ASSERT_EQ(leaders.size(), 1u);
  EXPECT_TRUE(*leaders.begin() == "drone_1" || *leaders.begin() == "drone_2") << *leaders.begin();
}

TEST(RaftHostMachine, MissionByDefaultAndTheDemoLoopOnlyWithIt) {
  const std::string dir = swarmbox::testing::MakeTempDir("swarmbox_agent_raft_machine_");
  radio::ChannelRadio radio("drone_1");
  RadioClock clock(radio, 0);
  std::FILE* log = std::tmpfile();
  RaftHostOptions o;
  o.self = "drone_1";
  o.members = {"drone_1"};
  o.raft_dir = dir + "/mission";
  auto mission = RaftHost::Start(o, radio, clock, log);
  ASSERT_TRUE(mission) << mission.error().ToString();
  ASSERT_NE((*mission)->FindMission(), nullptr);
  EXPECT_EQ((*mission)->mission().phase(), raft::MissionPhase::kIdle);
  o.raft_dir = dir + "/log";
  o.propose_every_ms = 500;
  auto bad = RaftHost::Start(o, radio, clock, log, nullptr, std::make_unique<raft::EntryLogMachine>());
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(bad.error().ToString().find("--propose-every-ms proposes mission commands"), std::string::npos)
      << bad.error().ToString();
  o.propose_every_ms = 0;
  auto log_host = RaftHost::Start(o, radio, clock, log, nullptr, std::make_unique<raft::EntryLogMachine>());
  ASSERT_TRUE(log_host) << log_host.error().ToString();
  EXPECT_EQ((*log_host)->FindMission(), nullptr);
  Status empty = (*log_host)->ProposeBytes({});
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.error().code(), ErrorCode::kInvalidArgument);
  std::fclose(log);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::agent
