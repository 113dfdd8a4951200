#include <gtest/gtest.h>

#include <algorithm>
#include <map>

#include "swarmbox/faults/leader_tracker.hpp"
#include "swarmbox/faults/target_resolver.hpp"

namespace swarmbox::faults {
namespace {

const std::vector<std::string> kDrones = {"scout_1", "scout_2", "scout_3", "lifter"};

TEST(LeaderTracker, FollowsTheLatestElection) {
  LeaderTracker t;
  EXPECT_FALSE(t.Resolve());
  EXPECT_EQ(t.Resolve().error().code(), ErrorCode::kNotFound);
  EXPECT_NE(t.Resolve().error().message().find("no event=leader_elected seen"), std::string::npos);
  EXPECT_FALSE(t.Feed("t=1.000 node=scout_1 event=takeoff"));
  EXPECT_TRUE(t.Feed("t=12.340 node=scout_2 event=leader_elected term=3 leader=scout_2"));
  EXPECT_EQ(*t.Resolve(), "scout_2");
  EXPECT_EQ(t.term(), 3);
  EXPECT_TRUE(t.Feed("t=30.100 node=lifter event=leader_elected term=4 leader=lifter"));
  EXPECT_EQ(*t.Resolve(), "lifter");
}

TEST(LeaderTracker, IgnoresStaleTermsAndOtherEvents) {
  LeaderTracker t;
  t.Feed("t=30.1 node=lifter event=leader_elected term=4 leader=lifter");
  EXPECT_FALSE(t.Feed("t=12.3 node=scout_2 event=leader_elected term=3 leader=scout_2"));  // late line
  EXPECT_FALSE(t.Feed("t=31.0 node=scout_2 event=not_leader_elected leader=scout_2"));
  EXPECT_FALSE(t.Feed("event=leader_elected term=x leader=scout_3"));
  EXPECT_EQ(*t.Resolve(), "lifter");
  // Same term, same leader (every node may report it): no change.
  EXPECT_FALSE(t.Feed("t=30.2 node=scout_1 event=leader_elected term=4 leader=lifter"));
}

TEST(LeaderTracker, FallsBackToTheNodeFieldWithoutLeader) {
  LeaderTracker t;
  EXPECT_TRUE(t.Feed("t=5 node=scout_3 event=leader_elected term=1"));
  EXPECT_EQ(*t.Resolve(), "scout_3");
}

TEST(TargetResolver, ResolvesEveryForm) {
  LeaderTracker leaders;
  leaders.Feed("t=12.340 node=scout_2 event=leader_elected term=3 leader=scout_2");
  std::mt19937_64 rng(42);
  auto resolve = [&](FaultTarget t) { return ResolveTarget(t, kDrones, leaders, rng); };
  EXPECT_EQ(*resolve({FaultTarget::Kind::kAll, {}, {}}), kDrones);
  EXPECT_EQ(*resolve({FaultTarget::Kind::kRaftLeader, {}, {}}), std::vector<std::string>{"scout_2"});
  EXPECT_EQ(*resolve({FaultTarget::Kind::kPattern, {}, "scout_*"}),
            (std::vector<std::string>{"scout_1", "scout_2", "scout_3"}));
  EXPECT_EQ(*resolve({FaultTarget::Kind::kNames, {"lifter", "scout_1"}, {}}),
            (std::vector<std::string>{"lifter", "scout_1"}));
  auto random = resolve({FaultTarget::Kind::kRandom, {}, {}});
  ASSERT_TRUE(random);
  ASSERT_EQ(random->size(), 1u);
  EXPECT_NE(std::find(kDrones.begin(), kDrones.end(), (*random)[0]), kDrones.end());
}

TEST(TargetResolver, RandomIsReproducibleFromTheSeedAndCoversAllDrones) {
  LeaderTracker leaders;
  std::mt19937_64 a(7), b(7);
  std::map<std::string, int> counts;
  for (int i = 0; i < 400; ++i) {
    auto x = ResolveTarget({FaultTarget::Kind::kRandom, {}, {}}, kDrones, leaders, a);
    auto y = ResolveTarget({FaultTarget::Kind::kRandom, {}, {}}, kDrones, leaders, b);
    ASSERT_TRUE(x && y);
    EXPECT_EQ(*x, *y);
    ++counts[(*x)[0]];
  }
  // 400 draws over 4 drones: 100 expected each, binomial sd 8.7; allow 4 sd.
  ASSERT_EQ(counts.size(), 4u);
  for (const auto& [name, n] : counts) EXPECT_NEAR(n, 100, 35) << name;
}

TEST(TargetResolver, ErrorsSayWhy) {
  LeaderTracker leaders;
  std::mt19937_64 rng(1);
  auto leader = ResolveTarget({FaultTarget::Kind::kRaftLeader, {}, {}}, kDrones, leaders, rng);
  ASSERT_FALSE(leader);
  EXPECT_EQ(leader.error().code(), ErrorCode::kNotFound);
  leaders.Feed("event=leader_elected term=1 leader=ghost");
  leader = ResolveTarget({FaultTarget::Kind::kRaftLeader, {}, {}}, kDrones, leaders, rng);
  ASSERT_FALSE(leader);
  EXPECT_EQ(leader.error().message(), "the Raft leader 'ghost' is not a drone of this trial");
  auto none = ResolveTarget({FaultTarget::Kind::kPattern, {}, "relay*"}, kDrones, leaders, rng);
  ASSERT_FALSE(none);
  EXPECT_EQ(none.error().message(), "pattern 'relay*' matches no drone");
}

}  // namespace
}  // namespace swarmbox::faults
