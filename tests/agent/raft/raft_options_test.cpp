// Raft options from a trial description.
#include "swarmbox/raft/raft_options.hpp"

#include <gtest/gtest.h>

namespace swarmbox::raft {
namespace {

yaml::Node Parse(std::string_view text) {
  auto n = yaml::Parse(text, "trial.yaml");
  EXPECT_TRUE(n.ok()) << (n.ok() ? "" : n.error().ToString());
  return n.ok() ? *n : yaml::Node{};
}

TEST(RaftOptions, ReadsTimingsAndKeepsDefaultsForTheRest) {
  DriverConfig c;
  ASSERT_TRUE(ReadRaftOptions(Parse("{heartbeat_ms: 200, election_timeout_ms: 2000}"), &c).ok());
  EXPECT_EQ(c.heartbeat_ms, 200);
  EXPECT_EQ(c.election_timeout_ms, 2000);
  EXPECT_EQ(c.tick_ms, 50);
  EXPECT_TRUE(c.pre_vote);
}

TEST(RaftOptions, UnknownKeyIsAnErrorWithPosition) {
  DriverConfig c;
  Status s = ReadRaftOptions(Parse("heartbeat_ms: 100\nelection_ms: 500\n"), &c);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.error().ToString().find("trial.yaml:2:"), std::string::npos) << s.error().ToString();
  EXPECT_NE(s.error().message().find("election_ms"), std::string::npos) << s.error().message();
}

TEST(RaftOptions, UnworkableTimingIsRejectedAndConfigUntouched) {
  DriverConfig c;
  Status s = ReadRaftOptions(Parse("{heartbeat_ms: 500, election_timeout_ms: 500}"), &c);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.error().message(),
            "election_timeout_ms (500) must be greater than heartbeat_ms (500)");
  EXPECT_EQ(s.error().where(), "trial.yaml:1:1");
  EXPECT_EQ(c.heartbeat_ms, 100);
}

}  // namespace
}  // namespace swarmbox::raft
