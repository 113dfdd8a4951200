// world_size_m (dsl/README.md "Drone groups"): the derived world keeps everything but the geofence, refuses a
// size that leaves a victim outside, and is what the physics server and every agent get as their world.
#include "swarmbox/runner/derived_world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/dsl/trial_loader.hpp"
#include "swarmbox/runner/plan.hpp"
#include "swarmbox/worlds/generator.hpp"

namespace swarmbox::runner {
namespace {

constexpr const char* kWorld = R"(name: field
geofence: {size_x_m: 200, size_y_m: 200}
obstacles:
  - {id: hut, center_m: [0, 80, 2], size_m: [4, 4, 4], yaw_deg: 0}
victims:
  - {id: victim_1, x_m: 35.0, y_m: 20.0, heading_deg: 30}
  - {id: victim_2, x_m: -42.0, y_m: 55.0, heading_deg: 200}
home: {lat_deg: 47.397742, lon_deg: 8.545594, alt_m: 488.0}
)";

TEST(DeriveWorld, SetsTheGeofenceAndKeepsTheRest) {
  auto text = DeriveWorld(kWorld, "worlds/field.yaml", {600, 450});
  ASSERT_TRUE(text) << text.error().ToString();
  EXPECT_EQ(text->rfind("# worlds/field.yaml with its geofence set to 600 x 450 m", 0), 0u) << *text;
  auto derived = yaml::Parse(*text, "world.yaml");
  auto original = yaml::Parse(kWorld, "field.yaml");
  ASSERT_TRUE(derived && original);
  EXPECT_EQ(derived->Find("geofence")->Find("size_x_m")->AsDouble().value(), 600);
  EXPECT_EQ(derived->Find("geofence")->Find("size_y_m")->AsDouble().value(), 450);
  for (const char* key : {"name", "obstacles", "victims", "home"}) {
    EXPECT_EQ(yaml::EmitJson(*derived->Find(key)), yaml::EmitJson(*original->Find(key))) << key;
  }
  // Key order is kept (the physics server reads any order; people diff it).
  EXPECT_EQ(derived->entries()[1].first.scalar(), "geofence");
}

TEST(DeriveWorld, RefusesASizeThatLeavesAVictimOrObstacleOutside) {
  auto small = DeriveWorld(kWorld, "worlds/field.yaml", {100, 100});
  ASSERT_FALSE(small);
  EXPECT_EQ(small.error().where(), "worlds/field.yaml:7:5");
  EXPECT_EQ(small.error().message(),
            "victim victim_2 at (-42, 55) m lies outside world_size_m [100, 100] (the geofence spans |x| <= X/2, "
            "|y| <= Y/2): use at least [84, 110]");
  auto narrow = DeriveWorld(kWorld, "worlds/field.yaml", {100, 150});
  ASSERT_FALSE(narrow);
  EXPECT_NE(narrow.error().message().find("obstacle hut at (0, 80) m lies outside"), std::string::npos);
  EXPECT_FALSE(DeriveWorld("[1, 2]", "w.yaml", {100, 100}));
}

TEST(DeriveWorld, TheShippedWorldAtTheSwarmSizes) {
  std::ifstream in(std::string(SWARMBOX_SOURCE_DIR) + "/trials/worlds/open_field.yaml");
  std::ostringstream text;
  text << in.rdbuf();
  // swarm_size.yaml's smallest area (5 scouts) still holds both victims.
  EXPECT_TRUE(DeriveWorld(text.str(), "open_field.yaml", {150, 150}));
  EXPECT_TRUE(DeriveWorld(text.str(), "open_field.yaml", {600, 600}));
}

TEST(PlanWorldSize, EveryContainerReadsTheDerivedWorldAtTheWorldsPath) {
  dsl::LoadOptions load;
  load.overrides = {"world_size_m=[400,400]"};
  auto spec = dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/sar_search.yaml", load);
  ASSERT_TRUE(spec) << spec.error().ToString();
  PlanOptions options;
  options.run_id = "20261126-090000-aaaa";
  options.images = {"swarmbox/physics:abc", "swarmbox/agent:def"};
  options.subnets = {*Ipv4Net::Parse("10.200.8.0/24"), *Ipv4Net::Parse("10.200.9.0/24")};
  options.trials_dir = "/src/trials";
  options.world_path = "/runs/sar-search-20261126-090000-aaaa/world.yaml";
  auto trial = PlanTrial(*spec, options);
  ASSERT_TRUE(trial) << trial.error().ToString();
  int readers = 0;
  for (const char* id : {"physics", "scout_1", "scout_2", "scout_3", "lifter"}) {
    const dsl::ContainerSpec& c = (*trial)->FindPlugin(id)->spec();
    bool found = false;
    for (const dsl::InputFile& in : c.inputs) {
      if (in.container_path != "/swarmbox/trials/worlds/open_field.yaml") continue;
      EXPECT_EQ(in.host_path, options.world_path) << id;
      found = true;
    }
    EXPECT_TRUE(found) << id << " gets no world";
    // ... and its --world flag names that path.
    const auto& argv = c.argv;
    auto flag = std::find(argv.begin(), argv.end(), "--world");
    ASSERT_NE(flag, argv.end()) << id;
    EXPECT_EQ(*(flag + 1), "/swarmbox/trials/worlds/open_field.yaml") << id;
    ++readers;
  }
  EXPECT_EQ(readers, 5);
}

// A generated world (issue #19, point 5): the text is the generator's for the trial's seed (so
// another trial seed is another world), world_size_m sets its size, and the plan needs the path
// the runner wrote it to.
TEST(GeneratedWorld, TheDerivedWorldIsGeneratedFromTheTrialSeed) {
  auto spec = dsl::LoadTrial(std::string(SWARMBOX_SOURCE_DIR) + "/trials/sar_rubble.yaml", dsl::LoadOptions{});
  ASSERT_TRUE(spec) << spec.error().ToString();
  ASSERT_TRUE(spec->world_generate.has_value());
  auto text = DerivedWorldText(*spec, "/nowhere");  // no file is read
  ASSERT_TRUE(text) << text.error().ToString();
  auto expected = worlds::GenerateWorld(*spec->world_generate, worlds::WorldSeed(*spec->world_generate, spec->seed));
  ASSERT_TRUE(expected);
  EXPECT_EQ(*text, *expected);
  EXPECT_NE(text->find("geofence: {size_x_m: 160, size_y_m: 160}"), std::string::npos) << *text;

  dsl::TrialSpec other = *spec;
  other.seed = spec->seed + 1;
  EXPECT_NE(*DerivedWorldText(other, "/nowhere"), *text);
  other.world_size_m = {300, 200};
  EXPECT_NE(DerivedWorldText(other, "/nowhere")->find("geofence: {size_x_m: 300, size_y_m: 200}"), std::string::npos);

  PlanOptions options;
  options.run_id = "20261126-090000-aaaa";
  options.images = {"swarmbox/physics:abc", "swarmbox/agent:def"};
  options.subnets = {*Ipv4Net::Parse("10.200.8.0/24"), *Ipv4Net::Parse("10.200.9.0/24")};
  options.trials_dir = "/src/trials";
  auto unplanned = PlanTrial(*spec, options);
  ASSERT_FALSE(unplanned);
  EXPECT_NE(unplanned.error().message().find("a generated world needs PlanOptions::world_path"), std::string::npos);
  options.world_path = "/runs/sar-rubble-20261126-090000-aaaa/world.yaml";
  auto trial = PlanTrial(*spec, options);
  ASSERT_TRUE(trial) << trial.error().ToString();
  const dsl::ContainerSpec& physics = (*trial)->FindPlugin("physics")->spec();
  const bool reads = std::any_of(physics.inputs.begin(), physics.inputs.end(), [&](const dsl::InputFile& in) {
    return in.host_path == options.world_path && in.container_path == "/swarmbox/trials/worlds/generated_rubble_field.yaml";
  });
  EXPECT_TRUE(reads);
}

}  // namespace
}  // namespace swarmbox::runner
