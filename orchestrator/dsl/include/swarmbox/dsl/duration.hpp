// Duration: a span of (simulated or wall) time as written in trial files: "30s", "500ms", "2m",
// "1h", decimals allowed ("1.5s"). Stored as whole milliseconds.
//
//   auto d = ParseDuration("2m");   // d->ms() == 120000
//   d->ToString();                  // "2m"
#pragma once

#include <compare>
#include <cstdint>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::dsl {

class Duration {
 public:
  constexpr Duration() = default;
  static constexpr Duration Ms(std::int64_t ms) { return Duration(ms); }
  static constexpr Duration Seconds(std::int64_t s) { return Duration(s * 1000); }
  static constexpr Duration Minutes(std::int64_t m) { return Duration(m * 60000); }

  constexpr std::int64_t ms() const { return ms_; }
  constexpr double seconds() const { return static_cast<double>(ms_) / 1000.0; }
  constexpr bool zero() const { return ms_ == 0; }
  // The shortest exact spelling: "2m", "90s", "500ms", "0s".
  std::string ToString() const;

  constexpr auto operator<=>(const Duration&) const = default;

 private:
  constexpr explicit Duration(std::int64_t ms) : ms_(ms) {}
  std::int64_t ms_ = 0;
};

// Parses "<number><unit>" with unit ms, s, m or h; no sign, no spaces. Errors (kInvalidArgument)
// say what was expected.
Result<Duration> ParseDuration(std::string_view text);

// yaml::MapReader support: a scalar such as 30s; errors carry the node's file:line:col.
Status Decode(const yaml::Node& node, Duration* out);

}  // namespace swarmbox::dsl
