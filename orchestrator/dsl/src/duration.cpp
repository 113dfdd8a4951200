#include "swarmbox/dsl/duration.hpp"

#include <cstdint>
#include <string>

#include "swarmbox/faults/duration_ms.hpp"

namespace swarmbox::dsl {

// One parser and one spelling for every duration of the trial files: the fault model's
// (faults/duration_ms.hpp), which the DSL links already.
std::string Duration::ToString() const { return faults::FormatDurationMs(ms_); }

Result<Duration> ParseDuration(std::string_view text) {
  auto ms = faults::ParseDurationMs(text);
  if (!ms) return ms.error();
  return Duration::Ms(*ms);
}

Status Decode(const yaml::Node& node, Duration* out) {
  std::int64_t ms = 0;
  if (Status s = faults::DecodeDurationMs(node, &ms); !s) return s;
  *out = Duration::Ms(ms);
  return Ok{};
}

}  // namespace swarmbox::dsl
