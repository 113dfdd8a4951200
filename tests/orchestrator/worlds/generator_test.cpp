// Generated search areas: deterministic per seed, different across seeds, and what they generate
// is a world the physics server accepts with what the recipe asked for.
#include "swarmbox/worlds/generator.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <set>
#include <string>

#include "perception_scenes.hpp"
#include "swarmbox/physics/world_config.hpp"

namespace swarmbox::worlds {
namespace {

Result<GenerateSpec> ParseText(const std::string& text) {
  auto doc = yaml::Parse(text, "t.yaml");
  if (!doc) return doc.error();
  return ParseGenerateSpec(*doc);
}

physics::WorldConfig Generated(const GenerateSpec& spec, std::uint64_t seed) {
  auto text = GenerateWorld(spec, seed);
  EXPECT_TRUE(text.ok()) << text.error().ToString();
  auto doc = yaml::Parse(text.ok() ? *text : std::string(), "generated.yaml");
  EXPECT_TRUE(doc.ok());
  auto world = physics::ParseWorld(*doc, "generated.yaml");
  EXPECT_TRUE(world.ok()) << world.error().ToString() << "\n" << (text.ok() ? *text : "");
  return world.ok() ? *world : physics::WorldConfig{};
}

TEST(WorldGenerator, SameSeedSameWorldOtherSeedOtherWorld) {
  const GenerateSpec spec{.kind = WorldKind::kRubbleField, .size_m = {200, 150}, .victims = 4, .obstacles = 30, .distractors = 25};
  EXPECT_EQ(*GenerateWorld(spec, 7), *GenerateWorld(spec, 7));
  EXPECT_NE(*GenerateWorld(spec, 7), *GenerateWorld(spec, 8));
  const physics::WorldConfig a = Generated(spec, 7), b = Generated(spec, 8);
  ASSERT_EQ(a.victims.size(), 4u);
  ASSERT_EQ(b.victims.size(), 4u);
  EXPECT_NE(a.victims[0].x_m, b.victims[0].x_m);
  EXPECT_NE(a.ground_texture_seed, b.ground_texture_seed);
}

TEST(WorldGenerator, EveryKindMakesAValidWorldWithWhatWasAskedFor) {
  for (WorldKind kind : {WorldKind::kRubbleField, WorldKind::kForestEdge, WorldKind::kOpenField}) {
    SCOPED_TRACE(std::string(KindName(kind)));
    const GenerateSpec spec{.kind = kind, .size_m = {240, 200}, .victims = 6, .obstacles = 40, .distractors = 30};
    const physics::WorldConfig w = Generated(spec, 42);
    EXPECT_DOUBLE_EQ(w.size_x_m, 240);
    EXPECT_DOUBLE_EQ(w.size_y_m, 200);
    ASSERT_EQ(w.victims.size(), 6u);
    EXPECT_EQ(w.obstacles.size(), 40u);
    EXPECT_EQ(w.distractors.size(), 30u);
    ASSERT_TRUE(w.terrain.has_value());
    ASSERT_TRUE(w.lighting.has_value());
    EXPECT_EQ(w.terrain->kind, kind == WorldKind::kRubbleField ? physics::TerrainKind::kRubble
                               : kind == WorldKind::kForestEdge ? physics::TerrainKind::kMixed
                                                                : physics::TerrainKind::kGrass);
    int trees = 0;
    for (const physics::ObstacleBox& o : w.obstacles) {
      trees += o.kind == physics::ObstacleKind::kTree ? 1 : 0;
      // Inside the geofence, out of the launch area, standing on the ground.
      EXPECT_LE(std::abs(o.center_m.x) + o.size_m.x / 2, 120.0);
      EXPECT_LE(std::abs(o.center_m.y) + o.size_m.y / 2, 100.0 + 1e-9);
      EXPECT_GE(std::hypot(o.center_m.x, o.center_m.y), 15.0);
      EXPECT_NEAR(o.center_m.z, o.size_m.z / 2, 0.01);
    }
    if (kind == WorldKind::kForestEdge) {
      EXPECT_GT(trees, 30);
    }
    if (kind == WorldKind::kRubbleField) {
      EXPECT_LT(trees, 15);
    }
    std::set<std::string> ids;
    for (std::size_t i = 0; i < w.victims.size(); ++i) {
      const physics::Victim& v = w.victims[i];
      ids.insert(v.id);
      EXPECT_TRUE(v.clothing_bgr.has_value());
      EXPECT_LE(v.cover, 0.6);
      for (std::size_t j = 0; j < i; ++j) {
        EXPECT_GE(std::hypot(v.x_m - w.victims[j].x_m, v.y_m - w.victims[j].y_m), 8.0) << v.id;
      }
      for (const physics::ObstacleBox& o : w.obstacles) {  // 3 m clear of the obstacle's disc
        EXPECT_GE(std::hypot(v.x_m - o.center_m.x, v.y_m - o.center_m.y), std::hypot(o.size_m.x, o.size_m.y) / 2 + 3.0 + 1.0 - 0.01);
      }
    }
    EXPECT_EQ(ids.size(), 6u);
  }
}

TEST(WorldGenerator, PosesAndClothesVaryAcrossVictims) {
  const GenerateSpec spec{.kind = WorldKind::kOpenField, .size_m = {400, 400}, .victims = 40, .obstacles = 10, .distractors = 0};
  const physics::WorldConfig w = Generated(spec, 3);
  std::set<physics::VictimPose> poses;
  std::set<physics::Bgr> clothes;
  for (const physics::Victim& v : w.victims) {
    poses.insert(v.pose);
    clothes.insert(*v.clothing_bgr);
  }
  EXPECT_EQ(poses.size(), 4u);
  EXPECT_GE(clothes.size(), 8u);
}

// The detector's training scenes (tools/train_detector perception_scenes.hpp) draw tarps and
// backpacks from the palettes below; a generated world must hold no colour outside them.
TEST(WorldGenerator, TarpsAndBackpacksComeInTheColoursTheDetectorIsTrainedOn) {
  auto in = [](const physics::Bgr& c, const auto& palette) {
    return std::find(std::begin(palette), std::end(palette), c) != std::end(palette);
  };
  std::set<physics::Bgr> seen;
  for (WorldKind kind : {WorldKind::kRubbleField, WorldKind::kForestEdge, WorldKind::kOpenField}) {
    for (std::uint64_t seed = 1; seed <= 8; ++seed) {
      const physics::WorldConfig w =
          Generated({.kind = kind, .size_m = {200, 200}, .victims = 4, .obstacles = 10, .distractors = 60}, seed);
      for (const physics::Distractor& d : w.distractors) {
        if (d.kind == physics::DistractorKind::kTarp) {
          EXPECT_TRUE(in(d.colour_bgr, perception_scenes::kTarpColours)) << KindName(kind) << " seed " << seed;
          seen.insert(d.colour_bgr);
        }
        if (d.kind == physics::DistractorKind::kBackpack) {
          EXPECT_TRUE(in(d.colour_bgr, perception_scenes::kBackpackColours)) << KindName(kind) << " seed " << seed;
          seen.insert(d.colour_bgr);
        }
      }
    }
  }
  EXPECT_EQ(seen.size(), std::size(perception_scenes::kTarpColours) + std::size(perception_scenes::kBackpackColours));
}

TEST(WorldGenerator, AnAreaTooSmallForTheVictimsSaysSo) {
  const GenerateSpec spec{.kind = WorldKind::kOpenField, .size_m = {40, 40}, .victims = 60, .obstacles = 0, .distractors = 0};
  auto text = GenerateWorld(spec, 1);
  ASSERT_FALSE(text.ok());
  EXPECT_NE(text.error().message().find("no spot for victim"), std::string::npos) << text.error().message();
}

TEST(WorldGenerator, SeedComesFromTheTrialUnlessGiven) {
  GenerateSpec spec;
  EXPECT_EQ(WorldSeed(spec, 1), WorldSeed(spec, 1));
  EXPECT_NE(WorldSeed(spec, 1), WorldSeed(spec, 2));
  spec.seed = 99;
  EXPECT_EQ(WorldSeed(spec, 1), 99u);
  EXPECT_EQ(WorldSeed(spec, 2), 99u);
}

TEST(WorldGeneratorSpec, ParsesTheRecipeAndItsDefaults) {
  auto spec = ParseText("{generate: forest_edge, size_m: [300, 250], victims: 5, obstacles: 80, distractors: 12, seed: 4}");
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  EXPECT_EQ(spec->kind, WorldKind::kForestEdge);
  EXPECT_EQ(spec->size_m, (std::array<double, 2>{300, 250}));
  EXPECT_EQ(spec->victims, 5);
  EXPECT_EQ(spec->obstacles, 80);
  EXPECT_EQ(spec->distractors, 12);
  EXPECT_EQ(spec->seed, std::optional<std::uint64_t>(4));
  auto defaults = ParseText("{generate: open_field}");
  ASSERT_TRUE(defaults.ok());
  EXPECT_FALSE(defaults->seed.has_value());
  EXPECT_EQ(defaults->victims, 4);
  // The node round-trips.
  auto again = ParseGenerateSpec(ToNode(*spec));
  ASSERT_TRUE(again.ok()) << again.error().ToString();
  EXPECT_EQ(again->kind, spec->kind);
  EXPECT_EQ(again->size_m, spec->size_m);
  EXPECT_EQ(again->seed, spec->seed);
}

TEST(WorldGeneratorSpec, BadRecipesNameTheirKey) {
  struct Case {
    const char* text;
    const char* message;
  };
  const Case cases[] = {
      {"{generate: volcano}", "generate 'volcano' is not one of rubble_field|forest_edge|open_field"},
      {"{size_m: [100, 100]}", "generate"},
      {"{generate: open_field, size_m: [10, 100]}", "size_m must be [X, Y] in metres, each 40..2000"},
      {"{generate: open_field, size_m: [100]}", "size_m must be [X, Y]"},
      {"{generate: open_field, victims: -1}", "victims must be 0..100"},
      {"{generate: open_field, obstacles: 5000}", "obstacles must be 0..2000"},
      {"{generate: open_field, trees: 5}", "unknown key 'trees'"},
  };
  for (const Case& c : cases) {
    auto spec = ParseText(c.text);
    ASSERT_FALSE(spec.ok()) << c.text;
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos) << spec.error().message();
  }
}

}  // namespace
}  // namespace swarmbox::worlds
