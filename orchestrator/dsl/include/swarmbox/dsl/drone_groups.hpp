// Drone groups: one `drones:` item with `count: N` stands for N drones on a grid (dsl/README.md "Drone
// groups").
//
//   drones:
//     - {name: scout, count: 100, airframe: x500, pose: [0, 0, 0], spacing_m: 4}
//     - {name: lifter, airframe: x8_heavy, pose: [0, -10, 0], payload: stretcher}
//
// expands, in the trial document and before it is decoded, to scout_1 .. scout_100 (the group's
// name plus `_<i>`, in that order, each with the group's other keys: airframe, payload, limits,
// brain) at the poses GroupGridPose gives, followed by the lifter. Every expanded item carries the
// group's marks, so an error about scout_37 points at the group's line.
//
// Overrides address the group before expansion (`--set drones.scout.count=50`); one expanded drone
// is addressed by its full name (`--set drones.scout_7.pose=[1,2,0]`): the loader expands the
// groups when an override names a drone only a group has (AddressesGroupMember), so later
// overrides see the expanded list (a `count` override must come before such an override).
// Pure: no I/O.
#pragma once

#include <array>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::dsl {

inline constexpr int kMaxGroupCount = 500;
inline constexpr double kDefaultGroupSpacingM = 4.0;

// The start pose of drone `index` (0-based) of a group of `count` at `origin` [m]: a grid of
// ceil(sqrt(count)) columns, `spacing_m` apart, row-major along +x then +y; z is the origin's.
std::array<double, 3> GroupGridPose(const std::array<double, 3>& origin, double spacing_m, int count, int index);

// Replaces every `drones:` item that has `count:` with its drones, in place; a document without
// groups is left as it is. Errors (file:line:col, at the key): count not an integer in
// 1..kMaxGroupCount, spacing_m not a number > 0 or given without count, pose not three numbers,
// a group without a name, and an expanded name that another drone (or group) also has.
Status ExpandDroneGroups(yaml::Node& document);

// Whether `assignment` ("drones.scout_7.pose=...") names, as its second path segment, a drone that
// no item of `drones:` is called but a group's expansion is.
bool AddressesGroupMember(const yaml::Node& document, std::string_view assignment);

}  // namespace swarmbox::dsl
