// ReplayTrial (perception_scenes.hpp): a trial folder's camera frames rendered again from its
// truth.csv. A synthetic folder: one victim at the origin, scout_1 flying a straight line over it
// at 30 m and 5 m/s (10 Hz truth rows), the lifter below the height window. And scene sets on
// generated worlds, which the trainer and the bench also render.
#include <array>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <optional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "perception_score.hpp"

namespace swarmbox::swarm {
namespace {

using perception_scenes::ReplayFrame;
using perception_scenes::ReplayTrial;

constexpr const char* kHeader =
    "t_s,drone,x_m,y_m,z_m,vx_m_s,vy_m_s,vz_m_s,qw,qx,qy,qz,p_rad_s,q_rad_s,r_rad_s,w0_rad_s,payload_attached,"
    "payload_swing_rad,crashed,lost";

class ReplayFolder : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("swarmbox_replay_" + std::to_string(::testing::UnitTest::GetInstance()->random_seed()) + "_" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
    std::ofstream(dir_ / "world.yaml") << "name: replay\ngeofence: {size_x_m: 200, size_y_m: 200}\n"
                                          "ground_texture_seed: 7\nobstacles: []\nvictims:\n"
                                          "  - {id: victim_1, x_m: 0.0, y_m: 0.0, heading_deg: 90}\n";
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  // scout_1 from x = -30 to +30 m at 30 m, 0.5 m a row; the lifter hovers at 5 m.
  void WriteTruth(const std::string& header) {
    std::ofstream f(dir_ / "truth.csv");
    f << header << "\n";
    for (int k = 0; k <= 120; ++k) {
      char row[256];
      std::snprintf(row, sizeof row, "%.3f,scout_1,%.3f,0,30,5,0,0,1,0,0,0,0,0,0,0,0,0,0,0\n", 0.1 * k, -30 + 0.5 * k);
      f << row;
      std::snprintf(row, sizeof row, "%.3f,lifter,0,0,5,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0\n", 0.1 * k);
      f << row;
    }
  }
  std::filesystem::path dir_;
};

TEST_F(ReplayFolder, TakesAFrameEveryTriggerDistanceAndSeesTheVictimUnderTheCamera) {
  WriteTruth(kHeader);
  std::vector<double> xs;
  int half_visible = 0;
  double visible_at_nadir = -1;
  const Status st = ReplayTrial({.trial_dir = dir_.string()}, [&](const physics::WorldConfig& w, const ReplayFrame& f) {
    EXPECT_EQ(f.drone, "scout_1");
    ASSERT_EQ(w.victims.size(), 1u);
    ASSERT_EQ(f.scene.victims.size(), 1u);
    EXPECT_NEAR(f.scene.altitude_m, 30.0, 0.1);
    xs.push_back(f.scene.true_pose.position_m.x());
    half_visible += f.scene.victims[0].visible_fraction >= 0.5 ? 1 : 0;
    if (std::abs(f.scene.true_pose.position_m.x()) < 0.1) visible_at_nadir = f.scene.victims[0].visible_fraction;
  });
  ASSERT_TRUE(st.ok()) << st.error().ToString();
  // The x500's trigger_distance_m is 3 m: -30, -27, ..., +30.
  ASSERT_EQ(xs.size(), 21u);
  for (std::size_t i = 0; i < xs.size(); ++i) EXPECT_NEAR(xs[i], -30.0 + 3.0 * static_cast<double>(i), 0.1);
  // Straight below the camera the whole figure is seen; the along-track footprint (23 m at 30 m)
  // holds it in about 7 of the 3 m frames, never in the frames 15 m or more away.
  EXPECT_GT(visible_at_nadir, 0.95);
  EXPECT_GE(half_visible, 6);
  EXPECT_LE(half_visible, 9);
}

// A revisit's close look: scout_1 hovers at 18 m over the victim for 2 s (10 Hz rows). The
// camera takes a frame once trigger_interval_max_s (0.5 s) has passed without moving, on its
// 5 Hz grid (every 0.6 s), as the physics server's trigger does; with `thermal` each carries its
// thermal frame, in which the person is warmer than the rubble around it.
TEST_F(ReplayFolder, AHoverTakesAFrameEveryIntervalWithItsThermalFrame) {
  {
    std::ofstream f(dir_ / "truth.csv");
    f << kHeader << "\n";
    for (int k = 0; k <= 20; ++k) {
      char row[256];
      std::snprintf(row, sizeof row, "%.3f,scout_1,0,0,18,0,0,0,1,0,0,0,0,0,0,0,0,0,0,0\n", 0.1 * k);
      f << row;
    }
  }
  std::vector<double> ts;
  std::vector<double> contrasts;
  const Status st = ReplayTrial(
      {.trial_dir = dir_.string(), .thermal = true}, [&](const physics::WorldConfig&, const ReplayFrame& f) {
        ts.push_back(f.t_s);
        ASSERT_TRUE(f.scene.thermal.has_value());
        const std::optional<double> c = ThermalContrastAt(perception_scenes::ThermalViewOf(*f.scene.thermal),
                                                          Eigen::Vector3d::Zero(), 0.7);
        ASSERT_TRUE(c.has_value());
        contrasts.push_back(*c);
      });
  ASSERT_TRUE(st.ok()) << st.error().ToString();
  ASSERT_EQ(ts.size(), 4u);  // t = 0, 0.6, 1.2, 1.8
  for (std::size_t i = 0; i < ts.size(); ++i) EXPECT_NEAR(ts[i], 0.6 * static_cast<double>(i), 1e-6);
  for (double c : contrasts) EXPECT_GT(c, 2.0);
}

TEST_F(ReplayFolder, RefusesAFolderWithoutTruthOrWithoutItsColumns) {
  int frames = 0;
  auto count = [&](const physics::WorldConfig&, const ReplayFrame&) { ++frames; };
  const Status missing = ReplayTrial({.trial_dir = dir_.string()}, count);
  ASSERT_FALSE(missing.ok());
  EXPECT_EQ(missing.error().code(), ErrorCode::kNotFound);
  WriteTruth("t_s,drone,x_m,y_m,z_m");
  const Status columns = ReplayTrial({.trial_dir = dir_.string()}, count);
  ASSERT_FALSE(columns.ok());
  EXPECT_EQ(columns.error().code(), ErrorCode::kInvalidArgument);
  EXPECT_NE(columns.error().ToString().find("qw"), std::string::npos) << columns.error().ToString();
  EXPECT_EQ(frames, 0);
}

}  // namespace
}  // namespace swarmbox::swarm

