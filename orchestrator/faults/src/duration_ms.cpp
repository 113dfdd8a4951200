#include "swarmbox/faults/duration_ms.hpp"

#include <cmath>
#include <cstdlib>
#include <string>

namespace swarmbox::faults {

Result<std::int64_t> ParseDurationMs(std::string_view text) {
  auto bad = [&](const std::string& why) {
    return Error(ErrorCode::kInvalidArgument,
                 "expected a duration such as 30s, 500ms or 2m, got '" + std::string(text) + "'" +
                     (why.empty() ? "" : " (" + why + ")"));
  };
  std::size_t i = 0;
  bool digits = false;
  bool dot = false;
  while (i < text.size() && ((text[i] >= '0' && text[i] <= '9') || (text[i] == '.' && !dot))) {
    if (text[i] == '.') {
      dot = true;
    } else {
      digits = true;
    }
    ++i;
  }
  if (!digits) return bad("");
  const std::string number(text.substr(0, i));
  const std::string_view unit = text.substr(i);
  double scale_ms = 0;
  if (unit == "ms") {
    scale_ms = 1;
  } else if (unit == "s") {
    scale_ms = 1000;
  } else if (unit == "m") {
    scale_ms = 60000;
  } else if (unit == "h") {
    scale_ms = 3600000;
  } else if (unit.empty()) {
    return bad("missing unit ms, s, m or h");
  } else {
    return bad("unknown unit '" + std::string(unit) + "'");
  }
  const double ms = std::strtod(number.c_str(), nullptr) * scale_ms;
  if (ms > 1e15) return bad("too long");
  const double rounded = std::round(ms);
  if (std::fabs(rounded - ms) > 1e-6) return bad("finer than a millisecond");
  return static_cast<std::int64_t>(rounded);
}

std::string FormatDurationMs(std::int64_t ms) {
  if (ms != 0 && ms % 3600000 == 0) return std::to_string(ms / 3600000) + "h";
  if (ms != 0 && ms % 60000 == 0) return std::to_string(ms / 60000) + "m";
  if (ms % 1000 == 0) return std::to_string(ms / 1000) + "s";
  return std::to_string(ms) + "ms";
}

Status DecodeDurationMs(const yaml::Node& node, std::int64_t* out_ms) {
  if (!node.is_scalar()) {
    return Error(ErrorCode::kInvalidArgument, "expected a duration such as 30s, 500ms or 2m",
                 node.Where());
  }
  auto ms = ParseDurationMs(node.scalar());
  if (!ms) return Error(ms.error().code(), ms.error().message(), node.Where());
  *out_ms = *ms;
  return Ok{};
}

}  // namespace swarmbox::faults
