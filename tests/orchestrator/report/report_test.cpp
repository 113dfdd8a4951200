// Per-trial metrics from events and truth samples, results.csv, report.html and box-plot
// statistics (pure), and reading a trial folder written here (temp dir).
#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <cmath>

#include "swarmbox/common/version.hpp"
#include "swarmbox/report/plot_axis.hpp"
#include "swarmbox/report/provenance.hpp"
#include "swarmbox/report/report_html.hpp"
#include "swarmbox/report/results_csv.hpp"
#include "swarmbox/report/trial_metrics.hpp"
#include "swarmbox/report/trial_record.hpp"

namespace swarmbox::report {
namespace {

void Feed(TrialMetrics& m, std::string_view component, std::string_view line) {
  m.OnLogEvent(component, ParseLogfmt(line));
}

TEST(TrialMetrics, EmptyLogsGiveEmptyCellsNotZeros) {
  TrialMetrics m;
  MetricValues v = m.Values();
  ASSERT_EQ(v.size(), MetricNames().size());
  for (const auto& [name, value] : v) EXPECT_FALSE(value.has_value()) << name;
  TrialMetrics with_physics;
  with_physics.SawPhysicsLog();
  EXPECT_EQ(with_physics.Values()["collisions"], 0.0);
}

TEST(TrialMetrics, MissionDetectionsCollisionsAndRadio) {
  TrialMetrics m;
  m.SawPhysicsLog();
  Feed(m, "scout_1", "t=5.000 node=scout_1 event=mission_state phase=search");
  Feed(m, "scout_1", "t=41.200 node=scout_1 event=victim_detected victim=v1 x=10 y=20");
  Feed(m, "scout_2", "t=38.900 node=scout_2 event=victim_detected victim=v2 x=1 y=2");
  Feed(m, "scout_2", "t=44.000 node=scout_2 event=victim_confirmed victim=v2");
  Feed(m, "scout_1", "t=45.000 node=scout_1 event=victim_detected victim=v2");
  Feed(m, "physics", "t=50.000 node=physics event=collision a=scout_1 b=scout_2");
  Feed(m, "lifter", "t=300.500 node=lifter event=mission_complete");
  Feed(m, "scout_1", "t=10 node=scout_1 event=link peer=scout_2 loss=0.10 rtt_ms_mean=210.0");
  Feed(m, "scout_2", "t=10 node=scout_2 event=link peer=scout_1 loss=0.00 rtt_ms_mean=190.0");
  Feed(m, "scout_2", "t=50 node=scout_2 event=sighting_reported seq=7 x=1 y=2 confidence=0.9");
  Feed(m, "scout_2", "not an event line");
  MetricValues v = m.Values();
  EXPECT_EQ(v["mission_time_s"], 300.5);
  EXPECT_EQ(v["first_detection_s"], 38.9);
  EXPECT_EQ(v["detections"], 2.0);
  EXPECT_EQ(v["victims_confirmed"], 1.0);
  EXPECT_EQ(v["collisions"], 1.0);
  EXPECT_DOUBLE_EQ(*v["radio_rtt_ms"], 200.0);
  EXPECT_DOUBLE_EQ(*v["radio_loss"], 0.05);
  EXPECT_FALSE(v["leader_changes"].has_value());
  EXPECT_FALSE(v["min_separation_m"].has_value());
}

TEST(TrialMetrics, VictimsAsTheAgentsLogThemMatchTheEndingLine) {
  // agent/raft node_driver.cpp: every node logs what it applies, the victim by `id`.
  TrialMetrics m;
  for (const char* node : {"scout_1", "lifter"}) {
    const std::string n(node);
    Feed(m, n, "t=30.1 node=" + n + " event=victim_confirmed id=1 x=40.0 y=12.0 index=17");
    Feed(m, n, "t=52.7 node=" + n + " event=victim_confirmed id=2 x=-35.0 y=60.0 index=31");
    Feed(m, n, "t=90.0 node=" + n + " event=victim_status id=1 status=being_rescued rescuer=lifter index=40");
    Feed(m, n, "t=140.0 node=" + n + " event=victim_status id=1 status=rescued index=55");
    Feed(m, n, "t=210.0 node=" + n + " event=victim_status id=2 status=rescued index=80");
  }
  Feed(m, "scout_3", "t=25.0 node=scout_3 event=sighting_reported seq=1 x=40.1 y=11.8 confidence=0.9");
  Feed(m, "scout_3", "t=257.3 node=scout_3 event=mission_complete victims=2 rescued=2");
  MetricValues v = m.Values();
  EXPECT_EQ(v["victims_confirmed"], 2.0);
  EXPECT_EQ(v["victims_rescued"], 2.0);
  EXPECT_EQ(v["detections"], 2.0);
  EXPECT_EQ(v["first_detection_s"], 25.0);
  EXPECT_EQ(v["mission_time_s"], 257.3);
}

TEST(TrialMetrics, FalseVictimsAreConfirmedFarFromEveryVictimOfTheWorld) {
  TrialMetrics m;
  Feed(m, "scout_1", "t=5 node=scout_1 event=mission_state state=search index=3");
  Feed(m, "scout_1", "t=30 node=scout_1 event=victim_confirmed id=1 x=40.0 y=12.0 index=17");
  Feed(m, "scout_1", "t=52 node=scout_1 event=victim_confirmed id=2 x=-35.0 y=60.0 index=31");
  Feed(m, "scout_1", "t=60 node=scout_1 event=victim_confirmed id=3 x=0.0 y=0.0 index=35");
  Feed(m, "scout_1", "t=140 node=scout_1 event=victim_status id=1 status=rescued index=55");
  Feed(m, "scout_1", "t=150 node=scout_1 event=victim_status id=3 status=rescued index=57");
  Feed(m, "scout_2", "t=70 node=scout_2 event=rejected candidate=4 reason=belief decided_belief=0.1");
  Feed(m, "scout_3", "t=71 node=scout_3 event=rejected candidate=4 reason=belief decided_belief=0.1");
  Feed(m, "scout_3", "t=80 node=scout_3 event=rejected candidate=6 reason=undecided decided_belief=0.5");
  // Without the world's victims the false ones are unknown, not zero.
  MetricValues unknown = m.Values();
  EXPECT_EQ(unknown["false_alarms_rejected"], 2.0);
  EXPECT_FALSE(unknown["false_victims_confirmed"].has_value());
  EXPECT_FALSE(unknown["false_victims_rescued"].has_value());
  m.OnWorldVictim(41.0, 13.5);   // victim 1, 1.8 m away
  m.OnWorldVictim(-35.0, 57.5);  // victim 2, 2.5 m away
  m.OnWorldVictim(3.0, 0.5);     // 3.04 m from the confirmed victim 3: that one is false
  MetricValues v = m.Values();
  EXPECT_EQ(v["victims_confirmed"], 3.0);
  EXPECT_EQ(v["false_victims_confirmed"], 1.0);
  EXPECT_EQ(v["false_victims_rescued"], 1.0);
  EXPECT_EQ(v["false_alarms_rejected"], 2.0);
  EXPECT_EQ(v["victims_missed"], 2.0);  // victim 2 was confirmed, not rescued; the third has no true find
  EXPECT_FALSE(unknown["victims_missed"].has_value());
}

TEST(TrialMetrics, RadioFiguresAreWeightedByPingsAndVictimsKnownById) {
  TrialMetrics m;
  // The agents' format: counts per window; a window with nothing answered has no RTT.
  Feed(m, "a", "t=12 node=a event=link peer=b sent=6 received=0 loss=1.0000 late=0 dup=0");
  Feed(m, "a", "t=13 node=a event=link peer=b sent=10 received=9 loss=0.1 rtt_ms_mean=200 rtt_ms_p50=199");
  Feed(m, "b", "t=13 node=b event=link peer=a sent=4 received=3 loss=0.25 rtt_ms_mean=100");
  Feed(m, "lifter", "t=77 node=lifter event=victim_confirmed id=1 x=35.6 y=19.6 index=12");
  Feed(m, "scout_1", "t=75 node=scout_1 event=victim_confirmed id=1 x=35.6 y=19.6 index=12");
  Feed(m, "scout_1", "t=72.5 node=scout_1 event=sighting_reported seq=4405 x=-42.9 y=54.6");
  Feed(m, "scout_1", "t=86 node=scout_1 event=victim_confirmed id=2 x=-42.7 y=54.7 index=20");
  MetricValues v = m.Values();
  EXPECT_DOUBLE_EQ(*v["radio_loss"], 8.0 / 20.0);
  EXPECT_DOUBLE_EQ(*v["radio_rtt_ms"], (200.0 * 9 + 100.0 * 3) / 12.0);
  EXPECT_EQ(v["detections"], 2.0);
  EXPECT_EQ(v["victims_confirmed"], 2.0);
  EXPECT_EQ(v["first_detection_s"], 72.5);
}

TEST(TrialMetrics, LeaderChangesAndFailoverFromTheLeadersStop) {
  TrialMetrics m;
  // Every node logs the same election; term 2 re-elects scout_1 (no change), term 3 after its stop.
  for (const char* node : {"scout_1", "scout_2", "scout_3"}) {
    Feed(m, node, std::string("t=2.000 node=") + node + " event=leader_elected term=1 leader=scout_1");
  }
  Feed(m, "scout_2", "t=9.000 node=scout_2 event=leader_elected term=2 leader=scout_1");
  Feed(m, "scout_1", "t=30.000 node=scout_1 event=raft_stopped");
  Feed(m, "scout_3", "t=32.400 node=scout_3 event=leader_elected term=3 leader=scout_3");
  Feed(m, "scout_2", "t=32.500 node=scout_2 event=leader_elected term=3 leader=scout_3");
  MetricValues v = m.Values();
  EXPECT_EQ(v["leader_changes"], 1.0);
  ASSERT_TRUE(v["failover_s"].has_value());
  EXPECT_NEAR(*v["failover_s"], 2.4, 1e-9);
}

TEST(TrialMetrics, FailoverFromAFaultOnTheLeaderAndNoneWhenAFollowerStops) {
  TrialMetrics m;
  Feed(m, "a", "t=1 node=a event=leader_elected term=1 leader=a");
  Feed(m, "b", "t=20 node=b event=stopped");  // a follower: no failover
  m.OnOrchestratorEvent("fault", "raft_leader", 40.0);
  Feed(m, "b", "t=41.5 node=b event=leader_elected term=2 leader=b");
  MetricValues v = m.Values();
  EXPECT_NEAR(*v["failover_s"], 1.5, 1e-9);
}

TEST(TrialMetrics, MinSeparationComparesDronesAtTheSameTime) {
  TrialMetrics m;
  m.OnTruth(0.0, "a", 0, 0, 0);
  m.OnTruth(0.0, "b", 3, 4, 0);   // 5 m
  m.OnTruth(0.1, "a", 0, 0, 1);
  m.OnTruth(0.1, "b", 0, 2, 1);   // 2 m
  m.OnTruth(0.2, "a", 0, 0, 0);   // alone at t=0.2
  EXPECT_DOUBLE_EQ(*m.Values()["min_separation_m"], 2.0);
}

TrialRecord Record(std::string id, std::string code, std::vector<std::string> levels,
                   std::string outcome, double wall) {
  TrialRecord r;
  r.folder = id;
  r.meta.id = std::move(id);
  r.meta.code = std::move(code);
  r.meta.levels = std::move(levels);
  r.meta.repetition = 1;
  r.meta.seed = 7;
  r.host = "local";
  r.outcome = std::move(outcome);
  r.wall_s = wall;
  r.sim_s = 60;
  for (const std::string& m : MetricNames()) r.metrics[m] = std::nullopt;
  return r;
}

TEST(ResultsCsv, ContractColumnsQuotingAndEmptyCells) {
  TrialRecord r = Record("e-ab-r1", "ab", {"0.05", "three, spread"}, "timeout", 12.25);
  r.reason = "sim time \"60 s\" reached";
  r.metrics["collisions"] = 0;
  r.metrics["radio_rtt_ms"] = 201.5;
  const std::string csv = ResultsCsv({"loss", "swarm"}, {r});
  const std::string header =
      "trial_id,code,loss,swarm,repetition,seed,host,outcome,reason,wall_s,sim_s,mission_time_s,"
      "first_detection_s,detections,victims_confirmed,min_separation_m,collisions,leader_changes,"
      "failover_s,radio_rtt_ms,radio_loss,victims_rescued,false_alarms_rejected,false_victims_confirmed,"
      "false_victims_rescued,victims_missed,swarmbox_version,swarmbox_commit,"
      "build_type,images,docker_version,docker_api_version,kernel,fault_mechanism,rtf_requested,"
      "rtf_achieved,host_name\n";
  ASSERT_EQ(csv.substr(0, header.size()), header);
  EXPECT_EQ(csv.substr(header.size()),
            "e-ab-r1,ab,0.05,\"three, spread\",1,7,local,timeout,\"sim time \"\"60 s\"\" reached\","
            "12.25,60,,,,,,0,,,201.5,,,,,,,,,,,,,,,,,\n");
  EXPECT_EQ(CsvNumber(0.1 + 0.2), "0.3");
  EXPECT_EQ(CsvNumber(3), "3");
}

TEST(ResultsCsv, ProvenanceColumnsFollowTheMetrics) {
  TrialRecord r = Record("e-a-r1", "a", {"0"}, "success", 10);
  r.provenance.swarmbox_version = "0.1.0";
  r.provenance.swarmbox_commit = "1a2b3c4d5e6f-dirty";
  r.provenance.build_type = "RelWithDebInfo";
  r.provenance.images = {"swarmbox/agent:aa11", "swarmbox/physics:bb22"};
  r.provenance.engine = {"20.10.24+dfsg1", "1.41", "6.1.0-18-amd64"};
  r.provenance.fault_mechanism = "userspace-nfqueue";
  r.provenance.rtf_requested = 0;
  r.provenance.rtf_achieved = 2.5;
  r.provenance.host_name = "lab-3";
  const std::string csv = ResultsCsv({"loss"}, {r});
  const std::string row = csv.substr(csv.find('\n') + 1);
  EXPECT_NE(row.find(",0.1.0,1a2b3c4d5e6f-dirty,RelWithDebInfo,swarmbox/agent:aa11 swarmbox/physics:bb22,"
                     "20.10.24+dfsg1,1.41,6.1.0-18-amd64,userspace-nfqueue,0,2.5,lab-3\n"),
            std::string::npos)
      << row;
  // Round trip through result.json's object.
  const Provenance back = ParseProvenance(ProvenanceNode(r.provenance));
  EXPECT_EQ(ProvenanceCells(back), ProvenanceCells(r.provenance));
  EXPECT_EQ(ProvenanceCells(ParseProvenance(yaml::Node::Mapping())).size(), ProvenanceColumns().size());
}

TEST(Provenance, LocalIsThisBuildAndMachine) {
  const Provenance p = LocalProvenance();
  EXPECT_EQ(p.swarmbox_version, std::string(Build().version));
  EXPECT_EQ(p.swarmbox_commit, std::string(Build().commit));
  EXPECT_FALSE(p.swarmbox_version.empty());
  EXPECT_FALSE(p.host_name.empty());
}

TEST(PlotAxis, NiceStepsFollowTheOneTwoFiveSeries) {
  EXPECT_DOUBLE_EQ(NiceStep(0.0238), 0.05);
  EXPECT_DOUBLE_EQ(NiceStep(0.02), 0.02);
  EXPECT_DOUBLE_EQ(NiceStep(0.2), 0.2);
  EXPECT_DOUBLE_EQ(NiceStep(3), 5);
  EXPECT_DOUBLE_EQ(NiceStep(7), 10);
  EXPECT_DOUBLE_EQ(NiceStep(1), 1);
  EXPECT_DOUBLE_EQ(NiceStep(140), 200);
}

TEST(PlotAxis, RatesAndCountsStartAtZeroWithRoundTicks) {
  // The example report's loss: 0.0078..0.1169 (drew -0.0119 .. 0.13 before).
  const PlotAxis loss = ChooseAxis(0.007763, 0.11691, AxisKindOf("radio_loss"));
  EXPECT_DOUBLE_EQ(loss.lo, 0);
  EXPECT_DOUBLE_EQ(loss.step, 0.05);
  EXPECT_DOUBLE_EQ(loss.hi, 0.15);
  EXPECT_EQ(loss.Ticks(), (std::vector<double>{0, 0.05, 0.1, 0.15}));
  // Every collisions value 0 (drew -0.55 .. 0.55 before).
  const PlotAxis none = ChooseAxis(0, 0, AxisKindOf("collisions"));
  EXPECT_EQ(none.Ticks(), (std::vector<double>{0, 1}));
  // Counts step by whole numbers.
  const PlotAxis detections = ChooseAxis(2, 2, AxisKindOf("detections"));
  EXPECT_DOUBLE_EQ(detections.lo, 0);
  for (double t : detections.Ticks()) EXPECT_EQ(t, std::round(t));
  EXPECT_GE(detections.hi, 2);
  const PlotAxis changes = ChooseAxis(0, 3, AxisKindOf("leader_changes"));
  EXPECT_EQ(changes.Ticks(), (std::vector<double>{0, 1, 2, 3}));
  // A rate never passes 1.
  EXPECT_DOUBLE_EQ(ChooseAxis(0.2, 0.97, AxisKindOf("radio_loss")).hi, 1.0);
}

TEST(PlotAxis, TimesKeepTheirRangeOnRoundTicksAndNeverGoBelowZero) {
  const PlotAxis mission = ChooseAxis(239.112, 261.848, AxisKindOf("mission_time_s"));
  EXPECT_DOUBLE_EQ(mission.step, 10);  // 5 would take 7 ticks
  EXPECT_DOUBLE_EQ(mission.lo, 230);
  EXPECT_DOUBLE_EQ(mission.hi, 270);
  EXPECT_EQ(mission.Ticks(), (std::vector<double>{230, 240, 250, 260, 270}));
  const PlotAxis near_zero = ChooseAxis(0.4, 9.7, AxisKindOf("failover_s"));
  EXPECT_DOUBLE_EQ(near_zero.lo, 0);
  const PlotAxis one = ChooseAxis(210.9, 210.9, AxisKindOf("radio_rtt_ms"));
  EXPECT_LE(one.lo, 210.9);
  EXPECT_GE(one.hi, 210.9);
  EXPECT_GE(one.lo, 0);
  for (double t : one.Ticks()) EXPECT_NEAR(t / one.step, std::round(t / one.step), 1e-9);
}

TEST(ReportHtml, BoxPlotTicksAreRoundAndNeverBelowZero) {
  std::vector<TrialRecord> records = {
      Record("e-a-r1", "a", {"0"}, "success", 10),
      Record("e-a-r2", "a", {"0"}, "success", 11),
      Record("e-b-r1", "b", {"0.05"}, "success", 12),
  };
  records[0].metrics["collisions"] = 0;
  records[1].metrics["collisions"] = 0;
  records[2].metrics["collisions"] = 0;
  records[0].metrics["radio_loss"] = 0.007763;
  records[1].metrics["radio_loss"] = 0.011596;
  records[2].metrics["radio_loss"] = 0.11691;
  for (const ReportPlot& p : ReportPlots({"loss"}, records)) {
    EXPECT_EQ(p.svg.find(">-"), std::string::npos) << p.metric << ": a negative tick\n" << p.svg;
    if (p.metric == "collisions") {
      EXPECT_NE(p.svg.find("text-anchor='end'>0</text>"), std::string::npos) << p.svg;
      EXPECT_NE(p.svg.find("text-anchor='end'>1</text>"), std::string::npos) << p.svg;
      EXPECT_EQ(p.svg.find("text-anchor='end'>0.5</text>"), std::string::npos) << p.svg;
    }
    if (p.metric == "radio_loss") {
      EXPECT_NE(p.svg.find("text-anchor='end'>0.05</text>"), std::string::npos) << p.svg;
    }
  }
}

TEST(BoxStats, TukeyQuartilesWhiskersAndOutliers) {
  BoxStats b = ComputeBoxStats({1, 2, 3, 4, 5, 6, 7, 8, 100});
  EXPECT_EQ(b.n, 9u);
  EXPECT_DOUBLE_EQ(b.q1, 3);
  EXPECT_DOUBLE_EQ(b.median, 5);
  EXPECT_DOUBLE_EQ(b.q3, 7);
  EXPECT_DOUBLE_EQ(b.whisker_low, 1);
  EXPECT_DOUBLE_EQ(b.whisker_high, 8);
  ASSERT_EQ(b.outliers.size(), 1u);
  EXPECT_DOUBLE_EQ(b.outliers[0], 100);
  BoxStats two = ComputeBoxStats({1, 2});
  EXPECT_DOUBLE_EQ(two.median, 1.5);
  EXPECT_DOUBLE_EQ(two.q1, 1.25);
  EXPECT_EQ(ComputeBoxStats({}).n, 0u);
}

TEST(ReportHtml, CountsPerLevelPlotsPerMetricAndLinksEveryTrial) {
  std::vector<TrialRecord> records = {
      Record("e-aa-r1", "aa", {"0", "3"}, "success", 10),
      Record("e-ab-r1", "ab", {"0", "<5>"}, "failure", 20),
      Record("e-ba-r1", "ba", {"0.2", "3"}, "success", 30),
  };
  records[0].has_trajectories = true;
  records[2].metrics["mission_time_s"] = 55;
  const std::string html = ReportHtml("exp <1>", {"loss", "swarm"}, records);
  EXPECT_EQ(html.rfind("<!DOCTYPE html>", 0), 0u);
  EXPECT_NE(html.find("<title>exp &lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("3 trials: <span class='success'>success 2</span>"), std::string::npos);
  EXPECT_NE(html.find("<td>b: &lt;5&gt;</td><td>0</td><td>1</td>"), std::string::npos);
  EXPECT_NE(html.find("<h3>wall_s</h3>"), std::string::npos);
  EXPECT_NE(html.find("<h3>mission_time_s</h3>"), std::string::npos);
  EXPECT_EQ(html.find("<h3>radio_rtt_ms</h3>"), std::string::npos);  // no trial has it
  EXPECT_NE(html.find("wall_s by loss"), std::string::npos);
  EXPECT_NE(html.find("<a href='e-aa-r1/trajectories.png'><img"), std::string::npos);
  EXPECT_NE(html.find("<a href='e-ab-r1/logs/'>logs</a>"), std::string::npos);
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("http://"), std::string::npos) << "self-contained: no external resource";
}

TEST(ReportHtml, PlotsAreThePagesBoxPlotsAndStandAloneAsFiles) {
  std::vector<TrialRecord> records = {
      Record("e-aa-r1", "aa", {"0", "3"}, "success", 10),
      Record("e-ba-r1", "ba", {"0.2", "3"}, "success", 30),
  };
  records[1].metrics["mission_time_s"] = 55;
  const std::vector<ReportPlot> plots = ReportPlots({"loss", "swarm size"}, records);
  // wall_s, sim_s and mission_time_s (reported by one trial), each by both factors, page order.
  ASSERT_EQ(plots.size(), 6u);
  EXPECT_EQ(plots[0].metric, "wall_s");
  EXPECT_EQ(plots[0].factor, "loss");
  EXPECT_EQ(plots[1].factor, "swarm size");
  EXPECT_EQ(plots[4].metric, "mission_time_s");
  EXPECT_EQ(PlotFileName(plots[1]), "wall_s_by_swarm_size.svg");
  const std::string html = ReportHtml("e", {"loss", "swarm size"}, records);
  for (const ReportPlot& p : plots) EXPECT_NE(html.find(p.svg), std::string::npos) << p.metric;
  const std::string file = StandalonePlotSvg(plots[4]);
  EXPECT_EQ(file.rfind("<?xml", 0), 0u);
  EXPECT_NE(file.find("<svg xmlns='http://www.w3.org/2000/svg' width="), std::string::npos);
  EXPECT_NE(file.find("<style>"), std::string::npos);
  EXPECT_NE(file.find("<title>mission_time_s by loss</title>"), std::string::npos);
  EXPECT_NE(file.find("n=1"), std::string::npos);
  EXPECT_EQ(file.find("<svg", file.find("<svg") + 1), std::string::npos);  // one root element
  EXPECT_NE(file.rfind("</svg>"), std::string::npos);
}

TEST(TrialRecordTest, ReadsResultMetaLogsAndTruthFromAFolder) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("swarmbox-record-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  const fs::path trial = dir / "e-ab-r2";
  fs::create_directories(trial / "logs");
  TrialMeta meta;
  meta.id = "e-ab-r2";
  meta.code = "ab";
  meta.factors = {"loss", "size"};
  meta.levels = {"0", "3"};
  meta.repetition = 2;
  meta.seed = 99;
  meta.attempts = 2;
  meta.hosts = {"root@10.250.0.2", "local"};
  std::ofstream(trial / "trial_meta.json") << TrialMetaJson(meta);
  std::ofstream(trial / "result.json")
      << R"({"trial":"e-ab-r2","outcome":"success","reason":"","wall_s":21.5,"sim_s":60.0,)"
      << R"("seed":99,"host":"local","metrics":{}})";
  std::ofstream(trial / "logs" / "physics.log") << "t=0.000 node=physics event=ready\n";
  std::ofstream(trial / "logs" / "scout_1.log")
      << "t=3.000 node=scout_1 event=leader_elected term=1 leader=scout_1\nplain text\n"
      << "t=9.000 node=scout_1 event=victim_confirmed id=1 x=10.5 y=-3.0 index=9\n"
      << "t=9.500 node=scout_1 event=victim_confirmed id=2 x=60.0 y=60.0 index=11\n";
  // The trial's world as the runner writes it (generated worlds): the victims' truth.
  std::ofstream(trial / "world.yaml") << "name: w\nvictims:\n  - {id: v1, x_m: 10.0, y_m: -2.0}\n"
                                         "  - {id: v2, x_m: -20.0, y_m: 5.0}\n";
  std::ofstream(trial / "truth.csv") << "t_s,drone,x_m,y_m,z_m,vx_m_s\n0,a,0,0,0,0\n0,b,0,6,8,0\n";
  fs::create_directories(dir / ".staging" / "e-aa-r1.1");
  fs::create_directories(dir / "e-ba-r1");  // no result.json: not a trial yet

  auto rec = ReadTrialFolder(trial.string());
  ASSERT_TRUE(rec) << rec.error().ToString();
  EXPECT_EQ(rec->meta.id, "e-ab-r2");
  EXPECT_EQ(rec->meta.hosts, meta.hosts);
  EXPECT_EQ(rec->meta.attempts, 2);
  EXPECT_EQ(rec->outcome, "success");
  EXPECT_EQ(rec->host, "local");
  EXPECT_EQ(rec->wall_s, 21.5);
  EXPECT_EQ(rec->metrics["collisions"], 0.0);
  EXPECT_EQ(rec->metrics["leader_changes"], 0.0);
  EXPECT_DOUBLE_EQ(*rec->metrics["min_separation_m"], 10.0);
  EXPECT_EQ(rec->metrics["victims_confirmed"], 2.0);
  EXPECT_EQ(rec->metrics["false_victims_confirmed"], 1.0);  // id 2: no victim near (60, 60)
  EXPECT_EQ(rec->metrics["false_victims_rescued"], 0.0);
  EXPECT_EQ(rec->metrics["victims_missed"], 2.0);  // nothing rescued
  EXPECT_FALSE(rec->has_trajectories);

  std::vector<std::string> problems;
  auto all = ReadExperimentFolder(dir.string(), &problems);
  ASSERT_EQ(all.size(), 1u);
  EXPECT_TRUE(problems.empty());
  EXPECT_EQ(FactorNames(dir.string(), all), (std::vector<std::string>{"loss", "size"}));
  // The title: the folder's name until experiment.json names the experiment.
  EXPECT_EQ(ExperimentTitle(dir.string()), dir.filename().string());
  std::ofstream(dir / "experiment.json") << R"({"name":"radio","factors":["loss","size"]})";
  EXPECT_EQ(ExperimentTitle(dir.string()), "radio");
  EXPECT_EQ(ExperimentTitle(dir.string() + "/"), "radio");
  fs::remove_all(dir);
}

TEST(TrialRecordTest, AFolderWithoutLogsKeepsTheMetricsItsResultStored) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("swarmbox-pruned-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir);
  std::ofstream(dir / "result.json")
      << R"({"trial":"t","outcome":"success","reason":"","wall_s":2,"sim_s":3,"seed":1,)"
      << R"("host":"local","metrics":{"victims_confirmed":2,"victims_rescued":2,"failover_s":null},)"
      << R"("provenance":{"swarmbox_version":"0.1.0","kernel":"6.1.0","rtf_requested":0}})";
  EXPECT_FALSE(ReadTrialMetrics(dir.string()).has_value());
  auto rec = ReadTrialFolder(dir.string());
  ASSERT_TRUE(rec) << rec.error().ToString();
  EXPECT_EQ(rec->metrics["victims_confirmed"], 2.0);
  EXPECT_EQ(rec->metrics["victims_rescued"], 2.0);
  EXPECT_FALSE(rec->metrics["failover_s"].has_value());
  EXPECT_EQ(rec->metrics.size(), MetricNames().size());
  EXPECT_EQ(rec->provenance.swarmbox_version, "0.1.0");
  EXPECT_EQ(rec->provenance.engine.kernel, "6.1.0");
  EXPECT_EQ(rec->provenance.rtf_requested, 0.0);
  fs::remove_all(dir);
}

TEST(TrialRecordTest, ProcessFaultRecordsCountForFailoverFromTheirApplication) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("swarmbox-failover-" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "logs");
  std::ofstream(dir / "result.json") << R"({"trial":"t","outcome":"success","seed":1})";
  std::ofstream(dir / "logs" / "scout_2.log")
      << "t=3.000 node=scout_2 event=leader_elected term=1 leader=scout_1\n"
      << "t=34.500 node=scout_2 event=leader_elected term=2 leader=scout_2\n";
  std::ofstream(dir / "events.jsonl")
      << R"({"type":"fault","phase":"requested","fault":"fault_1","kind":"kill","t_sim_s":30.0,"wall_s":9.0,"targets":["scout_1"]})"
      << "\n"
      << R"({"type":"fault","phase":"applied","fault":"fault_1","kind":"kill","t_sim_s":31.0,"wall_s":9.4,"targets":["scout_1"]})"
      << "\n";
  auto metrics = ReadTrialMetrics(dir.string());
  ASSERT_TRUE(metrics);
  ASSERT_TRUE((*metrics)["failover_s"].has_value());
  EXPECT_DOUBLE_EQ(*(*metrics)["failover_s"], 3.5);
  fs::remove_all(dir);
}

}  // namespace
}  // namespace swarmbox::report