namespace swarmbox::swarm {
namespace {

// Scene sets on generated search areas (SceneSetParams::generated): the mission's rubble fields,
// four people each, seeded like any scene set.
TEST(GeneratedScenes, ComeFromTheMissionsRubbleFieldsAndRepeatWithTheSeed) {
  testing::SceneSetParams p{.seed = 5, .scenes = 4, .scenes_per_world = 2, .min_altitude_m = 30, .max_altitude_m = 30,
                            .near_victim_fraction = 1.0, .near_victim_offset = 0.2};
  p.generated = testing::SarRubbleSpec();
  Result<std::vector<testing::Scene>> a = testing::RenderScenes(p);
  ASSERT_TRUE(a.ok()) << a.error().ToString();
  Result<std::vector<testing::Scene>> b = testing::RenderScenes(p);
  ASSERT_TRUE(b.ok()) << b.error().ToString();
  ASSERT_EQ(a->size(), 4u);
  for (std::size_t i = 0; i < a->size(); ++i) {
    const testing::Scene& s = (*a)[i];
    ASSERT_EQ(s.victims.size(), 4u);
    double seen = 0;
    for (const auto& v : s.victims) {
      EXPECT_LE(std::abs(v.position_m.x()), 80.0);  // inside the 160 x 160 m field
      EXPECT_LE(std::abs(v.position_m.y()), 80.0);
      seen = std::max(seen, v.visible_fraction);
    }
    EXPECT_GT(seen, 0.0) << "scene " << i << " is centred near a person";
    EXPECT_EQ(s.image.bgr, (*b)[i].image.bgr) << "scene " << i;
  }
  // Two worlds: the third scene's people are not the first's.
  EXPECT_NE((*a)[0].victims[0].position_m, (*a)[2].victims[0].position_m);
}

// The close looks of a trial's decided candidates (`swarmbox-bench perception --looks`): per look,
// people's candidates apart from false ones, a candidate decided twice counted once; and the same
// candidates decided again on their own records.
std::vector<LogfmtFields> DecisionLines() {
  return {
      ParseLogfmt("t=5 node=scout_1 event=mission_stage stage=searching"),
      // A person's candidate (2 m from victim (10, 10)): a 30 m view, a close miss, a close 0.93.
      ParseLogfmt(
          "t=60 node=scout_2 event=confirmed candidate=1 x=11.5 y=11.3 drones=scout_1,scout_2,scout_2 "
          "confidences=0.900,0.000,0.930 viewers=0:0:30.0,11:11:18.0,11.2:11:19.5 view_t=10,30,50"),
      // A false one far from both victims: close 0.55 and a miss; decided again by a later leader
      // with one more close miss (the last record counts).
      ParseLogfmt("t=70 node=scout_2 event=rejected candidate=2 x=50 y=50 drones=scout_1,scout_3,scout_3 "
                  "confidences=0.700,0.550,0.000 viewers=40:40:30,50:50:18,50:50:18 view_t=12,40,60"),
      ParseLogfmt(
          "t=90 node=scout_3 event=rejected candidate=2 x=50 y=50 drones=scout_1,scout_3,scout_3,scout_1 "
          "confidences=0.700,0.550,0.000,0.000 viewers=40:40:30,50:50:18,50:50:18,50:50:18 "
          "view_t=12,40,60,80"),
      // Search views only: a candidate, no close look.
      ParseLogfmt("t=95 node=scout_3 event=rejected candidate=3 x=-30 y=0 drones=scout_3 confidences=0.600 "
                  "viewers=-30:0:30 view_t=20"),
      // Not an evidence record (the lists disagree): skipped.
      ParseLogfmt("t=96 node=scout_3 event=rejected candidate=4 x=5 y=5 drones=scout_3 confidences=0.6,0.7 "
                  "viewers=5:5:30 view_t=20"),
  };
}

TEST(CloseLookTally, CountsThePeoplesAndTheFalseCandidatesCloseLooksFromTheDecisions) {
  const std::vector<Eigen::Vector2d> victims = {{10, 10}, {-80, -80}};
  const std::vector<testing::DecidedCandidate> decided =
      testing::DecidedCandidates(DecisionLines(), victims, 5.0);
  ASSERT_EQ(decided.size(), 3u);
  EXPECT_EQ(decided[1].candidate.views.size(), 4u);  // the later leader's record
  EXPECT_EQ(decided[0].candidate.views[2].viewer_height_m, 19.5);
  EXPECT_FALSE(decided[0].candidate.views[1].detected);
  const testing::CloseLookTally t = testing::TallyCloseLooks(decided, 21.0);
  EXPECT_EQ(t.real_candidates, 1);
  EXPECT_EQ(t.false_candidates, 2);
  EXPECT_EQ(t.real_looks, 2);
  EXPECT_EQ(t.real_detected, 1);
  EXPECT_DOUBLE_EQ(t.close_recall(), 0.5);
  EXPECT_EQ(t.false_looks, 3);
  EXPECT_EQ(t.false_detected, 1);
  EXPECT_DOUBLE_EQ(t.close_false_repeat(), 1.0 / 3.0);
  EXPECT_EQ(t.real_bins, (std::array<int, 5>{0, 0, 0, 0, 1}));   // 0.93
  EXPECT_EQ(t.false_bins, (std::array<int, 5>{1, 0, 0, 0, 0}));  // 0.55
  testing::CloseLookTally sum = t;
  sum.Add(t);
  EXPECT_EQ(sum.real_looks, 4);
  EXPECT_EQ(sum.false_bins[0], 2);
}

TEST(CloseLookTally, RedecidesEachCandidateOnItsOwnRecord) {
  const std::vector<testing::DecidedCandidate> decided =
      testing::DecidedCandidates(DecisionLines(), {{10, 10}}, 5.0);
  FusionParams p{.close_look_height_m = 21.0};
  // The person: 0.9 from 30 m (capped at 9:1), a close miss (-2.25: 0.46), then 0.93 close
  // (2.2 + 2.59: 0.99) confirms. The false one: 0.7 from 30 m, 0.55 close (0.85 + 0.2: 0.74, no
  // confirmation), then a miss: the best close detection still counts alone, the record ends open
  // ... unless max_revisits ends it: 2 revisits done, undecided, rejected. The third: one view,
  // undecided (no miss, no close look).
  p.max_revisits = 3;
  testing::Redecision r = testing::Redecide(decided, p);
  EXPECT_EQ(r.real_confirmed, 1);
  EXPECT_EQ(r.false_confirmed, 0);
  EXPECT_EQ(r.false_rejected, 1);  // 3 close looks = 3 revisits: undecided, rejected
  EXPECT_EQ(r.false_open, 1);
  EXPECT_EQ(r.same, 2);
  // A prior of 0.9 (9:1 before any view): the false one's 0.7 from 30 m and 0.55 close give
  // 2.2 + 0.85 + 0.2 (0.96) and confirm it at its second view.
  p.prior = 0.9;
  r = testing::Redecide(decided, p);
  EXPECT_EQ(r.real_confirmed, 1);
  EXPECT_EQ(r.false_confirmed, 1);
  EXPECT_EQ(r.false_open, 1);
  EXPECT_EQ(r.same, 1);
}

}  // namespace
}  // namespace swarmbox::swarm
