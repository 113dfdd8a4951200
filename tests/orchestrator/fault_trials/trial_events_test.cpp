// The events.jsonl readers the fault-trial tests judge by: link pooling (discovery windows
// skipped, pooled mean and sd), failovers, commits and their agreement, on hand-written lines.
#include "trial_events.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>

namespace swarmbox::fault_trials {
namespace {

// One event=link line (the agents' link probe) of `node` -> `peer` over one window: the loss is
// 1 - received / sent, and the round trips (mean = median, sd) are there only when a pong came back.
std::string LinkLine(double wall_s, const char* node, const char* peer, int sent, int received,
                     double rtt_mean_ms = 0, double rtt_sd_ms = 0) {
  char buf[320];
  const double loss = 1.0 - static_cast<double>(received) / sent;
  int n = std::snprintf(buf, sizeof buf,
                        R"({"wall_s":%g,"event":"link","node":"%s","peer":"%s",)"
                        R"("sent":"%d","received":"%d","loss":"%g")",
                        wall_s, node, peer, sent, received, loss);
  if (received > 0) {
    n += std::snprintf(buf + n, sizeof buf - static_cast<std::size_t>(n),
                       R"(,"rtt_ms_mean":"%g","rtt_ms_sd":"%g","rtt_ms_p50":"%g")", rtt_mean_ms, rtt_sd_ms,
                       rtt_mean_ms);
  }
  return std::string(buf) + "}\n";
}

std::vector<TrialEvent> Parse(std::string_view text) {
  auto e = ParseEvents(text);
  EXPECT_TRUE(e) << e.error().ToString();
  return e ? *e : std::vector<TrialEvent>{};
}

TEST(ParseEvents, ReadsScalarsTargetsAndRefusesNonObjects) {
  auto events = Parse(
      R"({"wall_s":1.5,"component":"scout_1","t":"1.200","node":"scout_1","event":"hover"})"
      "\n\n"
      R"({"type":"fault","phase":"applied","fault":"k","kind":"kill","wall_s":3.25,"targets":["scout_2"]})"
      "\n");
  ASSERT_EQ(events.size(), 2u);
  EXPECT_DOUBLE_EQ(events[0].wall_s, 1.5);
  EXPECT_EQ(events[0].component, "scout_1");
  EXPECT_EQ(events[0].Get("event"), "hover");
  EXPECT_EQ(events[0].Number("t"), 1.2);
  EXPECT_EQ(events[1].targets, std::vector<std::string>{"scout_2"});
  ASSERT_TRUE(FindFaultRecord(events, "k", "applied"));
  EXPECT_FALSE(FindFaultRecord(events, "k", "removed"));
  auto bad = ParseEvents("{\"a\":1}\n[1, 2]\n");
  ASSERT_FALSE(bad);
  EXPECT_EQ(bad.error().where(), "events.jsonl:2");
}

TEST(SummariseLinks, SkipsDiscoveryWindowsAndPoolsMoments) {
  // scout_1 -> scout_2: a discovery window (nothing back), then two windows of 2 and 4 pongs.
  auto events = Parse(LinkLine(1, "scout_1", "scout_2", 5, 0) + LinkLine(3, "scout_1", "scout_2", 5, 2, 10, 0) +
                      LinkLine(5, "scout_1", "scout_2", 5, 4, 20, 2) + LinkLine(7, "scout_1", "scout_2", 5, 5, 99, 0));
  // The first window with a pong straddles discovery too: [0, 6) holds only the 5 s window.
  LinkSummary s = SummariseLinks(events, 0.0, 6.0);
  EXPECT_EQ(s.windows, 1u);
  EXPECT_EQ(s.sent, 5u);
  EXPECT_EQ(s.received, 4u);
  EXPECT_DOUBLE_EQ(s.loss, 0.2);
  EXPECT_DOUBLE_EQ(s.rtt_mean_ms, 20.0);
  EXPECT_NEAR(s.rtt_sd_ms, 2.0, 1e-9);
  // Two windows pooled: 4 x N(20, 2) and 5 x 99: mean (80 + 495) / 9.
  LinkSummary all = SummariseLinks(events, 0.0, 100.0);
  EXPECT_EQ(all.windows, 2u);
  EXPECT_DOUBLE_EQ(all.rtt_mean_ms, 575.0 / 9.0);
  const double mean = 575.0 / 9.0;
  const double ss = 3 * 4.0 + 4 * 400.0 + 5 * 99.0 * 99.0 - 9 * mean * mean;
  EXPECT_NEAR(all.rtt_sd_ms, std::sqrt(ss / 8.0), 1e-9);
}

TEST(SummariseLinks, TheWindowMedianSdIgnoresABurstAndThinWindows) {
  // After discovery (the first window with a pong straddles it: skipped, as above), three
  // windows of 6 pongs (sd 50, a host's burst; 3; 2) and one of 3 pongs (sd 99: too few to count).
  auto events = Parse(LinkLine(1, "a", "b", 5, 0) + LinkLine(3, "a", "b", 6, 6, 10, 1) +
                      LinkLine(5, "a", "b", 6, 6, 10, 50) + LinkLine(7, "a", "b", 6, 6, 10, 3) +
                      LinkLine(9, "a", "b", 6, 3, 10, 99) + LinkLine(11, "a", "b", 6, 6, 10, 2));
  const LinkSummary s = SummariseLinks(events, 0.0, 100.0);
  EXPECT_EQ(s.windows, 4u);
  EXPECT_EQ(s.sd_windows, 3u);
  EXPECT_DOUBLE_EQ(s.pongs_per_sd_window, 6.0);
  EXPECT_DOUBLE_EQ(s.rtt_sd_window_median_ms, 3.0);
  EXPECT_GT(s.rtt_sd_ms, 25.0);  // the pooled sd takes the burst in whole
}

TEST(Failovers, FromTheKilledLeaderToTheNextLeaderOfAHigherTerm) {
  auto events = Parse(
      R"({"wall_s":2,"event":"leader_elected","node":"a","term":"2","leader":"b"})"
      "\n"
      R"({"type":"fault","phase":"applied","fault":"k1","kind":"kill","wall_s":10,"targets":["b"]})"
      "\n"
      R"({"wall_s":10.5,"event":"leader_elected","node":"c","term":"2","leader":"b"})"
      "\n"
      R"({"wall_s":11.75,"event":"leader_elected","node":"c","term":"4","leader":"c"})"
      "\n"
      R"({"type":"fault","phase":"applied","fault":"k2","kind":"kill","wall_s":20,"targets":["a"]})"
      "\n");
  const std::vector<Failover> f = Failovers(events);
  ASSERT_EQ(f.size(), 1u);  // k2 killed a follower
  EXPECT_EQ(f[0].fault, "k1");
  EXPECT_EQ(f[0].old_leader, "b");
  EXPECT_EQ(f[0].new_leader, "c");
  EXPECT_EQ(f[0].new_term, 4u);
  EXPECT_DOUBLE_EQ(f[0].failover_ms, 1750.0);
}

TEST(Commits, IndexAtAndDisagreements) {
  auto events = Parse(
      R"({"wall_s":1,"event":"mission_state","node":"a","state":"SEARCH","index":"3"})"
      "\n"
      R"({"wall_s":2,"event":"victim_confirmed","node":"a","id":"1","index":"4"})"
      "\n"
      R"({"wall_s":2.5,"event":"mission_state","node":"b","state":"SEARCH","index":"3"})"
      "\n"
      R"({"wall_s":3,"event":"mission_state","node":"b","state":"CONVERGE","index":"4"})"
      "\n"
      R"({"wall_s":4,"event":"mission_state","node":"c","state":"SEARCH","index":"9","from":"snapshot"})"
      "\n");
  const auto commits = CommitsByDrone(events);
  EXPECT_EQ(IndexAt(commits.at("a"), 1.5), 3u);
  EXPECT_EQ(IndexAt(commits.at("a"), 0.5), 0u);
  EXPECT_EQ(commits.count("c"), 0u);  // snapshot installs are not commits of their own
  const auto d = Disagreements(commits);
  ASSERT_EQ(d.size(), 1u);
  EXPECT_EQ(d[0], "index 4: a 'victim_confirmed id=1' vs b 'mission_state state=CONVERGE'");
  EXPECT_EQ(LeaderSeenBy(Parse(R"({"wall_s":1,"event":"leader_elected","node":"x","leader":"y"})"),
                         {"x"}, 2.0),
            "y");
}

TEST(Percentile, NearestRank) {
  EXPECT_EQ(Percentile({}, 0.5), -1.0);
  EXPECT_EQ(Percentile({5, 1, 3}, 0.5), 3.0);
  EXPECT_EQ(Percentile({5, 1, 3}, 0.99), 5.0);
}

}  // namespace
}  // namespace swarmbox::fault_trials
