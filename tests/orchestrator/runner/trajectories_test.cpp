#include "swarmbox/runner/trajectories.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace swarmbox::runner {
namespace {

namespace fs = std::filesystem;

TEST(ParseTruthCsv, GroupsRowsByDroneInFirstSeenOrder) {
  auto tracks = ParseTruthCsv(
      "t_s,drone,x_m,y_m,z_m\n0.0,scout_2,1,2,0\n0.0,scout_1,0,0,0\n0.1,scout_2,1.5,2.5,0.2\n");
  ASSERT_TRUE(tracks) << tracks.error().ToString();
  ASSERT_EQ(tracks->size(), 2u);
  EXPECT_EQ((*tracks)[0].first, "scout_2");
  ASSERT_EQ((*tracks)[0].second.size(), 2u);
  EXPECT_DOUBLE_EQ((*tracks)[0].second[1].y_m, 2.5);
}

TEST(ParseTruthCsv, ReportsBadRowsByLine) {
  auto missing = ParseTruthCsv("time,drone\n");
  ASSERT_FALSE(missing);
  EXPECT_EQ(missing.error().ToString(), "truth.csv:1: truth.csv header lacks t_s, drone, x_m or y_m");
  auto short_row = ParseTruthCsv("t_s,drone,x_m,y_m\n0,a,1,2\n0,a,1\n");
  ASSERT_FALSE(short_row);
  EXPECT_EQ(short_row.error().ToString(), "truth.csv:3: expected 4 columns, got 3");
  auto nan = ParseTruthCsv("t_s,drone,x_m,y_m\n0,a,east,2\n");
  ASSERT_FALSE(nan);
  EXPECT_EQ(nan.error().where(), "truth.csv:2");
}

TEST(LoadWorldPicture, ReadsTheShippedWorld) {
  auto w = LoadWorldPicture(std::string(SWARMBOX_SOURCE_DIR) + "/trials/worlds/open_field.yaml");
  ASSERT_TRUE(w) << w.error().ToString();
  EXPECT_DOUBLE_EQ(w->size_x_m, 200);
  ASSERT_EQ(w->victims.size(), 2u);
  EXPECT_EQ(w->victims[1].id, "victim_2");
  EXPECT_DOUBLE_EQ(w->victims[1].x_m, -42.0);
}

TEST(DrawTrajectories, WritesAPng) {
  WorldPicture world;
  world.obstacles.push_back({10, 10, 4, 2, 30});
  world.victims.push_back({"victim_1", 35, 20});
  std::vector<std::pair<std::string, std::vector<TrackPoint>>> tracks = {
      {"scout_1", {{0, 0, 0}, {1, 10, 5}, {2, 30, 18}}},
      {"lifter", {{0, 0, -10}, {1, 5, -5}}}};
  const fs::path png = fs::temp_directory_path() / "swarmbox-trajectories-test.png";
  fs::remove(png);
  auto s = DrawTrajectories(tracks, world, {{"scout_1", 34, 19, true}}, png.string(), 400);
  ASSERT_TRUE(s) << s.error().ToString();
  std::ifstream in(png, std::ios::binary);
  char magic[8] = {};
  in.read(magic, 8);
  EXPECT_EQ(std::string(magic + 1, 3), "PNG");
  EXPECT_GT(fs::file_size(png), 2000u);
  fs::remove(png);
}

TEST(DrawTrajectories, UnwritablePathIsAnError) {
  auto s = DrawTrajectories({}, WorldPicture{}, {}, "/nonexistent/dir/t.png", 100);
  ASSERT_FALSE(s);
  EXPECT_EQ(s.error().code(), ErrorCode::kIo);
}

}  // namespace
}  // namespace swarmbox::runner
