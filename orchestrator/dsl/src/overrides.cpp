#include "swarmbox/dsl/overrides.hpp"

#include <string>
#include <vector>

#include "swarmbox/common/split.hpp"

namespace swarmbox::dsl {

namespace {

std::vector<std::string> SplitPath(std::string_view key) {
  std::vector<std::string> parts;
  for (std::string_view part : SplitOn(key, '.')) parts.emplace_back(part);
  return parts;
}

bool IsIndex(const std::string& s) {
  if (s.empty() || s.size() > 6) return false;
  for (char c : s) {
    if (c < '0' || c > '9') return false;
  }
  return true;
}

}  // namespace

namespace {

// The item of a list that `part` names: by index, or the item whose `name` is `part`.
Result<yaml::Node*> ListItem(yaml::Node& list, const std::string& part, const std::string& walked,
                             const std::string& where) {
  if (IsIndex(part)) {
    const std::size_t index = std::stoul(part);
    if (index >= list.items().size()) {
      return Error(ErrorCode::kInvalidArgument,
                   "'" + walked + "': index " + part + " is past the end of a list of " +
                       std::to_string(list.items().size()),
                   where);
    }
    return &list.items()[index];
  }
  yaml::Node* next = nullptr;
  for (yaml::Node& item : list.items()) {
    const yaml::Node* name = item.is_mapping() ? item.Find("name") : nullptr;
    if (name != nullptr && name->is_scalar() && name->scalar() == part) next = &item;
  }
  if (next == nullptr) {
    return Error(ErrorCode::kInvalidArgument, "'" + walked + "': no list item named '" + part + "'", where);
  }
  return next;
}

// The entry `part` of a mapping (a null node becomes one). A new entry (*created) is the value
// when it is the `last` segment, else an empty mapping; new keys carry the override's mark, so
// schema errors about them point at the --set.
Result<yaml::Node*> MapEntry(yaml::Node& node, const std::string& part, bool last, const yaml::Node& value,
                             const std::string& walked, const std::string& where, bool* created) {
  if (node.is_null()) node = yaml::Node::Mapping(node.mark());
  if (!node.is_mapping()) {
    return Error(ErrorCode::kInvalidArgument,
                 "'" + walked + "': cannot descend into a scalar (" + node.Where() + ")", where);
  }
  const yaml::Mark mark = value.mark();
  if (yaml::Node* next = node.Find(part)) return next;
  node.entries().emplace_back(yaml::Node::Scalar(part, mark), last ? value : yaml::Node::Mapping(mark));
  *created = true;
  return &node.entries().back().second;
}

}  // namespace

Status ApplyOverride(yaml::Node& document, std::string_view assignment) {
  const std::string where = "--set " + std::string(assignment);
  const std::size_t eq = assignment.find('=');
  if (eq == std::string_view::npos || eq == 0) {
    return Error(ErrorCode::kInvalidArgument, "expected key=value", where);
  }
  const std::string_view key = assignment.substr(0, eq);
  const std::string_view text = assignment.substr(eq + 1);
  auto value = yaml::Parse(text, "--set " + std::string(key));
  if (!value) return value.error();

  const std::vector<std::string> parts = SplitPath(key);
  if (document.is_null()) document = yaml::Node::Mapping();
  yaml::Node* node = &document;
  std::string walked;
  for (std::size_t i = 0; i < parts.size(); ++i) {
    const std::string& part = parts[i];
    if (part.empty()) return Error(ErrorCode::kInvalidArgument, "empty path segment in key", where);
    const bool last = i + 1 == parts.size();
    walked += (walked.empty() ? "" : ".") + part;
    bool created = false;
    auto next = node->is_sequence() ? ListItem(*node, part, walked, where)
                                    : MapEntry(*node, part, last, *value, walked, where, &created);
    if (!next) return next.error();
    if (last) {
      if (!created) **next = *value;
      return Ok{};
    }
    node = *next;
  }
  return Ok{};
}

}  // namespace swarmbox::dsl
