// Helpers for reading the airframe and world YAML schemas with common/yaml.hpp (the airframe
// library's parser and the physics server's world parser use them).
#pragma once

#include <string>
#include <string_view>

#include "swarmbox/common/yaml.hpp"
#include "swarmbox/airframe/vec3.hpp"

namespace swarmbox::airframe {

// A Vec3 is written as a list of three numbers: [x, y, z]. Found by MapReader through ADL.
Status Decode(const yaml::Node& node, Vec3* out);

namespace detail {

// An invalid-argument error at `map.key`'s mark (the map's own when the key is absent).
Error InvalidAt(const yaml::Node& map, std::string_view key, std::string msg);

// Reads an optional/required number and checks `lo <= value` (strictly above lo when
// `strict`); errors point at the value's own mark.
class Checked {
 public:
  explicit Checked(yaml::MapReader& reader, const yaml::Node& map) : reader_(reader), map_(map) {}
  // value > 0
  Checked& Positive(std::string_view key, double* out, bool required = true);
  // value >= 0
  Checked& NonNegative(std::string_view key, double* out, bool required = false);

 private:
  Checked& Range(std::string_view key, double* out, bool required, bool strict);
  yaml::MapReader& reader_;
  const yaml::Node& map_;
};

// Runs a nested reader on `map.key` (if present) with `fn(MapReader&, const Node&)`, and folds
// its error into `parent`.
template <typename Fn>
void Nested(yaml::MapReader& parent, std::string_view key, std::string what, bool required, Fn fn) {
  const yaml::Node* child = parent.Child(key, required);
  if (child == nullptr) return;
  yaml::MapReader r(*child, std::move(what));
  fn(r, *child);
  if (auto s = r.Finish(); !s) parent.Fail(s.error());
}

}  // namespace detail
}  // namespace swarmbox::airframe
