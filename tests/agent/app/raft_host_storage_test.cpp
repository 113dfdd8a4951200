// The agent's Raft host driven as the control loop drives it, on a ChannelRadio and simulated
// time (no DDS, no wall clock): a one-drone cluster elects itself, the diagnostic loop proposes
// and commits, the event lines carry the simulated time, then an injected fsync failure stops
// the service and Step() reports it (swarmbox-agent then exits 1).
#include <gtest/gtest.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "raft_host.hpp"
#include "support/files.hpp"
#include "support/flaky_file_system.hpp"
#include "swarmbox/radio/channel_radio.hpp"

namespace swarmbox::agent {
namespace {

using swarmbox::testing::FlakyFileSystem;

TEST(RaftHostService, ProposesWhenLeaderAndReportsAStorageFailure) {
  const std::string dir = swarmbox::testing::MakeTempDir("swarmbox_agent_raft_host_");
  ASSERT_FALSE(dir.empty());
  std::FILE* log = std::tmpfile();
  ASSERT_NE(log, nullptr);
  FlakyFileSystem fs;
  RaftHostOptions o;
  o.self = "drone_1";
  o.members = {"drone_1"};
  o.raft_dir = dir + "/raft";
  o.seed = 3;
  o.propose_every_ms = 50;
  o.file_system = &fs;
  radio::ChannelRadio radio("drone_1");
  RadioClock clock(radio, 0);
  SimClock events;
  auto host = RaftHost::Start(o, radio, clock, log, &events);
  ASSERT_TRUE(host) << host.error().ToString();

  // Given a running node stepped every 4 ms of simulated time, the demo mission commits.
  std::vector<bus::RadioFrame> frames;
  bus::SensorSample sample;
  std::int64_t t_ns = 0;
  auto step = [&] {
    t_ns += 4'000'000;
    sample.sim_time_ns = t_ns;
    frames.clear();
    radio.TakeReceived(sample, &frames);
    events.Set(static_cast<double>(t_ns) * 1e-9);
    return (*host)->Step();
  };
  while ((*host)->service().commit_index() < 2 && t_ns < 20'000'000'000) ASSERT_TRUE(step());
  ASSERT_GE((*host)->service().commit_index(), 2u);
  EXPECT_FALSE((*host)->stopped());
  const double elected_by_s = static_cast<double>(t_ns) * 1e-9;
  EXPECT_LT(elected_by_s, 5.0);  // a 500..1000 ms election timeout, then two 50 ms proposals

  // When the WAL's fsync fails, then Step() returns the injected error and the host is stopped.
  fs.fail_sync = true;
  Status stepped;
  while (stepped && t_ns < 40'000'000'000) stepped = step();
  ASSERT_FALSE(stepped);
  EXPECT_NE(stepped.error().ToString().find("injected"), std::string::npos) << stepped.error().ToString();
  EXPECT_TRUE((*host)->stopped());
  EXPECT_FALSE(step());  // stays stopped

  host->reset();
  std::fflush(log);
  std::rewind(log);
  std::string text;
  char buf[512];
  while (std::fgets(buf, sizeof buf, log) != nullptr) text += buf;
  std::fclose(log);
  EXPECT_NE(text.find("node=drone_1 event=leader_elected"), std::string::npos) << text;
  EXPECT_NE(text.find("event=raft_stopped"), std::string::npos) << text;
  // A single-member cluster sends nothing on the radio.
  EXPECT_EQ(radio.sent(), 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::agent
