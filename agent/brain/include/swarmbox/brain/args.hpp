// The brain's arguments from their JSON text (the agent's `--brain-args`, the trial's
// `brain.args` mapping as the orchestrator passes it) into Context::args.
//
//   auto args = brain::ParseBrainArgs(R"({"altitude_m": 12, "name": "a", "ring": {"n": 3}})");
//   // {"altitude_m": "12", "name": "a", "ring": "{\"n\":3}"}
//
// The text must be one JSON object (YAML flow style is read too: the same parser as trial files,
// common/yaml.hpp). Scalars become their text as written (12 -> "12", "12" -> "12", true ->
// "true"); nested objects and lists become their JSON text (yaml::EmitJson); a null value leaves
// the key out (the brain's default applies). Empty text is an empty object. Errors are
// kInvalidArgument with where = "<source>:line:col" (duplicate keys, syntax, not an object).
#pragma once

#include <map>
#include <string>
#include <string_view>

#include "swarmbox/common/result.hpp"

namespace swarmbox::brain {

Result<std::map<std::string, std::string>> ParseBrainArgs(std::string_view json,
                                                          std::string_view source = "--brain-args");

}  // namespace swarmbox::brain
