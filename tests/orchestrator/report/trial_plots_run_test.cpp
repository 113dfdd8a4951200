// plots.html of a real trial folder: the logs of a `swarmbox run trials/sar_search.yaml` with the
// agents that log event=battery and event=flock_metrics, and its truth.csv at the plots' 1 Hz
// (data/sar_plots; its README says how it was written and trimmed). Every panel is drawn from the
// folder's files, the figures agree with what the run's result.json says, and `swarmbox report`'s
// path (ReadTrialFolder, WriteTrialPlots, ReportHtml) links the page.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "swarmbox/report/report_html.hpp"
#include "swarmbox/report/trial_plots.hpp"
#include "swarmbox/report/trial_record.hpp"

namespace swarmbox::report {
namespace {

namespace fs = std::filesystem;

std::string ReadFile(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

class SarTrialPlots : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = fs::temp_directory_path() / ("swarmbox-plots-run-" + std::to_string(::getpid()));
    fs::remove_all(root_);
    dir_ = root_ / "sar-search-r1";
    fs::create_directories(root_);
    fs::copy(fs::path(SWARMBOX_SOURCE_DIR) / "tests/orchestrator/report/data/sar_plots", dir_,
             fs::copy_options::recursive);
  }
  void TearDown() override { fs::remove_all(root_); }

