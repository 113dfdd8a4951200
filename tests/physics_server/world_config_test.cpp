#include "swarmbox/physics/world_config.hpp"

#include <gtest/gtest.h>

#include "test_util.hpp"

namespace swarmbox::physics {
namespace {

Result<WorldConfig> ParseText(const std::string& text) {
  auto doc = yaml::Parse(text, "w.yaml");
  if (!doc) return doc.error();
  return ParseWorld(*doc, "w.yaml");
}

TEST(WorldConfig, ShippedOpenFieldHasTwoVictimsAndNoObstacles) {
  auto w = LoadWorld(testing::WorldPath("open_field"));
  ASSERT_TRUE(w.ok()) << w.error().ToString();
  EXPECT_EQ(w->name, "open_field");
  EXPECT_TRUE(w->obstacles.empty());
  ASSERT_EQ(w->victims.size(), 2u);
  EXPECT_DOUBLE_EQ(w->victims[0].x_m, 35.0);
  EXPECT_NEAR(w->victims[0].heading_rad, 30.0 * 3.14159265358979 / 180.0, 1e-9);
}

TEST(WorldConfig, ShippedRubbleBlockHasObstaclesAndVictims) {
  auto w = LoadWorld(testing::WorldPath("rubble_block"));
  ASSERT_TRUE(w.ok()) << w.error().ToString();
  EXPECT_GE(w->obstacles.size(), 5u);
  EXPECT_GE(w->victims.size(), 3u);
  EXPECT_GT(w->wind.gust_std_m_s, 0.0);
}

TEST(WorldConfig, UnknownKeyIsReportedWithPosition) {
  auto w = ParseText("name: a\nvictims:\n  - {id: v, x_m: 1, y_m: 2, mood: calm}\n");
  ASSERT_FALSE(w.ok());
  EXPECT_EQ(w.error().where(), "w.yaml:3:29");
  EXPECT_NE(w.error().message().find("unknown key 'mood' in victim"), std::string::npos) << w.error().message();
}

TEST(WorldConfig, DuplicateObstacleIdIsRejected) {
  auto w = ParseText(
      "name: a\nobstacles:\n  - {id: b, center_m: [0, 0, 1], size_m: [1, 1, 2]}\n"
      "  - {id: b, center_m: [5, 0, 1], size_m: [1, 1, 2]}\n");
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message().find("duplicate obstacle id 'b'"), std::string::npos);
  EXPECT_EQ(w.error().where(), "w.yaml:4:10");
}

TEST(WorldConfig, VictimOutsideGeofenceIsRejected) {
  auto w = ParseText("name: a\ngeofence: {size_x_m: 10, size_y_m: 10}\nvictims: [{id: v, x_m: 6, y_m: 0}]\n");
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message().find("outside the geofence"), std::string::npos) << w.error().message();
}

TEST(WorldConfig, WrongTypeSaysWhatWasExpected) {
  auto w = ParseText("name: a\nwind: {mean_m_s: [1, 2]}\n");
  ASSERT_FALSE(w.ok());
  EXPECT_NE(w.error().message().find("expected a list of 3 values"), std::string::npos) << w.error().message();
  EXPECT_EQ(w.error().where(), "w.yaml:2:18");
}

