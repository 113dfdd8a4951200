#include "swarmbox/dsl/duration.hpp"

#include <cmath>
#include <string>

namespace swarmbox::dsl {

std::string Duration::ToString() const {
  if (ms_ != 0 && ms_ % 3600000 == 0) return std::to_string(ms_ / 3600000) + "h";
  if (ms_ != 0 && ms_ % 60000 == 0) return std::to_string(ms_ / 60000) + "m";
  if (ms_ % 1000 == 0) return std::to_string(ms_ / 1000) + "s";
  return std::to_string(ms_) + "ms";
}

Result<Duration> ParseDuration(std::string_view text) {
  auto bad = [&](std::string why) {
    return Error(ErrorCode::kInvalidArgument,
                 "expected a duration such as 30s, 500ms or 2m, got '" + std::string(text) + "'" +
                     (why.empty() ? "" : " (" + why + ")"));
  };
  std::size_t i = 0;
  bool digits = false, dot = false;
  while (i < text.size() && ((text[i] >= '0' && text[i] <= '9') || (text[i] == '.' && !dot))) {
    if (text[i] == '.') dot = true; else digits = true;
    ++i;
  }
  if (!digits) return bad("");
  std::string_view number = text.substr(0, i);
  std::string_view unit = text.substr(i);
  double scale_ms = 0;
  if (unit == "ms") scale_ms = 1;
  else if (unit == "s") scale_ms = 1000;
  else if (unit == "m") scale_ms = 60000;
  else if (unit == "h") scale_ms = 3600000;
  else if (unit.empty()) return bad("missing unit ms, s, m or h");
  else return bad("unknown unit '" + std::string(unit) + "'");
  double value = std::stod(std::string(number));
  double ms = value * scale_ms;
  if (ms > 1e15) return bad("too long");
  double rounded = std::round(ms);
  if (std::fabs(rounded - ms) > 1e-6) return bad("finer than a millisecond");
  return Duration::Ms(static_cast<std::int64_t>(rounded));
}

Status Decode(const yaml::Node& node, Duration* out) {
  if (!node.is_scalar()) {
    return Error(ErrorCode::kInvalidArgument, "expected a duration such as 30s, 500ms or 2m",
                 node.Where());
  }
  auto d = ParseDuration(node.scalar());
  if (!d) return Error(d.error().code(), d.error().message(), node.Where());
  *out = *d;
  return Ok{};
}

}  // namespace swarmbox::dsl
