// Drone groups (`count:`), `world_size_m` and their overrides (dsl/README.md "Drone groups"): a group expands
// to <name>_1 .. <name>_N on a grid; errors are file:line:col at the key (cases as data).
#include "swarmbox/dsl/drone_groups.hpp"

#include <gtest/gtest.h>

#include <set>
#include <string>
#include <vector>

#include "swarmbox/dsl/trial_loader.hpp"

namespace swarmbox::dsl {
namespace {

constexpr const char* kGroupTrial = R"(name: swarm
world: worlds/open_field.yaml
world_size_m: [300, 240]
drones:
  - {name: scout, count: 5, airframe: x500, pose: [10, 20, 0], spacing_m: 3, limits: {memory_mib: 64}}
  - {name: lifter, airframe: x8_heavy, pose: [0, -10, 0], payload: stretcher}
timeout: {sim: 60s}
)";

LoadOptions FakeTree(std::vector<std::string> overrides = {}) {
  LoadOptions o;
  o.trials_dir = "/trials";
  o.overrides = std::move(overrides);
  o.file_exists = [](const std::string& p) {
    static const std::set<std::string> files = {"/trials/worlds/open_field.yaml", "/trials/airframes/x500.yaml",
                                                "/trials/airframes/x8_heavy.yaml"};
    return files.count(p) > 0;
  };
  return o;
}

// Replaces the first occurrence of `from` in kGroupTrial.
std::string With(const std::string& from, const std::string& to) {
  std::string text = kGroupTrial;
  const std::size_t at = text.find(from);
  EXPECT_NE(at, std::string::npos) << from;
  return at == std::string::npos ? text : text.replace(at, from.size(), to);
}

TEST(GroupGridPose, RowMajorOnCeilSqrtColumns) {
  // 5 drones: 3 columns; 100: 10; 1: a single column; 10: 4 (ceil(sqrt(10))).
  EXPECT_EQ(GroupGridPose({0, 0, 0}, 4, 5, 0), (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(GroupGridPose({0, 0, 0}, 4, 5, 2), (std::array<double, 3>{8, 0, 0}));
  EXPECT_EQ(GroupGridPose({0, 0, 0}, 4, 5, 3), (std::array<double, 3>{0, 4, 0}));
  EXPECT_EQ(GroupGridPose({1, 2, 3}, 4, 100, 99), (std::array<double, 3>{37, 38, 3}));
  EXPECT_EQ(GroupGridPose({1, 2, 3}, 4, 100, 10), (std::array<double, 3>{1, 6, 3}));
  EXPECT_EQ(GroupGridPose({0, 0, 0}, 2, 1, 0), (std::array<double, 3>{0, 0, 0}));
  EXPECT_EQ(GroupGridPose({0, 0, 0}, 2, 10, 4), (std::array<double, 3>{0, 2, 0}));
}

TEST(DroneGroups, ExpandInOrderWithTheGroupsKeysAndMarks) {
  auto spec = LoadTrialText(kGroupTrial, "swarm.yaml", FakeTree());
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_EQ(spec->drones.size(), 6u);
  const std::vector<std::array<double, 3>> poses = {{10, 20, 0}, {13, 20, 0}, {16, 20, 0}, {10, 23, 0}, {13, 23, 0}};
  for (int i = 0; i < 5; ++i) {
    const DroneSpec& d = spec->drones[static_cast<std::size_t>(i)];
    EXPECT_EQ(d.name, "scout_" + std::to_string(i + 1));
    EXPECT_EQ(d.airframe, "x500");
    EXPECT_EQ(d.pose, poses[static_cast<std::size_t>(i)]) << d.name;
    EXPECT_EQ(d.limits.memory_mib, 64);
    EXPECT_EQ(d.mark.ToString(), "swarm.yaml:5:5");  // errors about scout_4 point at the group
  }
  EXPECT_EQ(spec->drones[5].name, "lifter");
  ASSERT_EQ(spec->groups.size(), 1u);
  EXPECT_EQ(spec->groups[0].name, "scout");
  EXPECT_EQ(spec->groups[0].count, 5);
  EXPECT_EQ(spec->world_size_m, (std::array<double, 2>{300, 240}));
  // The resolved document (trial.yaml) lists the drones, and reads back to the same trial.
  auto again = DecodeTrial(ToDocument(*spec), FakeTree());
  ASSERT_TRUE(again) << again.error().ToString();
  ASSERT_EQ(again->drones.size(), 6u);
  EXPECT_EQ(again->drones[3].pose, spec->drones[3].pose);
  EXPECT_EQ(again->world_size_m, spec->world_size_m);
  EXPECT_EQ(spec->document.Find("drones")->items().size(), 6u);
}

TEST(DroneGroups, DefaultSpacingIsFourMetresFromTheOrigin) {
  auto spec = LoadTrialText(With("pose: [10, 20, 0], spacing_m: 3, ", ""), "swarm.yaml", FakeTree());
  ASSERT_TRUE(spec) << spec.error().ToString();
  EXPECT_EQ(spec->drones[4].pose, (std::array<double, 3>{4, 4, 0}));
  EXPECT_FALSE(LoadTrialText(With("world_size_m: [300, 240]\n", ""), "swarm.yaml", FakeTree())->HasWorldSize());
}

TEST(DroneGroups, OverridesAddressTheGroupThenItsDrones) {
  auto spec = LoadTrialText(kGroupTrial, "swarm.yaml",
                            FakeTree({"drones.scout.count=50", "drones.scout_7.pose=[1,2,0]", "world_size_m=[420,420]"}));
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_EQ(spec->drones.size(), 51u);
  EXPECT_EQ(spec->drones[49].name, "scout_50");
  EXPECT_EQ(spec->drones[6].pose, (std::array<double, 3>{1, 2, 0}));
  EXPECT_EQ(spec->drones[7].pose, (std::array<double, 3>{10 + 3 * 7, 20, 0}));  // 8 columns
  EXPECT_EQ(spec->world_size_m, (std::array<double, 2>{420, 420}));
  ASSERT_EQ(spec->groups.size(), 1u);
  EXPECT_EQ(spec->groups[0].count, 50);
  // A drone past the group's end is not one of its drones.
  auto past = LoadTrialText(kGroupTrial, "swarm.yaml", FakeTree({"drones.scout_6.pose=[1,2,0]"}));
  ASSERT_FALSE(past);
  EXPECT_EQ(past.error().message(), "'drones.scout_6': no list item named 'scout_6'");
}

struct BadCase {
  const char* what;
  std::string from, to;
  std::string where;    // "line:col"
  std::string message;  // a part of it
};

TEST(DroneGroups, BadGroupsAndSizesFailAtTheKey) {
  const std::vector<BadCase> cases = {
      {"count 0", "count: 5", "count: 0", "5:26", "'count' must be an integer from 1 to 500"},
      {"count 501", "count: 5", "count: 501", "5:26", "from 1 to 500"},
      {"count not a number", "count: 5", "count: five", "5:26", "'count' must be an integer"},
      {"spacing 0", "spacing_m: 3", "spacing_m: 0", "5:75", "'spacing_m' must be a number > 0"},
      {"spacing without count", "payload: stretcher", "payload: stretcher, spacing_m: 2", "6:90",
       "'spacing_m' spaces the drones of a group: give 'count' too"},
      {"pose of two", "pose: [10, 20, 0]", "pose: [10, 20]", "5:51", "'pose' must be [x, y, z]"},
      {"clash with a drone", "name: lifter", "name: scout_4", "5:12",
       "group 'scout' (count 5) expands to 'scout_4', which is also the name of the drone at swarm.yaml:6:12"},
      {"two groups, one name", "name: lifter, airframe: x8_heavy,", "name: scout, count: 2, airframe: x8_heavy,",
       "6:12", "group 'scout' (count 2) expands to 'scout_1', which is also the name of the drone at swarm.yaml:5:12"},
      {"expanded names too long", "name: scout,", "name: scout_with_a_very_long_name_xyz,", "5:12",
       "drone name 'scout_with_a_very_long_name_xyz_1' must be 1-32 characters"},
      {"over 200 drones", "count: 5", "count: 200", "5:3", "at most 200 drones per trial"},
      {"world size of one", "[300, 240]", "[300]", "3:15", "'world_size_m' must be [X, Y]"},
      {"world size 0", "[300, 240]", "[300, 0]", "3:21", "'world_size_m' must be [X, Y], the geofence's size"},
      {"world size text", "[300, 240]", "big", "3:15", "'world_size_m' must be [X, Y]"},
  };
  for (const BadCase& c : cases) {
    auto spec = LoadTrialText(With(c.from, c.to), "swarm.yaml", FakeTree());
    ASSERT_FALSE(spec) << c.what;
    EXPECT_EQ(spec.error().where(), "swarm.yaml:" + c.where) << c.what << ": " << spec.error().ToString();
    EXPECT_NE(spec.error().message().find(c.message), std::string::npos) << c.what << ": " << spec.error().ToString();
  }
}

TEST(DroneGroups, AnOverrideOfTheCountIsCheckedAtTheOverride) {
  auto spec = LoadTrialText(kGroupTrial, "swarm.yaml", FakeTree({"drones.scout.count=0"}));
  ASSERT_FALSE(spec);
  EXPECT_EQ(spec.error().where(), "--set drones.scout.count:1:1");
  EXPECT_NE(spec.error().message().find("'count' must be an integer from 1 to 500"), std::string::npos);
}

TEST(DroneGroups, AddressesGroupMemberOnlyForExpandedNames) {
  auto doc = yaml::Parse(kGroupTrial, "swarm.yaml");
  ASSERT_TRUE(doc);
  EXPECT_TRUE(AddressesGroupMember(*doc, "drones.scout_5.pose=[0,0,0]"));
  EXPECT_TRUE(AddressesGroupMember(*doc, "drones.scout_1=null"));
  EXPECT_FALSE(AddressesGroupMember(*doc, "drones.scout_6.pose=[0,0,0]"));   // past the count
  EXPECT_FALSE(AddressesGroupMember(*doc, "drones.scout_05.pose=[0,0,0]"));  // not its spelling
  EXPECT_FALSE(AddressesGroupMember(*doc, "drones.scout.count=3"));          // the group itself
  EXPECT_FALSE(AddressesGroupMember(*doc, "drones.lifter.pose=[0,0,0]"));
  EXPECT_FALSE(AddressesGroupMember(*doc, "seed=3"));
}

// `world: {generate: ...}` (issue #19): a recipe instead of a file; no file is looked for, the
// trial reads a derived world, and the resolved document keeps the recipe.
TEST(GeneratedWorld, ARecipeIsADerivedWorldWithoutAFile) {
  auto spec = LoadTrialText(With("world: worlds/open_field.yaml\nworld_size_m: [300, 240]\n",
                                 "world: {generate: rubble_field, size_m: [220, 180], victims: 4, obstacles: 25}\n"),
                            "swarm.yaml", FakeTree());
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  ASSERT_TRUE(spec->world_generate.has_value());
  EXPECT_EQ(spec->world_generate->kind, worlds::WorldKind::kRubbleField);
  EXPECT_EQ(spec->world_generate->victims, 4);
  EXPECT_FALSE(spec->world_generate->seed.has_value());
  EXPECT_FALSE(spec->HasWorldSize());
  EXPECT_TRUE(spec->HasDerivedWorld());
  EXPECT_EQ(spec->world, "worlds/generated_rubble_field.yaml");
  auto again = DecodeTrial(ToDocument(*spec), FakeTree());
  ASSERT_TRUE(again.ok()) << again.error().ToString();
  ASSERT_TRUE(again->world_generate.has_value());
  EXPECT_EQ(again->world_generate->obstacles, 25);
  EXPECT_EQ(again->world_generate->size_m, (std::array<double, 2>{220, 180}));
}

TEST(GeneratedWorld, OverridesReachTheRecipe) {
  auto spec = LoadTrialText(With("world: worlds/open_field.yaml\n", "world: {generate: open_field}\n"), "swarm.yaml",
                            FakeTree({"world.generate=forest_edge", "world.seed=12"}));
  ASSERT_TRUE(spec.ok()) << spec.error().ToString();
  EXPECT_EQ(spec->world_generate->kind, worlds::WorldKind::kForestEdge);
  EXPECT_EQ(spec->world_generate->seed, std::optional<std::uint64_t>(12));
  EXPECT_TRUE(spec->HasWorldSize());  // world_size_m stays: the runner generates at that size
}

TEST(GeneratedWorld, ABadRecipeIsReportedAtItsKey) {
  auto spec = LoadTrialText(With("world: worlds/open_field.yaml\n", "world: {generate: lava_lake}\n"), "swarm.yaml", FakeTree());
  ASSERT_FALSE(spec.ok());
  EXPECT_NE(spec.error().message().find("generate 'lava_lake' is not one of"), std::string::npos) << spec.error().message();
  EXPECT_EQ(spec.error().where(), "swarm.yaml:2:19");
}

}  // namespace
}  // namespace swarmbox::dsl