TEST(WorldConfig, CameraWorldKeysAreReadWithTheirDefaults) {
  auto w = ParseText(
      "name: a\n"
      "lighting: {time_of_day_h: 17.5, overcast: 0.3}\n"
      "terrain: {kind: rubble, water_fraction: 0.1}\n"
      "obstacles:\n"
      "  - {id: oak, kind: tree, center_m: [5, 5, 4], size_m: [6, 6, 8]}\n"
      "  - {id: wall, center_m: [-5, 5, 1], size_m: [4, 1, 2]}\n"
      "victims:\n"
      "  - {id: v1, x_m: 1, y_m: 2, pose: curled, clothing_bgr: [40, 90, 60], cover: 0.4}\n"
      "  - {id: v2, x_m: 3, y_m: 2}\n"
      "distractors:\n"
      "  - {kind: tarp, x_m: 10, y_m: -3, heading_deg: 90}\n"
      "  - {kind: rock, x_m: -8, y_m: 1, size_m: 0.7, colour_bgr: [200, 210, 215]}\n");
  ASSERT_TRUE(w.ok()) << w.error().ToString();
  ASSERT_TRUE(w->lighting.has_value());
  EXPECT_DOUBLE_EQ(w->lighting->time_of_day_h, 17.5);
  EXPECT_DOUBLE_EQ(w->lighting->overcast, 0.3);
  ASSERT_TRUE(w->terrain.has_value());
  EXPECT_EQ(w->terrain->kind, TerrainKind::kRubble);
  EXPECT_DOUBLE_EQ(w->terrain->water_fraction, 0.1);
  ASSERT_EQ(w->obstacles.size(), 2u);
  EXPECT_EQ(w->obstacles[0].kind, ObstacleKind::kTree);
  EXPECT_EQ(w->obstacles[1].kind, ObstacleKind::kBox);
  ASSERT_EQ(w->victims.size(), 2u);
  EXPECT_EQ(w->victims[0].pose, VictimPose::kCurled);
  EXPECT_EQ(w->victims[0].clothing_bgr, (Bgr{40, 90, 60}));
  EXPECT_DOUBLE_EQ(w->victims[0].cover, 0.4);
  EXPECT_EQ(w->victims[1].pose, VictimPose::kLying);  // defaults: today's figure
  EXPECT_FALSE(w->victims[1].clothing_bgr.has_value());
  EXPECT_DOUBLE_EQ(w->victims[1].cover, 0.0);
  ASSERT_EQ(w->distractors.size(), 2u);
  EXPECT_EQ(w->distractors[0].kind, DistractorKind::kTarp);
  EXPECT_DOUBLE_EQ(w->distractors[0].size_m, DefaultSizeM(DistractorKind::kTarp));
  EXPECT_EQ(w->distractors[0].colour_bgr, DefaultColour(DistractorKind::kTarp));
  EXPECT_NEAR(w->distractors[0].heading_rad, 3.14159265358979 / 2, 1e-9);
  EXPECT_EQ(w->distractors[1].colour_bgr, (Bgr{200, 210, 215}));
  EXPECT_DOUBLE_EQ(w->distractors[1].size_m, 0.7);
}

TEST(WorldConfig, WithoutCameraKeysTheWorldKeepsTodaysLook) {
  auto w = LoadWorld(testing::WorldPath("open_field"));
  ASSERT_TRUE(w.ok()) << w.error().ToString();
  EXPECT_FALSE(w->lighting.has_value());
  EXPECT_FALSE(w->terrain.has_value());
  EXPECT_TRUE(w->distractors.empty());
}

TEST(WorldConfig, CameraWorldValuesAreChecked) {
  struct Case {
    const char* yaml;
    const char* message;
  };
  const Case cases[] = {
      {"name: a\nvictims: [{id: v, x_m: 1, y_m: 2, pose: dancing}]\n",
       "pose 'dancing' is not one of lying|sitting|curled|standing"},
      {"name: a\nvictims: [{id: v, x_m: 1, y_m: 2, cover: 1.5}]\n", "cover must be within 0..1"},
      {"name: a\nvictims: [{id: v, x_m: 1, y_m: 2, clothing_bgr: [0, 300, 0]}]\n", "must be 0..255 each"},
      {"name: a\nterrain: {kind: lava}\n", "kind 'lava' is not one of grass|soil|gravel|rubble|mixed"},
      {"name: a\nterrain: {kind: soil, water_fraction: 1}\n", "water_fraction must be within 0..1"},
      {"name: a\nlighting: {time_of_day_h: 25}\n", "time_of_day_h must be within 0..24"},
      {"name: a\nlighting: {overcast: -0.1}\n", "overcast must be within 0..1"},
      {"name: a\nobstacles: [{id: b, kind: bush, center_m: [0, 0, 1], size_m: [1, 1, 2]}]\n",
       "kind 'bush' is not one of box|tree"},
      {"name: a\ndistractors: [{kind: car, x_m: 0, y_m: 0}]\n", "kind 'car' is not one of tarp|cone|backpack|debris|rock"},
      {"name: a\ndistractors: [{kind: cone, x_m: 0, y_m: 0, size_m: -1}]\n", "size_m must be positive"},
      {"name: a\ngeofence: {size_x_m: 10, size_y_m: 10}\ndistractors: [{kind: cone, x_m: 0, y_m: 9}]\n",
       "cone distractor lies outside the geofence"},
  };
  for (const Case& c : cases) {
    auto w = ParseText(c.yaml);
    ASSERT_FALSE(w.ok()) << c.yaml;
    EXPECT_NE(w.error().message().find(c.message), std::string::npos) << w.error().message();
  }
}

}  // namespace
}  // namespace swarmbox::physics
