// Durations in fault schedules ("30s", "500ms", "2m", "1.5s"), as whole milliseconds.
//
// The same spelling as dsl::Duration; kept here so swarmbox_faults depends on common only (the DSL
// builds on faults, not the other way round).
//
//   auto ms = ParseDurationMs("1.5s");   // *ms == 1500
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"
#include "swarmbox/common/yaml.hpp"

namespace swarmbox::faults {

// "<number><unit>", unit ms, s, m or h; no sign. kInvalidArgument says what was expected.
Result<std::int64_t> ParseDurationMs(std::string_view text);
// The shortest exact spelling: "2m", "90s", "500ms".
std::string FormatDurationMs(std::int64_t ms);
// A YAML scalar such as 30s; errors carry the node's file:line:col.
Status DecodeDurationMs(const yaml::Node& node, std::int64_t* out_ms);

}  // namespace swarmbox::faults
