// ReplayTrial (perception_scenes.hpp): a trial folder's camera frames rendered again from its
// truth.csv. A synthetic folder: one victim at the origin, scout_1 flying a straight line over it
// at 30 m and 5 m/s (10 Hz truth rows), the lifter below the height window. And scene sets on
// generated worlds, which the trainer and the bench also render.
#include <cstdio>
#include <filesystem>
#include <fstream>
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

}  // namespace
}  // namespace swarmbox::swarm
