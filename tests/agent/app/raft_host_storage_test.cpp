// The agent's Raft host over a real mesh participant (Cyclone DDS on lo, domain 215): a one-drone
// cluster elects itself, the diagnostic loop proposes and commits, then an injected fsync failure
// stops the service and Poll() reports it (swarmbox-agent then exits 1).
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include "raft_host.hpp"
#include "support/files.hpp"
#include "support/flaky_file_system.hpp"

namespace swarmbox::agent {
namespace {

using namespace std::chrono_literals;
using swarmbox::testing::FlakyFileSystem;

TEST(RaftHostService, ProposesWhenLeaderAndReportsAStorageFailure) {
  const std::string dir = swarmbox::testing::MakeTempDir("swarmbox_agent_raft_host_");
  ASSERT_FALSE(dir.empty());
  auto mesh = bus::Participant::Create({.backend = "cyclonedds", .domain_id = 215, .interface = "lo"});
  ASSERT_TRUE(mesh) << mesh.error().ToString();
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
  auto host = RaftHost::Start(o, **mesh, log);
  ASSERT_TRUE(host) << host.error().ToString();
  (*host)->SetSimTime(4.25);

  // Given a running node, Poll() drives the proposal loop: the demo mission commits.
  const auto deadline = std::chrono::steady_clock::now() + 10s;
  while ((*host)->service().commit_index() < 2 && std::chrono::steady_clock::now() < deadline) {
    ASSERT_TRUE((*host)->Poll());
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_GE((*host)->service().commit_index(), 2u);
  EXPECT_FALSE((*host)->stopped());

  // When the WAL's fsync fails, then Poll() returns the injected error and the host is stopped.
  fs.fail_sync = true;
  Status polled;
  const auto deadline2 = std::chrono::steady_clock::now() + 10s;
  while (polled && std::chrono::steady_clock::now() < deadline2) {
    polled = (*host)->Poll();
    std::this_thread::sleep_for(5ms);
  }
  ASSERT_FALSE(polled);
  EXPECT_NE(polled.error().ToString().find("injected"), std::string::npos) << polled.error().ToString();
  EXPECT_TRUE((*host)->stopped());
  EXPECT_FALSE((*host)->Poll());  // stays stopped

  // The events went to the agent's log with its simulated time.
  host->reset();
  std::fflush(log);
  std::rewind(log);
  std::string text;
  char buf[512];
  while (std::fgets(buf, sizeof buf, log) != nullptr) text += buf;
  std::fclose(log);
  EXPECT_NE(text.find("t=4.250 node=drone_1 event=leader_elected"), std::string::npos) << text;
  EXPECT_NE(text.find("event=raft_stopped"), std::string::npos) << text;
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::agent
