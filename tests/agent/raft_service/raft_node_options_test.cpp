#include "swarmbox/raft_service/raft_node_options.hpp"

#include <gtest/gtest.h>

namespace swarmbox::raft_service {
namespace {

TEST(RaftNodeOptions, ParsesEveryFlag) {
  auto o = ParseRaftNodeArgs({"--name", "b", "--members", "a,b,c", "--data-dir", "/tmp/x",
                              "--domain", "181", "--interface", "lo", "--middleware", "fastdds",
                              "--seed", "42", "--propose-every-ms", "300", "--duration-s", "2.5",
                              "--tick-ms", "20", "--heartbeat-ms", "60",
                              "--election-timeout-ms", "400"});
  ASSERT_TRUE(o) << o.error().ToString();
  EXPECT_EQ(o->driver.self, "b");
  EXPECT_EQ(o->driver.members, (std::vector<std::string>{"a", "b", "c"}));
  EXPECT_EQ(o->data_dir, "/tmp/x");
  EXPECT_EQ(o->domain, 181);
  EXPECT_EQ(o->interface, "lo");
  EXPECT_EQ(o->middleware, "fastdds");
  EXPECT_EQ(o->driver.seed, 42u);
  EXPECT_EQ(o->propose_every_ms, 300);
  EXPECT_DOUBLE_EQ(o->duration_s, 2.5);
  EXPECT_EQ(o->driver.tick_ms, 20);
  EXPECT_EQ(o->driver.heartbeat_ms, 60);
  EXPECT_EQ(o->driver.election_timeout_ms, 400);
}

TEST(RaftNodeOptions, ErrorsNameTheFlag) {
  const std::vector<std::string> base = {"--name", "a", "--members", "a,b", "--data-dir", "d"};
  auto with = [&](std::vector<std::string> extra) {
    std::vector<std::string> v = base;
    v.insert(v.end(), extra.begin(), extra.end());
    return ParseRaftNodeArgs(v);
  };
  auto r = with({"--middleware", "zenoh"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("--middleware"), std::string::npos);
  r = with({"--domain", "12x"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("--domain"), std::string::npos);
  r = with({"--bogus", "1"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("--bogus"), std::string::npos);
  r = with({"--seed"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("missing value"), std::string::npos);
  r = ParseRaftNodeArgs({"--members", "a,b", "--data-dir", "d"});
  ASSERT_FALSE(r);
  EXPECT_NE(r.error().message().find("--name"), std::string::npos);
  r = ParseRaftNodeArgs({"--name", "a b", "--members", "a b,c", "--data-dir", "d"});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kInvalidArgument);
}

TEST(RaftNodeOptions, SelfMustBeAMember) {
  auto r = ParseRaftNodeArgs({"--name", "z", "--members", "a,b,c", "--data-dir", "d"});
  ASSERT_FALSE(r);
  EXPECT_EQ(r.error().code(), ErrorCode::kInvalidArgument);
}

TEST(RaftNodeOptions, HelpNeedsNothingElse) {
  auto r = ParseRaftNodeArgs({"--help"});
  ASSERT_TRUE(r);
  EXPECT_TRUE(r->help);
  EXPECT_NE(RaftNodeUsage().find("--members"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::raft_service
