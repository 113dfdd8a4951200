#include "swarmbox/airframe/yaml_read.hpp"

#include <array>
#include <cmath>
#include <utility>

namespace swarmbox::airframe {

Status Decode(const yaml::Node& node, Vec3* out) {
  std::array<double, 3> v{};
  if (auto s = yaml::Decode(node, &v); !s) return s;
  for (double c : v) {
    if (!std::isfinite(c)) return Error(ErrorCode::kInvalidArgument, "expected finite numbers", node.Where());
  }
  *out = Vec3{v[0], v[1], v[2]};
  return Ok{};
}

namespace detail {

Error InvalidAt(const yaml::Node& map, std::string_view key, std::string msg) {
  const yaml::Node* n = map.Find(key);
  return Error(ErrorCode::kInvalidArgument, std::move(msg), (n != nullptr ? *n : map).Where());
}

Checked& Checked::Positive(std::string_view key, double* out, bool required) {
  return Range(key, out, required, /*strict=*/true);
}

Checked& Checked::NonNegative(std::string_view key, double* out, bool required) {
  return Range(key, out, required, /*strict=*/false);
}

Checked& Checked::Range(std::string_view key, double* out, bool required, bool strict) {
  if (required) {
    reader_.Required(key, out);
  } else {
    reader_.Optional(key, out);
  }
  if (!reader_.ok()) return *this;
  const yaml::Node* n = map_.is_mapping() ? map_.Find(key) : nullptr;
  if (n == nullptr) return *this;
  const bool bad = !std::isfinite(*out) || (strict ? *out <= 0 : *out < 0);
  if (bad) {
    reader_.Fail(Error(ErrorCode::kInvalidArgument,
                       "'" + std::string(key) + "' must be " + (strict ? "> 0" : ">= 0") +
                           " (got " + n->scalar() + ")",
                       n->Where()));
  }
  return *this;
}

}  // namespace detail
}  // namespace swarmbox::airframe
