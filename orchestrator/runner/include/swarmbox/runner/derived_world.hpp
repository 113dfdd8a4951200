// The world a trial runs in when it sets `world_size_m: [X, Y]` (dsl/README.md "Drone groups") or generates
// its world (`world: {generate: ...}`, issue #19). world_size_m: the trial's world
// file with its geofence set to X x Y m, everything else (victims, obstacles, wind, home) as it is.
// The SAR search area is the geofence, so this scales the search with the swarm.
//
// The runner writes it into the trial folder (kDerivedWorldFile) and plans it as the world input of
// the physics server and every agent, at the same path in the containers as the world itself
// (PlanOptions::world_path), so `--world` and every reader see the derived one. Pure.
#pragma once

#include <array>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/dsl/trial_spec.hpp"

namespace swarmbox::runner {

inline constexpr std::string_view kDerivedWorldFile = "world.yaml";  // in the trial folder

// The text of the derived world. `world_text` is the world file (`world_file` names it in errors
// and in the header comment). kInvalidArgument when the file has no mapping at its top, or when a
// victim or an obstacle's centre would lie outside the new geofence (the mission could never find
// or fly around it): the message names it and the size that would hold it.
Result<std::string> DeriveWorld(std::string_view world_text, std::string_view world_file,
                                const std::array<double, 2>& size_m);

// The derived world of a trial with HasDerivedWorld(): the generated one (`world: {generate:
// ...}`, worlds/generator.hpp, seeded by WorldSeed(recipe, spec.seed); world_size_m, when also
// given, is its size), else the world file under `trials_dir` with world_size_m (DeriveWorld).
// kNotFound when the world file cannot be read.
Result<std::string> DerivedWorldText(const dsl::TrialSpec& spec, const std::string& trials_dir);

}  // namespace swarmbox::runner
