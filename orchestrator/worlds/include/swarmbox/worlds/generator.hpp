// Generated search areas (issue #19.5): a trial's `world:` may be a recipe instead of a file,
//
//   world: {generate: rubble_field, size_m: [200, 200], victims: 4, obstacles: 30, distractors: 20, seed: 7}
//
// and the runner writes the world it makes as the trial's derived world (runner/derived_world.hpp,
// like world_size_m), which the physics server, every agent, truth.csv and trajectories.png read.
// Pure and seeded: the same spec and seed give the same text; the seed is the trial's (mixed)
// unless the recipe gives one, so an experiment over seeds is an experiment over worlds.
//
// Kinds (world YAML schema: trials/worlds/open_field.yaml):
// - rubble_field: rubble terrain, collapsed slabs and walls (boxes 1-5 m tall; no trees, nothing
//   above the lifter's 10 m transit), people mostly lying or curled, partly under debris (cover up
//   to 0.6), debris and tarps among the distractors;
// - forest_edge: grass/soil/gravel mix with small ponds, trees (kind: tree, 6-15 m) dense on one
//   side of a wandering edge line and sparse on the other, people near the edge under vegetation;
// - open_field: grass with ponds, sheds and bales (1.5-3.5 m) and a few trees, people in the open.
// Every kind: time of day 7-18 h and overcast 0-1 drawn from the seed; victims at least 8 m apart,
// 3 m clear of obstacles and 2 m of distractors; obstacles and trees leave the 15 m around the
// origin (the launch area) and a 5 m border clear; everything inside the geofence.
#pragma once

#include <array>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::worlds {

enum class WorldKind { kRubbleField, kForestEdge, kOpenField };

std::string_view KindName(WorldKind kind);  // "rubble_field", ...

struct GenerateSpec {
  WorldKind kind = WorldKind::kRubbleField;
  std::array<double, 2> size_m{200, 200};  // geofence [m], 40..2000 each
  int victims = 4;                         // 0..100
  int obstacles = 20;                      // boxes and trees, 0..2000
  int distractors = 20;                    // 0..2000
  std::optional<std::uint64_t> seed{};     // absent: derived from the trial seed
};

// Reads the `world:` mapping ({generate, size_m, victims, obstacles, distractors, seed}; unknown
// keys are errors, with the position). Counts and sizes out of range: kInvalidArgument naming them.
Result<GenerateSpec> ParseGenerateSpec(const yaml::Node& world);
// The mapping as a trial file writes it (for the resolved trial.yaml).
yaml::Node ToNode(const GenerateSpec& spec);

// The seed the world is generated from: the spec's, else one mixed from the trial's.
std::uint64_t WorldSeed(const GenerateSpec& spec, std::uint64_t trial_seed);

// The world YAML text (name `<kind>_<seed>`). kInvalidArgument when the area cannot hold what was
// asked for (victims that cannot be placed 8 m apart, obstacles that find no free spot).
Result<std::string> GenerateWorld(const GenerateSpec& spec, std::uint64_t seed);

}  // namespace swarmbox::worlds
