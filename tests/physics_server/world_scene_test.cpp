// MakeWorldScene: a trial world's patch as the stereo pair sees it (issue #23).
#include <gtest/gtest.h>

#include <cmath>
#include <optional>

#include "swarmbox/physics/world_scene.hpp"

namespace swarmbox::physics {
namespace {

constexpr std::uint64_t kSeed = 7;

// A rubble world with a 2 x 1 x 1.5 m box yawed 90 deg at (5, 0), a 3 m tree at (-6, 4) and a
// person lying (1.8 m, heading east) at (0, -5).
WorldConfig TestWorld(TerrainKind kind = TerrainKind::kRubble) {
  WorldConfig w;
  w.terrain = Terrain{kind, 0.0};
  w.obstacles.push_back({"box", {5, 0, 0.75}, {2, 1, 1.5}, M_PI / 2, ObstacleKind::kBox});
  w.obstacles.push_back({"tree", {-6, 4, 1.5}, {2, 2, 3}, 0, ObstacleKind::kTree});
  Victim v;
  v.id = "v1";
  v.x_m = 0;
  v.y_m = -5;
  v.height_m = 1.8;
  w.victims.push_back(v);
  return w;
}

float CellHeight(const StereoScene& s, double x, double y) {
  const int col = static_cast<int>(std::lround((x - s.origin_x_m) / s.cell_m));
  const int row = static_cast<int>(std::lround((y - s.origin_y_m) / s.cell_m));
  return s.height_m.at<float>(row, col);
}

TEST(WorldScene, BoxesTreesAndPeopleRaiseTheirFootprints) {
  const StereoScene s = MakeWorldScene(TestWorld(), 0, 0, 10, kSeed);
  EXPECT_FLOAT_EQ(CellHeight(s, 5, 0), 1.5f);
  // Yawed 90 deg: 2 m along world y, 1 m along world x.
  EXPECT_FLOAT_EQ(CellHeight(s, 5, 0.9), 1.5f);
  EXPECT_FLOAT_EQ(CellHeight(s, 5, 1.1), 0.0f);
  EXPECT_FLOAT_EQ(CellHeight(s, 5.4, 0), 1.5f);
  EXPECT_FLOAT_EQ(CellHeight(s, 5.6, 0), 0.0f);
  EXPECT_FLOAT_EQ(CellHeight(s, -6, 4), 3.0f);
  // The person: 1.8 m along the heading (east), 0.5 m across, 0.25 m high.
  EXPECT_FLOAT_EQ(CellHeight(s, 0.8, -5), static_cast<float>(kLyingVictimTop_m));
  EXPECT_FLOAT_EQ(CellHeight(s, 1.0, -5), 0.0f);
  EXPECT_FLOAT_EQ(CellHeight(s, 0, -5.3), 0.0f);
  EXPECT_FLOAT_EQ(CellHeight(s, 2, 2), 0.0f);  // open ground
  EXPECT_FLOAT_EQ(s.max_height_m, 3.0f);
  EXPECT_FLOAT_EQ(s.min_height_m, 0.0f);
  EXPECT_FLOAT_EQ(s.HeightAt(5, 0), 1.5f);
}

TEST(WorldScene, StandingPersonIsTallerThanLying) {
  WorldConfig w = TestWorld();
  w.victims[0].pose = VictimPose::kStanding;
  const StereoScene s = MakeWorldScene(w, 0, -5, 3, kSeed);
  EXPECT_FLOAT_EQ(CellHeight(s, 0, -5), 1.8f);
}

// A person lying on a 0.6 m rubble heap (a 3 x 3 m box) lies on its top, 0.25 m over it; one
// lying half over the heap's edge rests at the level of most of the body (the median of the
// cells under it): its 1.8 m body 1.2 m over the heap lies on the heap, 0.6 m of it beyond the
// edge at that level; on open ground, on the ground.
TEST(WorldScene, PeopleLieOnWhatIsUnderThem) {
  WorldConfig w = TestWorld();
  w.obstacles.push_back({"heap", {0, 5, 0.3}, {3, 3, 0.6}, 0, ObstacleKind::kBox});
  Victim on_top = w.victims[0];
  on_top.id = "on_top";
  on_top.x_m = 0;  // the body's centre: from -0.9 to 0.9 (heading east), wholly on the heap
  on_top.y_m = 5;
  Victim on_edge = on_top;
  on_edge.id = "on_edge";
  on_edge.x_m = 1.2;  // from 0.3 to 2.1: 1.2 m on the heap (to 1.5), 0.6 m off it
  on_edge.y_m = 6;
  w.victims.push_back(on_top);
  w.victims.push_back(on_edge);
  const StereoScene s = MakeWorldScene(w, 0, 0, 10, kSeed);
  const auto lying_on_heap = static_cast<float>(0.6 + kLyingVictimTop_m);
  EXPECT_FLOAT_EQ(CellHeight(s, 0, 5), lying_on_heap);
  EXPECT_FLOAT_EQ(CellHeight(s, 1.0, 6), lying_on_heap);
  EXPECT_FLOAT_EQ(CellHeight(s, 2.0, 6), lying_on_heap);  // off the heap, the body still at its level
  EXPECT_FLOAT_EQ(CellHeight(s, 1.0, 4), 0.6f);           // the heap beside them
  EXPECT_FLOAT_EQ(CellHeight(s, 0.8, -5), static_cast<float>(kLyingVictimTop_m));  // the first, on the ground
}

// The (row, col) of world (x, y) in a scene, if inside.
std::optional<cv::Point> CellOf(const StereoScene& s, double x, double y) {
  const auto col = static_cast<int>(std::lround((x - s.origin_x_m) / s.cell_m));
  const auto row = static_cast<int>(std::lround((y - s.origin_y_m) / s.cell_m));
  if (row < 0 || col < 0 || row >= s.height_m.rows || col >= s.height_m.cols) return std::nullopt;
  return cv::Point(col, row);
}

TEST(WorldScene, TwoPatchesAgreeWhereTheyOverlap) {
  const WorldConfig w = TestWorld(TerrainKind::kMixed);
  const StereoScene a = MakeWorldScene(w, 0, 0, 8, kSeed);
  const StereoScene b = MakeWorldScene(w, 5.03, -3.4, 8, kSeed);
  int compared = 0, raised = 0;
  for (double y = -12; y <= 5; y += 0.05) {
    for (double x = -3; x <= 9; x += 0.05) {
      const auto ca = CellOf(a, x, y), cb = CellOf(b, x, y);
      if (!ca || !cb) continue;
      ASSERT_EQ(a.height_m.at<float>(*ca), b.height_m.at<float>(*cb)) << x << ", " << y;
      ASSERT_EQ(a.albedo.at<float>(*ca), b.albedo.at<float>(*cb)) << x << ", " << y;
      ++compared;
      if (a.height_m.at<float>(*ca) > 0) ++raised;
    }
  }
  EXPECT_GT(compared, 10000);
  EXPECT_GT(raised, 100);  // the box and the person lie in the overlap
}

TEST(WorldScene, SameArgumentsSameSceneAnotherSeedAnotherTexture) {
  const WorldConfig w = TestWorld();
  const StereoScene a = MakeWorldScene(w, 1, 2, 6, kSeed);
  const StereoScene b = MakeWorldScene(w, 1, 2, 6, kSeed);
  const StereoScene c = MakeWorldScene(w, 1, 2, 6, kSeed + 1);
  EXPECT_EQ(cv::norm(a.albedo, b.albedo, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.height_m, b.height_m, cv::NORM_INF), 0.0);
  EXPECT_GT(cv::norm(a.albedo, c.albedo, cv::NORM_INF), 0.05);
}

double AlbedoStd(TerrainKind kind) {
  const StereoScene s = MakeWorldScene(TestWorld(kind), 0, 20, 4, kSeed);  // open ground only
  cv::Scalar mean, std;
  cv::meanStdDev(s.albedo, mean, std);
  return std[0];
}

TEST(WorldScene, RubbleAndGravelAreStronglyTexturedGrassWeakly) {
  const double grass = AlbedoStd(TerrainKind::kGrass);
  EXPECT_LT(grass, 0.03);
  EXPECT_GT(AlbedoStd(TerrainKind::kRubble), 3 * grass);
  EXPECT_GT(AlbedoStd(TerrainKind::kGravel), 3 * grass);
}

TEST(WorldScene, AmbientFollowsTheSunAndOvercastLowersItTowardsShade) {
  WorldConfig w;
  EXPECT_DOUBLE_EQ(WorldAmbientWm2(w), kSunInBandWm2);  // no lighting: a clear noon
  w.lighting = Lighting{12.0, 0.0};
  EXPECT_NEAR(WorldAmbientWm2(w), kSunInBandWm2, 1e-9);
  w.lighting = Lighting{12.0, 1.0};
  EXPECT_NEAR(WorldAmbientWm2(w), kSunInBandWm2 * kShadeFraction, 1e-9);
  w.lighting = Lighting{8.0, 0.0};
  const double morning = WorldAmbientWm2(w);
  EXPECT_LT(morning, kSunInBandWm2);
  EXPECT_GT(morning, kSunInBandWm2 * kShadeFraction);
  const StereoScene s = MakeWorldScene(w, 0, 0, 1, kSeed);
  EXPECT_FLOAT_EQ(s.ambient_w_m2.at<float>(3, 3), static_cast<float>(morning));
}

}  // namespace
}  // namespace swarmbox::physics
