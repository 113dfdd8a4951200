#include "swarmbox/brain/args.hpp"

#include <utility>

#include "swarmbox/common/yaml.hpp"

namespace swarmbox::brain {

Result<std::map<std::string, std::string>> ParseBrainArgs(std::string_view json,
                                                          std::string_view source) {
  auto doc = yaml::Parse(json, source);
  if (!doc) return doc.error();
  std::map<std::string, std::string> args;
  if (doc->is_null()) return args;  // empty text
  if (!doc->is_mapping()) {
    return Error(ErrorCode::kInvalidArgument,
                 "brain arguments must be a JSON object ({\"key\": value, ...})", doc->Where());
  }
  for (const auto& [key, value] : doc->entries()) {
    if (key.scalar().empty()) {
      return Error(ErrorCode::kInvalidArgument, "a brain argument needs a name", key.Where());
    }
    if (value.is_null()) continue;  // null: the brain's default
    args.emplace(key.scalar(), value.is_scalar() ? value.scalar() : yaml::EmitJson(value));
  }
  return args;
}

}  // namespace swarmbox::brain
