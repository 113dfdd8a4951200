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

}  // namespace
}  // namespace swarmbox::physics