  fs::path root_;
  fs::path dir_;
};

const Series* Named(const std::vector<Series>& list, const std::string& name) {
  for (const Series& s : list) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

TEST_F(SarTrialPlots, EverySeriesComesFromTheFolderAndAgreesWithTheRun) {
  bool found = false;
  const TrialSeries s = ReadTrialSeries(dir_.string(), &found);
  ASSERT_TRUE(found);
  // The run ended on the lifter's mission_complete at 221.504 s (result.json's sim_s); the
  // containers logged on for the few simulated seconds their stop took.
  EXPECT_GE(s.t_end_s, 221.504);
  EXPECT_LT(s.t_end_s, 221.504 + 10);
  const std::vector<std::string> drones = {"lifter", "scout_1", "scout_2", "scout_3"};
  for (const auto* list : {&s.altitude_m, &s.speed_m_s, &s.nearest_m, &s.radio_loss, &s.radio_rtt_ms,
                           &s.raft_term, &s.battery}) {
    ASSERT_EQ(list->size(), 4u);
    for (std::size_t i = 0; i < 4; ++i) EXPECT_EQ((*list)[i].name, drones[i]);
  }
  // Altitude: scouts search at 30 m above home (scout_2 returned in a higher layer), the lifter
  // transits at 10 m.
  for (const std::string scout : {"scout_1", "scout_2", "scout_3"}) {
    const Series* alt = Named(s.altitude_m, scout);
    double top = 0;
    for (const SeriesPoint& p : alt->points) top = std::max(top, p.value);
    EXPECT_GT(top, 29.0) << scout;
    EXPECT_LT(top, 43.0) << scout;
  }
  double lifter_top = 0;
  for (const SeriesPoint& p : Named(s.altitude_m, "lifter")->points)
    lifter_top = std::max(lifter_top, p.value);
  EXPECT_NEAR(lifter_top, 10.0, 1.5);
  // One sample per simulated second per drone.
  EXPECT_GE(s.altitude_m[0].points.size(), 220u);
  EXPECT_LE(s.altitude_m[0].points.size(), 226u);
  // The nearest neighbour at 1 Hz is never closer than the smallest separation at the physics
  // rate (result.json min_separation_m 2.943856).
  for (const Series& n : s.nearest_m) {
    for (const SeriesPoint& p : n.points) EXPECT_GE(p.value, 2.943856 - 1e-6) << n.name << " at " << p.t_s;
  }
  // Radio: a burst every 2 s of each agent's clock, RTT near the channel's ~200 ms (result.json
  // radio_rtt_ms 202.7), loss a fraction.
  for (const Series& rtt : s.radio_rtt_ms) {
    EXPECT_GE(rtt.points.size(), 100u) << rtt.name;
    for (const SeriesPoint& p : rtt.points) EXPECT_NEAR(p.value, 200.0, 40.0) << rtt.name;
  }
  for (const Series& loss : s.radio_loss) {
    for (const SeriesPoint& p : loss.points) {
      EXPECT_GE(p.value, 0.0);
      EXPECT_LE(p.value, 1.0);
    }
  }
  // Raft: one election (leader_changes 0), every node followed scout_2 in term 2 until it stopped.
  ASSERT_EQ(s.raft_leader.size(), 4u);
  for (const Lane& lane : s.raft_leader) {
    ASSERT_EQ(lane.spans.size(), 1u) << lane.name;
    EXPECT_EQ(lane.spans[0].label, "scout_2") << lane.name;
    EXPECT_LE(lane.spans[0].t1_s, s.t_end_s);
  }
  for (const Series& term : s.raft_term) EXPECT_EQ(term.points.back().value, 2.0) << term.name;
  // Battery once per simulated second, draining.
  for (const Series& b : s.battery) {
    EXPECT_GE(b.points.size(), 220u) << b.name;
    EXPECT_LT(b.points.back().value, b.points.front().value) << b.name;
    EXPECT_GT(b.points.back().value, 0.0);
    EXPECT_LE(b.points.front().value, 1.0);
  }
  // Mission stages: every drone took off; the scouts searched.
  ASSERT_EQ(s.mission_stage.size(), 4u);
  for (const Lane& lane : s.mission_stage) {
    EXPECT_TRUE(std::any_of(lane.spans.begin(), lane.spans.end(), [](const StateSpan& sp) {
      return sp.label.find("tak") != std::string::npos;
    })) << lane.name;
    for (std::size_t i = 1; i < lane.spans.size(); ++i)
      EXPECT_DOUBLE_EQ(lane.spans[i].t0_s, lane.spans[i - 1].t1_s);
  }
  for (const std::string scout : {"scout_1", "scout_2", "scout_3"}) {
    const Lane* lane = nullptr;
    for (const Lane& l : s.mission_stage) lane = l.name == scout ? &l : lane;
    ASSERT_NE(lane, nullptr);
    EXPECT_TRUE(std::any_of(lane->spans.begin(), lane->spans.end(), [](const StateSpan& sp) {
      return sp.label == "searching";
    })) << scout;
  }
  // Flocking: the leader's line once per simulated second (on a 1 s grid from its first, at the
  // first 10 Hz mission tick due), scores within their ranges.
  ASSERT_EQ(s.flock.size(), 3u);
  for (const Series& f : s.flock) {
    EXPECT_GE(f.points.size(), 200u) << f.name;
    for (std::size_t k = 0; k < f.points.size(); ++k) {
      EXPECT_NEAR(f.points[k].t_s, f.points[0].t_s + static_cast<double>(k), 0.15) << f.name << " #" << k;
    }
    for (const SeriesPoint& p : f.points) {
      EXPECT_GE(p.value, f.name == "order" ? -1.0 : 0.0);
      EXPECT_LE(p.value, 1.0);
    }
  }
}

TEST_F(SarTrialPlots, TheReportWritesAndLinksThePageAndKeepsAPrunedFoldersOwn) {
  TrialPlotsPage page;
  page.title = "sar-search";
  auto written = WriteTrialPlots(dir_.string(), page);
  ASSERT_TRUE(written) << written.error().ToString();
  EXPECT_TRUE(*written);
  const std::string html = ReadFile(dir_ / "plots.html");
  EXPECT_EQ(html, TrialPlotsHtml(page, ReadTrialSeries(dir_.string())));
  // Every panel drawn: none says what it lacks.
  EXPECT_EQ(html.find("no event="), std::string::npos);
  EXPECT_EQ(html.find("no truth.csv"), std::string::npos);
  for (const TrialPanel& p : TrialPanels(ReadTrialSeries(dir_.string()))) {
    EXPECT_FALSE(p.svg.empty()) << p.caption;
  }
  EXPECT_FALSE(fs::exists(dir_ / ".plots.html.tmp"));

  auto rec = ReadTrialFolder(dir_.string());
  ASSERT_TRUE(rec) << rec.error().ToString();
  EXPECT_TRUE(rec->has_plots);
  EXPECT_NE(ReportHtml("e", {}, {*rec}).find("<a href='sar-search-r1/plots.html'>plots</a>"),
            std::string::npos);

  // A folder whose logs and truth.csv were pruned (docs/example-report) keeps the page it has.
  const fs::path pruned = root_ / "pruned";
  fs::create_directories(pruned);
  fs::copy_file(dir_ / "result.json", pruned / "result.json");
  written = WriteTrialPlots(pruned.string(), page);
  ASSERT_TRUE(written);
  EXPECT_FALSE(*written);
  EXPECT_FALSE(fs::exists(pruned / "plots.html"));
  std::ofstream(pruned / "plots.html") << "kept";
  EXPECT_FALSE(*WriteTrialPlots(pruned.string(), page));
  EXPECT_EQ(ReadFile(pruned / "plots.html"), "kept");
}

}  // namespace
}  // namespace swarmbox::report
