// A trial's series over time (trial_series.hpp) and plots.html (trial_plots.hpp): pure, on
// hand-written event lines and truth rows with known answers.
#include "swarmbox/report/trial_plots.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "swarmbox/report/report_html.hpp"
#include "swarmbox/report/trial_series.hpp"

namespace swarmbox::report {
namespace {

void Feed(TrialSeriesBuilder& b, std::string_view component, std::string_view line) {
  b.OnLogEvent(component, ParseLogfmt(line));
}

TruthRow Row(double t, std::string drone, double x, double y, double z, double vx = 0, double vy = 0,
             double vz = 0) {
  TruthRow r;
  r.t_s = t;
  r.drone = std::move(drone);
  r.x_m = x;
  r.y_m = y;
  r.z_m = z;
  r.vx_m_s = vx;
  r.vy_m_s = vy;
  r.vz_m_s = vz;
  return r;
}

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(TrialSeries, ALinkBurstIsOnePointPerNodeWeightedByPings) {
  TrialSeriesBuilder b;
  // Given scout_1's burst at 6.94 s over three peers (as the agents log it) and one at 16.316 s,
  Feed(b, "scout_1",
       "t=6.940 node=scout_1 event=link peer=scout_2 sent=10 received=7 loss=0.3000 rtt_ms_mean=200");
  Feed(b, "scout_1",
       "t=6.940 node=scout_1 event=link peer=scout_3 sent=10 received=9 loss=0.1000 rtt_ms_mean=100");
  Feed(b, "scout_1",
       "t=6.940 node=scout_1 event=link peer=lifter sent=10 received=0 loss=1.0000 rtt_ms_mean=0");
  Feed(b, "scout_2", "t=7.000 node=scout_2 event=link peer=scout_1 sent=4 received=4 loss=0 rtt_ms_mean=50");
  Feed(b, "scout_1",
       "t=16.316 node=scout_1 event=link peer=scout_2 sent=9 received=9 loss=0 rtt_ms_mean=210");
  const TrialSeries s = b.Finish();
  // Then loss = 1 - 16/30 at 6.94 s and RTT the mean weighted by answers (the lifter's none).
  ASSERT_EQ(s.radio_loss.size(), 2u);
  EXPECT_EQ(s.radio_loss[0].name, "scout_1");
  ASSERT_EQ(s.radio_loss[0].points.size(), 2u);
  EXPECT_DOUBLE_EQ(s.radio_loss[0].points[0].t_s, 6.94);
  EXPECT_DOUBLE_EQ(s.radio_loss[0].points[0].value, 1.0 - 16.0 / 30.0);
  EXPECT_DOUBLE_EQ(s.radio_loss[0].points[1].value, 0.0);
  ASSERT_EQ(s.radio_rtt_ms[0].points.size(), 2u);
  EXPECT_DOUBLE_EQ(s.radio_rtt_ms[0].points[0].value, (200.0 * 7 + 100.0 * 9) / 16.0);
  EXPECT_EQ(s.radio_loss[1].name, "scout_2");
  EXPECT_DOUBLE_EQ(s.radio_rtt_ms[1].points[0].value, 50.0);
  EXPECT_DOUBLE_EQ(s.t_end_s, 16.316);
}

TEST(TrialSeries, TruthIsSampledOncePerPeriodWithTheNearestNeighbour) {
  TrialSeriesBuilder b(1.0);
  // Three drones at 50 Hz from 0 to 2.02 s: a and b 5 m apart, c 13 m above b.
  for (int k = 0; k <= 101; ++k) {
    const double t = k * 0.02;
    b.OnTruth(Row(t, "a", 0, 0, 10 + t, 3, 4, 0));
    b.OnTruth(Row(t, "b", 3, 4, 10 + t));
    b.OnTruth(Row(t, "c", 3, 4, 23 + t));
  }
  const TrialSeries s = b.Finish();
  ASSERT_EQ(s.altitude_m.size(), 3u);
  // Samples at 0, 1 and 2 s (the first row group at or after each whole second), not 102.
  ASSERT_EQ(s.altitude_m[0].points.size(), 3u);
  EXPECT_DOUBLE_EQ(s.altitude_m[0].points[1].t_s, 1.0);
  EXPECT_DOUBLE_EQ(s.altitude_m[0].points[2].value, 12.0);
  EXPECT_DOUBLE_EQ(s.speed_m_s[0].points[0].value, 5.0);
  EXPECT_DOUBLE_EQ(s.speed_m_s[1].points[0].value, 0.0);
  EXPECT_DOUBLE_EQ(s.nearest_m[0].points[0].value, 5.0);   // a: b
  EXPECT_DOUBLE_EQ(s.nearest_m[1].points[0].value, 5.0);   // b: a
  EXPECT_DOUBLE_EQ(s.nearest_m[2].points[0].value, 13.0);  // c: b
  EXPECT_NEAR(s.t_end_s, 2.02, 1e-12);
}

TEST(TrialSeries, AFileWithoutVelocityGivesNoSpeedAndOneDroneNoNeighbour) {
  TrialSeriesBuilder b;
  TruthRow r = Row(0, "solo", 0, 0, 3);
  r.has_velocity = false;
  b.OnTruth(r);
  const TrialSeries s = b.Finish();
  EXPECT_EQ(s.altitude_m.size(), 1u);
  EXPECT_TRUE(s.speed_m_s.empty());
  EXPECT_TRUE(s.nearest_m.empty());
}

TEST(TrialSeries, LeaderAndStageBandsHoldUntilTheNextChangeTheStopOrTheEnd) {
  TrialSeriesBuilder b;
  Feed(b, "scout_1", "t=7.000 node=scout_1 event=leader_elected term=2 leader=scout_2");
  Feed(b, "scout_1", "t=4.216 node=scout_1 event=mission_stage role=scout stage=taking_off");
  Feed(b, "scout_1", "t=17.040 node=scout_1 event=mission_stage role=scout stage=awaiting_sector");
  Feed(b, "scout_1", "t=18.000 node=scout_1 event=mission_stage role=scout stage=awaiting_sector");
  Feed(b, "scout_1", "t=40.000 node=scout_1 event=leader_elected term=3 leader=scout_1");
  Feed(b, "scout_2", "t=7.000 node=scout_2 event=leader_elected term=2 leader=scout_2");
  Feed(b, "scout_2", "t=30.000 node=scout_2 event=raft_stopped reason=crash");
  Feed(b, "physics", "t=50.000 node=physics event=clock rtf=1");
  const TrialSeries s = b.Finish();
  ASSERT_EQ(s.raft_leader.size(), 2u);
  const Lane& one = s.raft_leader[0];
  ASSERT_EQ(one.spans.size(), 2u);
  EXPECT_EQ(one.spans[0].label, "scout_2");
  EXPECT_DOUBLE_EQ(one.spans[0].t1_s, 40.0);
  EXPECT_EQ(one.spans[1].label, "scout_1");
  EXPECT_DOUBLE_EQ(one.spans[1].t1_s, 50.0);  // open until the trial's last time
  ASSERT_EQ(s.raft_leader[1].spans.size(), 1u);
  EXPECT_DOUBLE_EQ(s.raft_leader[1].spans[0].t1_s, 30.0);  // its Raft stopped
  ASSERT_EQ(s.raft_term.size(), 2u);
  EXPECT_DOUBLE_EQ(s.raft_term[0].points[1].value, 3.0);
  ASSERT_EQ(s.mission_stage.size(), 1u);
  ASSERT_EQ(s.mission_stage[0].spans.size(), 2u);  // a repeated stage extends its span
  EXPECT_EQ(s.mission_stage[0].spans[1].label, "awaiting_sector");
  EXPECT_DOUBLE_EQ(s.mission_stage[0].spans[0].t1_s, 17.04);
}

TEST(TrialSeries, BatteryAndTheLeadersFlockMetrics) {
  TrialSeriesBuilder b;
  Feed(b, "lifter", "t=1.000 node=lifter event=battery fraction=0.999");
  Feed(b, "lifter", "t=2.000 node=lifter event=battery fraction=0.997");
  Feed(b, "scout_2", "t=2.000 node=scout_2 event=flock_metrics members=4 order=0.5 safety=1 union=0.667");
  Feed(b, "scout_2", "t=3.000 node=scout_2 event=flock_metrics members=4 order=-0.25 safety=0.833 union=1");
  const TrialSeries s = b.Finish();
  ASSERT_EQ(s.battery.size(), 1u);
  EXPECT_DOUBLE_EQ(s.battery[0].points[1].value, 0.997);
  ASSERT_EQ(s.flock.size(), 3u);
  EXPECT_EQ(s.flock[0].name, "order");
  EXPECT_EQ(s.flock[1].name, "safety");
  EXPECT_EQ(s.flock[2].name, "union");
  EXPECT_DOUBLE_EQ(s.flock[0].points[1].value, -0.25);
  EXPECT_DOUBLE_EQ(s.flock[2].points[0].value, 0.667);
}

TEST(TrialPlots, EnvelopeIsMinMedianMaxPerTimeBin) {
  std::vector<Series> series = {
      {"a", {{0.5, 1}, {9.5, 10}}},
      {"b", {{0.2, 3}, {9.9, 20}}},
      {"c", {{0.9, 2}}},
  };
  const std::vector<EnvelopeBin> env = Envelope(series, 10.0, 10);
  ASSERT_EQ(env.size(), 2u);  // bins without a point are left out
  EXPECT_DOUBLE_EQ(env[0].t_s, 0.5);
  EXPECT_DOUBLE_EQ(env[0].min, 1);
  EXPECT_DOUBLE_EQ(env[0].median, 2);
  EXPECT_DOUBLE_EQ(env[0].max, 3);
  EXPECT_DOUBLE_EQ(env[1].t_s, 9.5);
  EXPECT_DOUBLE_EQ(env[1].median, 15);
  EXPECT_TRUE(Envelope(series, 0.0, 10).empty());
  // Held values (the Raft term): every bin from a series' first point on has its value.
  const std::vector<Series> terms = {{"a", {{0.5, 2}, {4.2, 3}}}, {"b", {{2.5, 2}}}};
  const std::vector<EnvelopeBin> held = Envelope(terms, 10.0, 10, /*step=*/true);
  ASSERT_EQ(held.size(), 10u);
  EXPECT_DOUBLE_EQ(held[0].max, 2);  // a only
  EXPECT_DOUBLE_EQ(held[2].min, 2);  // a and b
  EXPECT_DOUBLE_EQ(held[4].max, 3);  // a's term 3 from 4.2 s
  EXPECT_DOUBLE_EQ(held[9].median, 2.5);
}

TrialSeries SmallTrial() {
  TrialSeriesBuilder b;
  for (int k = 0; k <= 20; ++k) {
    b.OnTruth(Row(k, "scout_1", 0, 0, k, 1, 0, 0));
    b.OnTruth(Row(k, "scout_2", 6, 8, k, 0, 1, 0));
  }
  Feed(b, "scout_1", "t=3.000 node=scout_1 event=leader_elected term=2 leader=scout_2");
  Feed(b, "scout_1", "t=6.000 node=scout_1 event=link peer=scout_2 sent=10 received=9 rtt_ms_mean=120");
  Feed(b, "scout_1", "t=4.000 node=scout_1 event=mission_stage role=scout stage=taking_off");
  return b.Finish();
}

TEST(TrialPlots, EveryPanelDrawnOrSaysWhichEventsItLacks) {
  const std::vector<TrialPanel> panels = TrialPanels(SmallTrial());
  ASSERT_EQ(panels.size(), 10u);
  EXPECT_EQ(panels[0].caption, "altitude [m]");
  EXPECT_NE(panels[0].svg.find("<title>scout_1</title>"), std::string::npos);
  EXPECT_EQ(Count(panels[0].svg, "class='line'"), 2u);  // one line per drone
  EXPECT_EQ(panels[2].caption, "nearest neighbour [m]");
  EXPECT_FALSE(panels[3].svg.empty());                                          // radio loss
  EXPECT_NE(panels[6].svg.find("scout_1: scout_2 3-20 s"), std::string::npos);  // leader band
  EXPECT_TRUE(panels[7].svg.empty());
  EXPECT_EQ(panels[7].missing, "no event=battery in the logs");
  EXPECT_NE(panels[8].svg.find("taking_off"), std::string::npos);
  EXPECT_EQ(panels[9].missing, "no event=flock_metrics in the logs");
  // The time axis is the same on every panel: ticks 0..20 s.
  for (std::size_t i : {0u, 3u, 6u}) {
    EXPECT_NE(panels[i].svg.find(">20</text>"), std::string::npos) << panels[i].caption;
  }
}

TEST(TrialPlots, ManyDronesDrawTheSwarmsEnvelopeNotALinePerDrone) {
  TrialSeriesBuilder b;
  for (int k = 0; k <= 10; ++k) {
    for (int d = 0; d < 12; ++d) b.OnTruth(Row(k, "scout_" + std::to_string(d), d * 5.0, 0, 30, 7, 0, 0));
  }
  const std::vector<TrialPanel> panels = TrialPanels(b.Finish());
  EXPECT_EQ(Count(panels[0].svg, "class='line'"), 0u);
  EXPECT_EQ(Count(panels[0].svg, "class='band'"), 1u);
  EXPECT_NE(panels[0].svg.find("<title>median of 12</title>"), std::string::npos);
  EXPECT_NE(panels[0].caption.find("12 series"), std::string::npos);
}

TEST(TrialPlots, ThePageIsSelfContainedDeterministicAndEscaped) {
  TrialPlotsPage page;
  page.title = "sar <search>";
  page.summary = "success: matched 'event=mission_complete'";
  page.has_trajectories = true;
  const std::string html = TrialPlotsHtml(page, SmallTrial());
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<title>sar &lt;search&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("matched &#39;event=mission_complete&#39;"), std::string::npos);
  EXPECT_NE(html.find("src='trajectories.png'"), std::string::npos);
  EXPECT_NE(html.find("no event=battery in the logs"), std::string::npos);
  EXPECT_EQ(Count(html, "<svg"), 8u);  // 10 panels, battery and flocking without events
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http"), std::string::npos) << "no external resource";
  EXPECT_EQ(html, TrialPlotsHtml(page, SmallTrial()));
}

TEST(ReportHtml, TheTrialTableLinksEachTrialsPlots) {
  TrialRecord with;
  with.folder = "e-a-r1";
  with.meta.id = "e-a-r1";
  with.outcome = "success";
  with.has_plots = true;
  TrialRecord without = with;
  without.folder = without.meta.id = "e-a-r2";
  without.has_plots = false;
  const std::string html = ReportHtml("e", {}, {with, without});
  EXPECT_NE(html.find("<th>over time</th>"), std::string::npos);
  EXPECT_NE(html.find("<a href='e-a-r1/plots.html'>plots</a>"), std::string::npos);
  EXPECT_EQ(html.find("e-a-r2/plots.html"), std::string::npos);
}

}  // namespace
}  // namespace swarmbox::report
