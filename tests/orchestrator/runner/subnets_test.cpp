#include "swarmbox/runner/subnets.hpp"

#include <gtest/gtest.h>

#include <set>

namespace swarmbox::runner {
namespace {

TEST(Ipv4Net, ParsesPrintsAndChecksOverlap) {
  auto n = Ipv4Net::Parse("10.200.4.7/24");
  ASSERT_TRUE(n);
  EXPECT_EQ(n->ToString(), "10.200.4.0/24");
  EXPECT_EQ(n->Host(12), "10.200.4.12");
  EXPECT_TRUE(n->Overlaps(*Ipv4Net::Parse("10.200.0.0/16")));
  EXPECT_TRUE(Ipv4Net::Parse("10.0.0.0/8")->Overlaps(*n));
  EXPECT_FALSE(n->Overlaps(*Ipv4Net::Parse("10.200.5.0/24")));
  for (const char* bad : {"10.200.4/24", "10.200.4.0/33", "300.1.1.1/8", "x", "10.0.0.0/"}) {
    EXPECT_FALSE(Ipv4Net::Parse(bad).has_value()) << bad;
  }
}

TEST(PickSubnets, IsDeterministicPerRunIdAndInThePool) {
  auto a = PickSubnets("20261121-101000-7f3a", 0, {});
  auto b = PickSubnets("20261121-101000-7f3a", 0, {});
  ASSERT_TRUE(a && b);
  EXPECT_EQ(a->sim.ToString(), b->sim.ToString());
  EXPECT_FALSE(a->sim.Overlaps(a->mesh));
  EXPECT_TRUE(Ipv4Net::Parse("10.200.0.0/14")->Overlaps(a->sim));
  EXPECT_TRUE(Ipv4Net::Parse("10.200.0.0/14")->Overlaps(a->mesh));
}

TEST(PickSubnets, DifferentRunsSpreadOverThePool) {
  std::set<std::string> seen;
  for (int i = 0; i < 50; ++i) {
    seen.insert(PickSubnets("run-" + std::to_string(i), 0, {})->sim.ToString());
  }
  EXPECT_GT(seen.size(), 40u);
}

TEST(PickSubnets, SkipsTakenNetworksAndMovesOnWithAttempts) {
  auto first = PickSubnets("r", 0, {});
  ASSERT_TRUE(first);
  auto avoiding = PickSubnets("r", 0, {first->mesh.ToString(), "172.17.0.0/16", "garbage"});
  ASSERT_TRUE(avoiding);
  EXPECT_FALSE(avoiding->sim.Overlaps(first->mesh));
  EXPECT_FALSE(avoiding->mesh.Overlaps(first->mesh));
  auto retry = PickSubnets("r", 1, {});
  ASSERT_TRUE(retry);
  EXPECT_NE(retry->sim.ToString(), first->sim.ToString());
}

TEST(PickSubnets, FailsWhenThePoolIsFull) {
  auto s = PickSubnets("r", 0, {"10.200.0.0/14"});
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kUnavailable);
  EXPECT_NE(s.error().message().find("no free subnet pair left in the pool 10.200.0.0/14"),
            std::string::npos);
}

}  // namespace
}  // namespace swarmbox::runner
