// The pure half of `swarmbox-bench launch`: Docker timestamps and the launch figures.
#include "launch_timing.hpp"

#include <gtest/gtest.h>

namespace swarmbox::cli::testing {
namespace {

constexpr std::int64_t kS = 1'000'000'000;

TEST(DockerTimestamp, ParsesNanosecondsInUtc) {
  // date -u -d 2026-11-21T16:00:00Z +%s = 1795276800
  EXPECT_EQ(ParseDockerTimestampNs("2026-11-21T16:00:00.123456789Z"), 1795276800 * kS + 123456789);
  EXPECT_EQ(ParseDockerTimestampNs("2026-11-21T16:00:00Z"), 1795276800 * kS);
  EXPECT_EQ(ParseDockerTimestampNs("2026-11-21T16:00:00.5Z"), 1795276800 * kS + 500'000'000);
  EXPECT_EQ(ParseDockerTimestampNs("1970-01-01T00:00:00Z"), 0);
  EXPECT_EQ(ParseDockerTimestampNs("2024-02-29T23:59:59Z"), 1709251199 * kS);  // a leap day
}

TEST(DockerTimestamp, RejectsWhatIsNotOne) {
  EXPECT_EQ(ParseDockerTimestampNs(""), std::nullopt);
  EXPECT_EQ(ParseDockerTimestampNs("t=1.000 node=physics event=ready"), std::nullopt);
  EXPECT_EQ(ParseDockerTimestampNs("2026-11-21T16:00:00.123+01:00"), std::nullopt);  // not UTC
  EXPECT_EQ(ParseDockerTimestampNs("2026-11-21T16:00:00.Z"), std::nullopt);
  EXPECT_EQ(ParseDockerTimestampNs("2026-11-21T16:00:00.1234567890Z"), std::nullopt);
  EXPECT_EQ(ParseDockerTimestampNs("2026-13-21T16:00:00Z"), std::nullopt);
}

TEST(DockerTimestamp, SplitsAStampedLogLine) {
  auto l = SplitStampedLine("2026-11-21T16:00:01.000000001Z t=0.000 node=scout_1 event=ready");
  ASSERT_TRUE(l);
  EXPECT_EQ(l->time_ns, 1795276801 * kS + 1);
  EXPECT_EQ(l->text, "t=0.000 node=scout_1 event=ready");
  EXPECT_EQ(SplitStampedLine("2026-11-21T16:00:01Z")->text, "");
  EXPECT_FALSE(SplitStampedLine("no stamp here"));
}

TEST(LaunchFigures, FromSpawnToTheLastAgentAndFromTheEndToTheLastStop) {
  LaunchTimes t;
  t.spawn_ns = 100 * kS;
  t.ready_ns = {{"scout_1", 102 * kS}, {"scout_2", 103 * kS + kS / 2}, {"physics", 101 * kS}};
  t.end_line_ns = 120 * kS;
  t.died_ns = {120 * kS + kS / 4, 120 * kS + kS / 2, 120 * kS + kS / 10};
  t.exited_ns = 121 * kS;
  const LaunchFigures f = ComputeLaunchFigures(t, {"scout_1", "scout_2"});
  ASSERT_TRUE(f.ready_s);
  EXPECT_DOUBLE_EQ(*f.ready_s, 3.5);
  EXPECT_TRUE(f.not_ready.empty());
  ASSERT_TRUE(f.end_to_stopped_s);
  EXPECT_DOUBLE_EQ(*f.end_to_stopped_s, 0.5);
  ASSERT_TRUE(f.end_to_exit_s);
  EXPECT_DOUBLE_EQ(*f.end_to_exit_s, 1.0);
}

TEST(LaunchFigures, AnAgentThatNeverGotReadyLeavesNoLaunchTime) {
  LaunchTimes t;
  t.spawn_ns = 100 * kS;
  t.ready_ns = {{"scout_1", 102 * kS}};
  const LaunchFigures f = ComputeLaunchFigures(t, {"scout_1", "scout_2"});
  EXPECT_FALSE(f.ready_s);
  EXPECT_EQ(f.not_ready, std::vector<std::string>{"scout_2"});
  EXPECT_FALSE(f.end_to_stopped_s);  // no ending line (a compose launch)
  EXPECT_FALSE(f.end_to_exit_s);
}

TEST(LaunchFigures, StartToReadyOfOneComponent) {
  LaunchTimes t;
  t.start_ns = {{"physics", 100 * kS + kS / 4}, {"scout_1", 101 * kS}};
  t.ready_ns = {{"physics", 100 * kS + kS}, {"scout_2", 102 * kS}};
  ASSERT_TRUE(StartToReady(t, "physics"));
  EXPECT_DOUBLE_EQ(*StartToReady(t, "physics"), 0.75);
  EXPECT_FALSE(StartToReady(t, "scout_1"));  // never ready
  EXPECT_FALSE(StartToReady(t, "scout_2"));  // no start event seen
}

}  // namespace
}  // namespace swarmbox::cli::testing
