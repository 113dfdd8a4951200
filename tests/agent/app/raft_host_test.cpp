// The agent's Raft host, pure parts: the --members list and the default WAL directory.
#include "raft_host.hpp"

#include <gtest/gtest.h>

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

}  // namespace
}  // namespace swarmbox::agent
