#include "swarmbox/faults/partition_plan.hpp"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::faults {
namespace {

using ::testing::ElementsAre;
using testing::Lines;

const std::vector<MeshNode> kNodes = {
    {"a", "eth1", "10.77.2.10"}, {"b", "eth1", "10.77.2.11"}, {"c", "eth2", "10.77.2.12"}, {"d", "eth1", "10.77.2.13"}};

TEST(PartitionPlan, SymmetricSplitDropsOtherGroupsOnIngressEverywhere) {
  auto plan = PlanPartition(PartitionFault{{{"a", "b"}, {"c", "d"}}, false}, kNodes);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_EQ(plan->apply.size(), 4u);
  EXPECT_THAT(Lines(plan->apply.at("a")),
              ElementsAre("iptables -w -N SWARMBOX-PART-0",
                          "iptables -w -A SWARMBOX-PART-0 -s 10.77.2.12/32 -j DROP",
                          "iptables -w -A SWARMBOX-PART-0 -s 10.77.2.13/32 -j DROP",
                          "iptables -w -I INPUT -i eth1 -j SWARMBOX-PART-0"));
  EXPECT_THAT(Lines(plan->apply.at("c")),
              ElementsAre("iptables -w -N SWARMBOX-PART-0",
                          "iptables -w -A SWARMBOX-PART-0 -s 10.77.2.10/32 -j DROP",
                          "iptables -w -A SWARMBOX-PART-0 -s 10.77.2.11/32 -j DROP",
                          "iptables -w -I INPUT -i eth2 -j SWARMBOX-PART-0"));
  EXPECT_THAT(Lines(plan->undo.at("c")),
              ElementsAre("iptables -w -D INPUT -i eth2 -j SWARMBOX-PART-0", "iptables -w -F SWARMBOX-PART-0",
                          "iptables -w -X SWARMBOX-PART-0"));
}

TEST(PartitionPlan, OneWayCutsOnlyTrafficFromTheFirstGroup) {
  auto plan = PlanPartition(PartitionFault{{{"a"}, {"b", "c", "d"}}, true}, kNodes);
  ASSERT_TRUE(plan) << plan.error().ToString();
  // a still hears everyone; b, c, d drop what comes from a.
  EXPECT_EQ(plan->apply.count("a"), 0u);
  EXPECT_EQ(plan->undo.count("a"), 0u);
  EXPECT_THAT(Lines(plan->apply.at("b")),
              ElementsAre("iptables -w -N SWARMBOX-PART-0", "iptables -w -A SWARMBOX-PART-0 -s 10.77.2.10/32 -j DROP",
                          "iptables -w -I INPUT -i eth1 -j SWARMBOX-PART-0"));
  EXPECT_EQ(plan->apply.size(), 3u);
}

TEST(PartitionPlan, UnlistedDronesFormTheRestGroup) {
  auto plan = PlanPartition(PartitionFault{{{"a"}}, false}, kNodes);
  ASSERT_TRUE(plan) << plan.error().ToString();
  ASSERT_EQ(plan->groups.size(), 2u);
  EXPECT_EQ(plan->groups[1], (std::vector<std::string>{"b", "c", "d"}));
  EXPECT_EQ(Lines(plan->apply.at("a")).size(), 5u);  // -N, three DROPs, the hook
  EXPECT_EQ(Lines(plan->apply.at("d")).size(), 3u);  // -N, one DROP (a), the hook
}

TEST(PartitionPlan, OverlappingPartitionsUseTheirOwnChains) {
  auto plan = PlanPartition(PartitionFault{{{"a"}, {"b"}}, false}, kNodes, 7);
  ASSERT_TRUE(plan) << plan.error().ToString();
  EXPECT_THAT(Lines(plan->undo.at("b")),
              ElementsAre("iptables -w -D INPUT -i eth1 -j SWARMBOX-PART-7", "iptables -w -F SWARMBOX-PART-7",
                          "iptables -w -X SWARMBOX-PART-7"));
}

TEST(PartitionPlan, RefusesUnknownAndDuplicateMembers) {
  auto unknown = PlanPartition(PartitionFault{{{"a"}, {"z"}}, false}, kNodes);
  ASSERT_FALSE(unknown);
  EXPECT_EQ(unknown.error().message(), "partition names unknown drone 'z'");
  auto twice = PlanPartition(PartitionFault{{{"a"}, {"a", "b"}}, false}, kNodes);
  ASSERT_FALSE(twice);
  EXPECT_EQ(twice.error().message(), "drone 'a' is in two partition groups");
  auto whole = PlanPartition(PartitionFault{{{"a", "b", "c", "d"}}, false}, kNodes);
  ASSERT_FALSE(whole);
  EXPECT_NE(whole.error().message().find("at least two groups"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::faults
