// The world a trial runs in when it sets `world_size_m: [X, Y]` (design18 §1): the trial's world
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

namespace swarmbox::runner {

inline constexpr std::string_view kDerivedWorldFile = "world.yaml";  // in the trial folder

// The text of the derived world. `world_text` is the world file (`world_file` names it in errors
// and in the header comment). kInvalidArgument when the file has no mapping at its top, or when a
// victim or an obstacle's centre would lie outside the new geofence (the mission could never find
// or fly around it): the message names it and the size that would hold it.
Result<std::string> DeriveWorld(std::string_view world_text, std::string_view world_file,
                                const std::array<double, 2>& size_m);

}  // namespace swarmbox::runner
