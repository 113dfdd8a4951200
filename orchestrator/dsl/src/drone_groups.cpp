#include "swarmbox/dsl/drone_groups.hpp"

#include <charconv>
#include <cmath>
#include <map>
#include <string>
#include <utility>
#include <vector>

namespace swarmbox::dsl {

namespace {

using yaml::Node;

Error At(const Node& node, std::string message) {
  return Error(ErrorCode::kInvalidArgument, std::move(message), node.Where());
}

std::string Number(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, r.ptr);
}

std::string MemberName(std::string_view group, int i) { return std::string(group) + "_" + std::to_string(i); }

// A group item's checked keys.
struct Group {
  std::string name;
  int count = 0;
  double spacing_m = kDefaultGroupSpacingM;
  std::array<double, 3> origin{};
};

bool IsGroup(const Node& item) { return item.is_mapping() && item.Find("count") != nullptr; }

Result<Group> ReadGroup(const Node& item) {
  Group g;
  const Node* name = item.Find("name");
  if (name == nullptr || !name->is_scalar() || name->scalar().empty()) {
    return At(item, "a drone group needs a 'name' (its drones are <name>_1 .. <name>_<count>)");
  }
  g.name = name->scalar();
  const Node& count = *item.Find("count");
  auto n = count.AsInt();
  if (!n || *n < 1 || *n > kMaxGroupCount) {
    return At(count, "'count' must be an integer from 1 to " + std::to_string(kMaxGroupCount) + " (drones in the group)");
  }
  g.count = static_cast<int>(*n);
  if (const Node* spacing = item.Find("spacing_m")) {
    auto s = spacing->AsDouble();
    if (!s || !(*s > 0) || !std::isfinite(*s)) return At(*spacing, "'spacing_m' must be a number > 0 [m]");
    g.spacing_m = *s;
  }
  if (const Node* pose = item.Find("pose")) {
    if (!pose->is_sequence() || pose->items().size() != 3) return At(*pose, "'pose' must be [x, y, z] [m]");
    for (std::size_t i = 0; i < 3; ++i) {
      auto v = pose->items()[i].AsDouble();
      if (!v) return v.error();
      g.origin[i] = *v;
    }
  }
  return g;
}

// Whether the list has a group (an item with `count:`); `spacing_m` without `count` is an error.
Result<bool> HasGroups(const Node& drones) {
  bool any = false;
  for (const Node& item : drones.items()) {
    if (item.is_mapping() && item.Find("spacing_m") != nullptr && item.Find("count") == nullptr) {
      return At(*item.Find("spacing_m"), "'spacing_m' spaces the drones of a group: give 'count' too");
    }
    any = any || IsGroup(item);
  }
  return any;
}

// Name -> the name node (the group's for a member), to report a clash at the group.
using TakenNames = std::map<std::string, const Node*>;

// The names of the list's single drones.
TakenNames SingleDroneNames(const Node& drones) {
  TakenNames taken;
  for (const Node& item : drones.items()) {
    if (IsGroup(item)) continue;
    const Node* name = item.is_mapping() ? item.Find("name") : nullptr;
    if (name != nullptr && name->is_scalar()) taken.emplace(name->scalar(), name);
  }
  return taken;
}

// Member `i` (1-based) of the group `item`: its keys but count and spacing_m, named `member`,
// at its grid pose (marked where the group's pose, else the group, is).
Node GroupMember(const Node& item, const Group& group, int i, const std::string& member) {
  Node drone = Node::Mapping(item.mark());
  for (const auto& [key, value] : item.entries()) {
    const std::string& k = key.scalar();
    if (k == "count" || k == "spacing_m" || k == "pose") continue;  // the pose: written below
    drone.entries().emplace_back(key, k == "name" ? Node::Scalar(member, value.mark()) : value);
  }
  const Node* pose_node = item.Find("pose");
  const yaml::Mark pose_mark = pose_node != nullptr ? pose_node->mark() : item.mark();
  Node pose = Node::Sequence(pose_mark);
  for (double v : GroupGridPose(group.origin, group.spacing_m, group.count, i - 1)) {
    pose.Append(Node::Scalar(Number(v), pose_mark));
  }
  drone.Set("pose", std::move(pose));
  return drone;
}

// The group `item`'s members onto `expanded`, each name into `taken` (a clash is an error).
Status ExpandGroup(const Node& item, TakenNames& taken, Node* expanded) {
  auto group = ReadGroup(item);
  if (!group) return group.error();
  const Node& name_node = *item.Find("name");
  for (int i = 1; i <= group->count; ++i) {
    const std::string member = MemberName(group->name, i);
    auto [it, inserted] = taken.emplace(member, &name_node);
    if (!inserted) {
      return At(name_node, "group '" + group->name + "' (count " + std::to_string(group->count) +
                               ") expands to '" + member + "', which is also the name of the drone at " +
                               it->second->Where() + ": rename the group or that drone");
    }
    expanded->Append(GroupMember(item, *group, i, member));
  }
  return Ok{};
}

}  // namespace

std::array<double, 3> GroupGridPose(const std::array<double, 3>& origin, double spacing_m, int count, int index) {
  int columns = 1;
  while (columns * columns < count) ++columns;  // ceil(sqrt(count)), exactly
  return {origin[0] + spacing_m * (index % columns), origin[1] + spacing_m * (index / columns), origin[2]};
}

Status ExpandDroneGroups(Node& document) {
  Node* drones = document.is_mapping() ? document.Find("drones") : nullptr;
  if (drones == nullptr || !drones->is_sequence()) return Ok{};
  auto any = HasGroups(*drones);
  if (!any) return any.error();
  if (!*any) return Ok{};
  TakenNames taken = SingleDroneNames(*drones);
  Node expanded = Node::Sequence(drones->mark());
  for (const Node& item : drones->items()) {
    if (IsGroup(item)) {
      SWARMBOX_TRY(ExpandGroup(item, taken, &expanded));
    } else {
      expanded.Append(item);
    }
  }
  *drones = std::move(expanded);
  return Ok{};
}

bool AddressesGroupMember(const Node& document, std::string_view assignment) {
  const std::string_view key = assignment.substr(0, assignment.find('='));
  constexpr std::string_view kPrefix = "drones.";
  if (key.substr(0, kPrefix.size()) != kPrefix) return false;
  std::string_view rest = key.substr(kPrefix.size());
  const std::string_view target = rest.substr(0, rest.find('.'));
  const Node* drones = document.is_mapping() ? document.Find("drones") : nullptr;
  if (drones == nullptr || !drones->is_sequence()) return false;
  for (const Node& item : drones->items()) {
    const Node* name = item.is_mapping() ? item.Find("name") : nullptr;
    if (name != nullptr && name->is_scalar() && name->scalar() == target) return false;
  }
  for (const Node& item : drones->items()) {
    if (!IsGroup(item)) continue;
    const Node* name = item.Find("name");
    if (name == nullptr || !name->is_scalar()) continue;
    const std::string prefix = name->scalar() + "_";
    if (target.size() <= prefix.size() || target.substr(0, prefix.size()) != prefix) continue;
    const std::string_view index = target.substr(prefix.size());
    int i = 0;
    auto [end, ec] = std::from_chars(index.data(), index.data() + index.size(), i);
    auto count = item.Find("count")->AsInt();
    if (ec == std::errc() && end == index.data() + index.size() && index[0] != '0' && count && i >= 1 &&
        i <= *count) {
      return true;
    }
  }
  return false;
}

}  // namespace swarmbox::dsl
