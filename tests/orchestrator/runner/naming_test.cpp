#include "swarmbox/runner/naming.hpp"

#include <gtest/gtest.h>

#include <regex>

namespace swarmbox::runner {
namespace {

TEST(Naming, RunIdIsUtcTimeAndRandomBits) {
  EXPECT_EQ(MakeRunId(1795267800, 0x7f3a), "20261121-133000-7f3a");
  EXPECT_EQ(MakeRunId(0, 0x12345), "19700101-000000-2345");
}

TEST(Naming, NewRunIdsDifferAndAreDockerNameSafe) {
  const std::string a = NewRunId(), b = NewRunId();
  EXPECT_TRUE(std::regex_match(a, std::regex("[0-9]{8}-[0-9]{6}-[0-9a-f]{4}"))) << a;
  EXPECT_NE(a, b);  // 16 random bits: a collision here would be 1 in 65536
}

TEST(Naming, NamesAndLabelsFollowTheContract) {
  EXPECT_EQ(ResourceName("sar-search", "20261121-101000-7f3a", "scout_1"),
            "sar-search-20261121-101000-7f3a-scout_1");
  EXPECT_EQ(TrialDirName("sar-search", "20261121-101000-7f3a"), "sar-search-20261121-101000-7f3a");
  auto labels = RunLabels("r1", "t1", "physics");
  EXPECT_EQ(labels.at("swarmbox.run"), "r1");
  EXPECT_EQ(labels.at("swarmbox.trial"), "t1");
  EXPECT_EQ(labels.at("swarmbox.component"), "physics");
}

}  // namespace
}  // namespace swarmbox::runner
