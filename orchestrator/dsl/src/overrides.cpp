#include "swarmbox/dsl/overrides.hpp"

#include <string>
#include <vector>

namespace swarmbox::dsl {

namespace {

std::vector<std::string> SplitPath(std::string_view key) {
  std::vector<std::string> parts;
  std::size_t start = 0;
  while (true) {
    std::size_t dot = key.find('.', start);
    parts.emplace_back(key.substr(start, dot == std::string_view::npos ? dot : dot - start));
    if (dot == std::string_view::npos) break;
    start = dot + 1;
  }
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
    if (node->is_sequence()) {
      yaml::Node* next = nullptr;
      if (IsIndex(part)) {
        const std::size_t index = std::stoul(part);
        if (index >= node->items().size()) {
          return Error(ErrorCode::kInvalidArgument,
                       "'" + walked + "': index " + part + " is past the end of a list of " +
                           std::to_string(node->items().size()),
                       where);
        }
        next = &node->items()[index];
      } else {
        for (yaml::Node& item : node->items()) {
          const yaml::Node* name = item.is_mapping() ? item.Find("name") : nullptr;
          if (name != nullptr && name->is_scalar() && name->scalar() == part) next = &item;
        }
        if (next == nullptr) {
          return Error(ErrorCode::kInvalidArgument,
                       "'" + walked + "': no list item named '" + part + "'", where);
        }
      }
      if (last) {
        *next = *value;
        return Ok{};
      }
      node = next;
      continue;
    }
    if (node->is_null()) *node = yaml::Node::Mapping(node->mark());
    if (!node->is_mapping()) {
      return Error(ErrorCode::kInvalidArgument,
                   "'" + walked + "': cannot descend into a scalar (" + node->Where() + ")", where);
    }
    // New keys carry the override's mark, so schema errors about them point at the --set.
    const yaml::Mark mark = value->mark();
    yaml::Node* next = node->Find(part);
    if (next == nullptr) {
      node->entries().emplace_back(yaml::Node::Scalar(part, mark),
                                   last ? *value : yaml::Node::Mapping(mark));
      next = &node->entries().back().second;
      if (last) return Ok{};
    } else if (last) {
      *next = *value;
      return Ok{};
    }
    node = next;
  }
  return Ok{};
}

}  // namespace swarmbox::dsl
